"""Taking a chosen cycle jump: the running state moved on by ``J`` cycles
(docs/model.md, "Long durations").

Each body's per-vertex arrays (:data:`JUMPED`) take the last measurement's
increments scaled by the jump's wear, its vertices move
(:func:`meshwear.longrun.jump_geometry.displacement`), a guided body moves
along its axis, and every body is placed at the new time with its stick
anchors carried along (:func:`_jump`); a worn counter-part's arrays
(:data:`PART_JUMPED`) alike, its faces' frames and tree renewed
(:func:`_jump_parts`). :func:`_progress` gives the share of an implicit jump
done at a fraction of its cycles, for the outputs filled inside it
(:mod:`meshwear.output.filled`).
"""

import numpy as np

from . import jump_geometry, jumps
from ..kernels.contact import ANCHOR
from ..kernels.nearest import face_frames
from ..kernels.rigid import SETTLED
from ..motion.motions import TurningMotion
from ..surfaces import quaternion_matrix, slot_normals
from .jump_errors import _relax_part, _slope_error

def _progress(measures, results, jump):
    """Per body, the share of each vertex's wear (n,) and of the move done
    at a fraction of an implicit jump's cycles: one backward-Euler step over
    that fraction against one over the whole jump, so outputs filled inside
    a long jump follow each vertex's own curve (the middle of a pin's scar
    slowing, its edge starting, as the contact widens), not a straight line."""
    whole = [jumps.single_step(m, jump) for m in measures]

    def share(fraction):
        if fraction <= 0.0 or fraction >= 1.0:
            return [(fraction, fraction)] * len(measures)
        out = []
        for m, (wear, move), (full_wear, _, _) in zip(measures, whole, results):
            part, part_move = jumps.single_step(m, fraction * jump)
            full = np.full(len(full_wear), fraction)
            worn = wear > 0.0
            full[m.index[worn]] = np.clip(part[worn] / wear[worn], 0.0, 1.0)
            out.append((full, float(np.clip(part_move / move, 0.0, 1.0)) if move else fraction))
        return out
    return share


#: the per-vertex arrays a jump extrapolates
JUMPED = ("vertices", "wear_depth", "wear_volume", "friction_work")


def _jump(model, state, before, rates, jump, results, measures=None, window=1):
    """Extrapolate the last measurement (``window`` resolved cycles, their
    per-cycle wear ``rates``, ``before`` the arrays at their start) over
    ``jump`` more cycles, each body's wear and move along its axis given
    by ``results``; return per body
    ``{name: (array at the jump's start, at its end)}`` for the :data:`JUMPED`
    arrays, and ``shift``, the move of its position."""
    spans = []
    for k, (body, s, b, rate) in enumerate(zip(model.bodies, state.bodies, before, rates)):
        _, vertices0, volume0, work0 = b
        span = {name: getattr(s, name).copy() for name in JUMPED}
        wear, z, _ = results[k]
        normal = None
        if measures is not None:
            normal = np.zeros((len(rate), 3))
            normal[measures[k].index] = measures[k].normal
        # every increment of the cycle scaled like the vertex's wear: a
        # vertex relieved by the jump wears, and dissipates, less; a vertex
        # the jump brought into contact had no cycle to scale: it moves
        # along its surface's normal (jump_geometry.displacement, which
        # the jump's bounds read)
        factor = np.full(len(rate), float(jump))
        wearing = rate > 0.0
        factor[wearing] = wear[wearing] / rate[wearing]
        factor /= window                 # the increments are the window's
        work = s.friction_work - work0
        volume = s.wear_volume - volume0
        s.vertices += jump_geometry.displacement(body, s, vertices0, rate, wear, normal, window)
        s.wear_volume += factor * volume
        s.friction_work += factor * work
        fresh = ~wearing & (wear > 0.0)
        if fresh.any() and normal is not None:
            # and wears its depth times its contact area, and dissipates
            # what the contact does per volume
            _wear_fresh(body, s, fresh, wear, normal,
                        work[wearing].sum() / max(volume[wearing].sum(), 1e-300))
        s.wear_depth += wear
        span = {name: (span[name], getattr(s, name).copy()) for name in JUMPED}
        span["shift"] = z * body.motion.axis if z else np.zeros(3)
        if isinstance(body.motion, TurningMotion):
            # its move is a turn, the arc at its largest lever (jumps.measure)
            span["shift"] = np.zeros(3)
            if z:
                body.motion.params[SETTLED] += z / body.motion.jump_lever
        spans.append(span)
    state.step += jump * model.cycle_steps
    state.time = state.step * model.dt
    state.resolved = False
    # (a mechanism goes on from its state at the end of the resolved cycle,
    # its clock moved on by the jump's whole cycles)
    model.dynamics.jumped(model, state, jump * model.cycle_steps * model.dt)
    # put every body where its path is at the new time (a steady sliding path
    # has moved on; a periodic one is back in phase), a guided one moved along
    # its axis as the jump's balance has it, and carry the stick anchors
    # along, so the next step does not see the jump as a slide
    for body, s, span in zip(model.bodies, state.bodies, spans):
        start = s.pose[0:3].copy()
        s.pose[0:3] += span["shift"]
        body.motion.place(s.pose, state.time)
        moved = s.pose[0:3] - start
        a = s.active                      # the others are in no contact
        for j, n in enumerate(slot_normals(model, s)):
            n = np.broadcast_to(n, s.tangential[j, :, ANCHOR].shape)[a]
            s.tangential[j, a, ANCHOR] += moved - np.einsum("ij,j->i", n, moved)[:, None] * n
    return spans


