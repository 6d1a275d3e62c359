"""Outputs inside a jumped span, filled from the jump (docs/outputs.md, "Long runs").

A history row or frame whose time falls in cycles a jump skips costs no
resolved cycle. While the cycle before a jump is resolved, the state of each
body is recorded at the phases of the outputs the jump may cover
(:func:`record`); once the jump is taken, each such output is written
(:func:`write`) from a view of the state: wear depth, worn volume, friction
work and the worn vertices interpolated along the jump, the pose and the
contact those of the resolved cycle at the same phase (the pose put on its
path at the output's time, a guided body moved along its axis by the jump's
share; the forces, planes and faces of the touching vertices and the
vertices within reach of a surface, so a worn counter-part's reaction is the
bodies' at that phase too; a mechanism's state, so the parts it carries, its
worn counter-surfaces' frames and its joint columns are those of that phase
too). The rows and frames are marked ``resolved = 0``.
"""

import copy
from dataclasses import dataclass

import numpy as np

from ..kernels.contact import FORCE


@dataclass
class Snapshot:
    """One body's state at one phase of the resolved cycle: pose, contact
    wrench, contact states, and the contact of its vertices that touch (their
    indices, forces, the planes and faces of the per-vertex surfaces under
    them, and the vertices within reach of a surface then): what the body's
    and the worn counter-parts' fields and reactions are made of."""

    pose: np.ndarray
    wrench: np.ndarray
    contact_state: np.ndarray
    touching: np.ndarray
    normal_force: np.ndarray
    friction_force: np.ndarray
    planes: np.ndarray
    hint: np.ndarray
    active: np.ndarray


@dataclass
class Phase:
    """The state at one phase of the resolved cycle: a :class:`Snapshot` per
    body and the dynamics' own state (``model.dynamics.get_state()``: a
    mechanism's; None for meshwear's own motions)."""

    bodies: list
    dynamics: np.ndarray = None


def _capture(model, state):
    out = []
    for s in state.bodies:
        touching = np.flatnonzero((s.normal_force > 0.0).any(axis=0))
        out.append(Snapshot(s.pose.copy(), s.wrench.copy(), s.contact_state.copy(), touching,
                            s.normal_force[:, touching].copy(),
                            s.tangential[:, touching, FORCE].copy(),
                            s.vertex_planes[:, touching].copy(), s.hint[:, touching].copy(),
                            s.active.copy()))
    dynamics = model.dynamics.get_state()
    return Phase(out, None if dynamics is None else np.array(dynamics, copy=True))


def phases(model, start, stop, cycles):
    """The steps of the cycle ``start..stop`` at the phases of the outputs a
    jump of up to ``cycles`` after it could cover (``stop`` for phase 0)."""
    n_c = stop - start
    schedule = model.output_steps
    inside = schedule[(schedule > stop) & (schedule < stop + cycles * n_c)]
    phase = (inside - start) % n_c
    return set(np.where(phase > 0, start + phase, stop).tolist())


def record(model, state, start, stop, cycles, observers, progress, advance):
    """Resolve the cycle ``start..stop`` (writing its own outputs) by
    ``advance(model, state, stop, observers, progress)``
    (:func:`meshwear.step.simulate.advance`), keeping the snapshots a jump of up
    to ``cycles`` cycles after it needs."""
    wanted = phases(model, start, stop, cycles)
    snapshots = {}
    for r in sorted(wanted) + [stop]:
        advance(model, state, r, observers, progress)
        if r in wanted:
            snapshots[r - start] = _capture(model, state)
    return snapshots


