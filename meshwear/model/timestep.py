"""The time step of a run (docs/model.md, "Stable time step";
docs/scene-format.md, ``run.dt``).

The largest stable step of the bodies integrated in time
(:func:`stable_time_step`, on :mod:`meshwear.contact.stability`'s bound),
the step ``run.dt = "auto"`` stands for (:func:`auto_time_step`), and how a
step is shortened so the duration, and with cycle jumping a cycle, is whole
steps, with the step indices of the outputs.
:func:`meshwear.model.build.check_time_step` refuses a step above the stable
one before a run starts.
"""

import math

import numpy as np

from ..motion.motions import MechanismMotion
from ..scene.checks import SceneError
from ..contact.stability import STABILITY_MARGIN, contact_matrix, stable_step, vertex_stiffness

#: ``run.dt = "auto"`` resolves a cycle of the motion into at least this many steps
AUTO_STEPS_PER_CYCLE = 200
#: ... and the whole run into at least this many
AUTO_STEPS_PER_RUN = 1000


def auto_time_step(scene, period, limit):
    """The step ``run.dt = "auto"`` stands for (s): the largest stable step
    ``limit`` of the bodies integrated in time, and no longer than a
    :data:`AUTO_STEPS_PER_CYCLE`-th of the motion's cycle ``period`` (None
    when nothing moves periodically) or a :data:`AUTO_STEPS_PER_RUN`-th of
    the duration."""
    return auto_time_step_why(scene, period, limit)[0]


def auto_time_step_why(scene, period, limit):
    """:func:`auto_time_step` and which of its limits set it, in words."""
    choices = [(scene.run.duration / AUTO_STEPS_PER_RUN,
                f"1/{AUTO_STEPS_PER_RUN} of the duration")]
    if period is not None:
        choices.append((period / AUTO_STEPS_PER_CYCLE,
                        f"1/{AUTO_STEPS_PER_CYCLE} of the {period:.4g} s cycle"))
    choices.append((limit, "the largest stable step"))
    return min(choices, key=lambda c: c[0])


#: most steps a run may take (counts stay exact in float64 times)
MAX_STEPS = 10**15
#: fewest steps per cycle cycle jumping accepts (one or two alias an oscillation away)
MIN_CYCLE_STEPS = 4


def _timing(scene, period, limit):
    """``(dt, n_steps, cycle_steps)`` of a run: the step asked (or
    :func:`auto_time_step`) shortened so the duration is whole steps; when
    cycles are jumped over, so a cycle is whole steps (``cycle_steps``, else
    0) and the duration whole cycles' steps. Never longer than asked."""
    asked = scene.run.dt
    if asked == "auto":
        asked = auto_time_step(scene, period, limit)
    key = "run.dt" if scene.run.dt != "auto" else "run.duration"
    if scene.wear.acceleration != "cycle_jump":
        n_steps = _step_count(scene, key, scene.run.duration / asked)
        return scene.run.duration / n_steps, n_steps, 0
    for j, b in enumerate(scene.bodies):
        if b.motion == "free":
            raise SceneError(scene.source, f"body[{j}].motion", "'free' bodies have no cycle to "
                             "jump over; wear.acceleration = 'cycle_jump' needs guided, "
                             "prescribed or fixed bodies")
    cycle_steps = _step_count(scene, key, period / asked)
    if cycle_steps < MIN_CYCLE_STEPS:
        raise SceneError(scene.source, "run.dt", f"{asked:.6g} s gives {cycle_steps} step(s) "
                         f"per cycle of {period:.6g} s; cycle jumping needs at least "
                         f"{MIN_CYCLE_STEPS} to resolve the cycle it extrapolates")
    dt = period / cycle_steps
    n_steps = _step_count(scene, "run.duration", scene.run.duration / dt, round)
    return dt, n_steps, cycle_steps


def _step_count(scene, key, ratio, rounding=None):
    """A count of steps ``ratio`` rounded up (or by ``rounding``), at least 1:
    a SceneError naming ``key`` if it is more than :data:`MAX_STEPS`."""
    if not ratio <= MAX_STEPS:
        raise SceneError(scene.source, key, f"the run would take {ratio:.3g} steps, more than "
                         f"{MAX_STEPS:.0e}; a longer dt or a shorter duration")
    return max(1, int(rounding(ratio) if rounding else math.ceil(ratio - 1e-9)))


def _even_steps(n_steps, count):
    """Step indices of ``count`` evenly spaced samples, first 0, last n_steps."""
    if count <= 0:
        return np.zeros(0, dtype=np.int64)
    if count == 1:
        return np.zeros(1, dtype=np.int64)
    return np.unique(np.rint(np.linspace(0, n_steps, count)).astype(np.int64))


def stable_time_step(model):
    """Largest stable time step (s) of the dynamic bodies, and the body that sets it.

    Bound: the contact stiffness of every vertex acting in all three directions
    and against every plane at once, ``K = P sum_i max(c_i, c_t,i) J_i^T J_i``
    with ``J_i = [I, -[r_i]x]`` and ``P`` planes, is at least the stiffness of
    any real contact configuration, so its largest
    generalised eigenvalue against the mass matrix bounds the fastest contact
    mode, rotations included. Each mode ``omega`` with damping ratio ``zeta``
    is stable under the symplectic Euler step for
    ``dt <= 2 (sqrt(1 + zeta^2) - zeta) / omega``; the result is that bound
    times :data:`STABILITY_MARGIN`. Returns ``(inf, None)`` when no body is
    integrated in time.
    """
    own = _stable_limit(model.bodies, model.law, model.slots)
    moved = model.dynamics.stable_limit(model.bodies, model.law, model.slots)
    return own if own[0] <= moved[0] else moved


def _stable_limit(bodies, law, slots):
    """:func:`stable_time_step` of ``bodies`` under the contact ``law`` with
    ``slots`` counter-surfaces."""
    best, who = np.inf, None
    for b in bodies:
        kind = b.motion.dynamic_axes
        if kind is None or isinstance(b.motion, MechanismMotion):
            continue        # a mechanism's riders: Mechanism.stable_limit
        # a vertex may press on every plane at once (a box in a corner)
        planes = max(1, slots)
        k, d = (planes * x for x in vertex_stiffness(b, law))
        if kind == "axis":
            K = np.array([[k.sum()]])
            C = np.array([[d.sum()]])
            M = np.array([[b.mass]])
        else:
            K, C = contact_matrix(k, b.reference_vertices), contact_matrix(d, b.reference_vertices)
            M = np.zeros((6, 6))
            M[:3, :3] = b.mass * np.eye(3)
            M[3:, 3:] = b.inertia
        dt = stable_step(K, C, M)
        if dt < best:
            best, who = dt, b.name
    return STABILITY_MARGIN * best, who