#: the arrays of a worn counter-part a jump extrapolates
PART_JUMPED = ("depth", "volume", "work", "vertices")


def _jump_parts(model, parts, before_parts, part_rates, js, jump, factors=None, window=1,
                bodies_share=None):
    """Extrapolate each worn counter-part's wear per cycle in the last
    measurement (of ``window`` resolved cycles, ``before_parts`` the arrays
    at its start) over ``jump`` more cycles, each vertex's relieved by its
    factor of ``factors`` (per per-vertex surface: (factor, relative error)
    or None, :func:`meshwear.longrun.jumps.counter_factors`; None: explicit) (its
    vertices moved to their new depth, their faces' frames and the face
    tree renewed); return per part ``{name: (array at the jump's start, at
    its end)}`` for depth, volume, work and vertices. ``bodies_share``: the
    bodies' jumped volume over their volume in a cycle of the measurement
    (the part's own over the jump is its cycle's times that), or None."""
    spans = []
    for k, ((j, part), (_, volume0, work0), rate) in enumerate(
            zip(parts, before_parts, part_rates)):
        surface = model.surfaces.per_vertex[j]
        span = {name: getattr(part, name).copy() for name in PART_JUMPED}
        scale = np.full(len(rate), float(jump))
        relative = None
        if factors is not None and factors[j] is not None:
            scale = jump * factors[j][0]
            relative = factors[j][1]
            if bodies_share is not None:
                # the same contacts wear both parts: over the jump the part
                # wears the bodies' jumped volume times its share of it in
                # the measurement (its factors, carried from the bodies'
                # vertices over it at one phase, set where; a gear's wheel,
                # most of its flanks out of mesh at that phase, outwore the
                # pinion by a third)
                cycle = (part.volume - volume0) / window
                planned = float(scale @ cycle)
                if planned > 0.0:
                    scale = scale * (bodies_share * float(cycle.sum()) / planned)
        part.depth += scale * rate
        part.volume += scale / window * (part.volume - volume0)
        part.work += scale / window * (part.work - work0)
        moved = scale * rate != 0.0
        part.vertices[moved] = (surface.reference_vertices[moved]
                                - part.depth[moved, None] * surface.vertex_normals[moved])
        # the faces round the vertices the jump moved get their frames again
        # (a fine flat's scar is a few per cent of its faces)
        around = moved[surface.faces].any(axis=1)
        part.frames[around] = face_frames(part.vertices, surface.faces[around])
        surface.rebin()
        previous = js.part_rate[k]
        # the errors so far relax where the part wears (implicit jumps:
        # js.relax is the contact's time; explicit, none)
        _relax_part(js, k, rate > 0.0, jump)
        if relative is not None:
            js.part_error[k] += jump * rate * relative      # the bodies' implicit step's
        else:
            js.part_error[k] += _slope_error(rate, previous, js.gap, jump)
        if js.part_noise[k] is not None:
            # the noise of one measurement's rate, times the jump: random
            # from jump to jump, so the jumps' errors add in quadrature
            js.part_noise_var[k] += (jump * js.part_noise[k]) ** 2
        spans.append({name: (span[name], getattr(part, name).copy()) for name in PART_JUMPED})
    return spans


def _fresh_area(body, s, fresh, normal):
    """The area (m^2) over which the vertices ``fresh`` (mask) of ``body``
    (state ``s``) wear, pressed by the surfaces of world ``normal`` (n, 3):
    their area vectors across it."""
    local = normal[fresh] @ quaternion_matrix(s.pose[3:7])
    return np.maximum(-np.einsum("ij,ij->i", body.area_vectors[fresh, 0:3], local), 0.0)


def _wear_fresh(body, s, fresh, wear, normal, work_per_volume):
    """The worn volume and friction work of the wear ``wear[fresh]`` of
    vertices with no cycle increments to scale, pressed by the surfaces of
    world ``normal`` (n, 3) (their move is
    :func:`meshwear.longrun.jump_geometry.displacement`'s)."""
    depth = wear[fresh]
    volume = depth * _fresh_area(body, s, fresh, normal)
    s.wear_volume[fresh] += volume
    s.friction_work[fresh] += work_per_volume * volume