def write(model, state, stop, jump, snapshots, spans, observers, check, part_spans=(),
          progress=None):
    """Write every output strictly inside the span the jump just covered
    (``stop`` to ``stop + jump`` cycles), filled from it (``spans``: per body,
    the jumped arrays at its start and end, and the shift of its position;
    ``part_spans`` the same per worn counter-part, in the order of
    ``state.parts``); ``check(model, state, face_normals)`` refuses an
    invalid state (:func:`meshwear.step.simulate.check`). ``progress(f)``: per
    body, the share of each vertex's wear (n,) and of the move done at the
    fraction ``f`` of the jump's cycles (the implicit jump's own curve: the
    middle of a pin's scar slows as its edge comes into contact; None: ``f``
    for all). Returns the number of outputs written."""
    n_c = model.cycle_steps
    end = stop + jump * n_c
    schedule = model.output_steps
    start = stop - n_c
    inside = schedule[(schedule > stop) & (schedule < end)].tolist()
    try:
        for o in inside:
            _write_one(model, state, o, start, end, snapshots, spans, observers, check,
                       part_spans, progress)
    finally:
        # (a mechanism shown at the outputs' phases: back where the jump left it)
        model.dynamics.show(model, state)
    return len(inside)


def _write_one(model, state, o, start, end, snapshots, spans, observers, check, part_spans,
               progress):
    """:func:`write`'s output at step ``o``."""
    n_c, stop = model.cycle_steps, start + model.cycle_steps
    phase = (o - start) % n_c
    shot = snapshots[phase if phase else n_c]
    fraction = (o - stop) / (end - stop)
    shares = (progress(fraction) if progress is not None
              else [(fraction, fraction)] * len(spans))
    view = copy.copy(state)
    view.step, view.time = o, o * model.dt
    view.bodies = [_view(body, s, one, span, share, view.time)
                   for body, s, one, span, share in zip(model.bodies, state.bodies, shot.bodies,
                                                        spans, shares)]
    if part_spans:
        spans_left = iter(part_spans)
        view.parts = [None if p is None else _interpolated(p, next(spans_left), fraction)
                      for p in state.parts]
    # (a mechanism's riders and the surfaces on its bodies where it had
    # them at that phase, at the output's time)
    model.dynamics.show(model, view, shot.dynamics)
    sample, frame = o in model.sample_set, o in model.frame_set
    if frame:
        check(model, view, [b.reference_face_normals for b in model.bodies])
    for observer in observers:
        if sample:
            observer.on_sample(model, view)
        if frame:
            observer.on_frame(model, view)
    state.written = o


def _interpolated(part, span, fraction):
    """A worn counter-part at ``fraction`` of the jump."""
    view = copy.copy(part)
    for name, (first, last) in span.items():
        setattr(view, name, first + fraction * (last - first))
    return view


def _view(body, s, shot, span, share, t):
    """A body state part way through the jump (``share``: of each vertex's
    wear, a scalar or (n,), and of the move), with the contact of ``shot``."""
    fraction, moved = share
    view = copy.copy(s)
    view.pose = shot.pose.copy()
    view.pose[0:3] += moved * span["shift"]
    body.motion.place(view.pose, t)
    view.wrench = shot.wrench
    view.contact_state = shot.contact_state
    for name, value in span.items():
        if name != "shift":
            first, last = value
            f = np.reshape(fraction, np.shape(fraction) + (1,) * (first.ndim - np.ndim(fraction)))
            setattr(view, name, first + f * (last - first))
    touching = shot.touching
    view.normal_force = np.zeros_like(s.normal_force)
    view.normal_force[:, touching] = shot.normal_force
    view.tangential = np.zeros_like(s.tangential)
    view.tangential[:, touching, FORCE] = shot.friction_force
    view.vertex_planes = np.zeros_like(s.vertex_planes)
    view.vertex_planes[:, touching] = shot.planes
    view.hint = np.full_like(s.hint, -1)
    view.hint[:, touching] = shot.hint
    # the vertices within reach at that phase: a worn counter-part's reaction
    # is summed over them (meshwear.output.fields.part_quantities), and the
    # contact moves over a turning part (a gear's teeth), so those at the
    # cycle's end miss most of the phase's touching vertices
    view.active = shot.active
    return view
