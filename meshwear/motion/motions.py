"""How bodies move: paths, and the free, guided, prescribed and fixed motions.

A motion owns one rule: given a body's pose at time ``t`` and the contact
wrench on it, produce the pose at ``t + dt``. Contact never calls back into a
motion, so the step order stays in :func:`meshwear.step.simulate.step`. Each is a
kind and a parameter array of :mod:`meshwear.kernels.rigid`, so the compiled
step loop (:mod:`meshwear.kernels.loop`) runs the same kernels.

Every motion implements

``place(pose, t)``
    Set the path-driven parts of ``pose`` at time ``t`` (used at ``t = 0``).
``advance(pose, wrench, t, dt)``
    Advance ``pose`` from ``t`` to ``t + dt`` under the contact ``wrench``.
``dynamic_axes``
    The degrees of freedom integrated in time: ``"all"``, ``"axis"`` or ``None``.

In quasi-static runs, :class:`BalancedMotion` (a guided body) also has
``settle``, which puts the body where its contacts carry its load, and
:class:`TurningMotion` (a guided body turning under a torque) one that
turns it to where its contacts carry the torque.
"""

import numpy as np

from ..kernels.balance import balance_offset
from ..kernels.rigid import (ACCELERATION, AXIS, BALANCED, CARRIED, CIRCLE, FIXED, FREE, GUIDED,
                             INERTIA, INVERSE_INERTIA, INVERSE_MASS, MOTION_PARAMS, OSCILLATION,
                             ORIENTATION, PRESCRIBED, SETTLED, START, STEADY, TURN_AXIS,
                             TURN_CENTER, TURN_RATE, TURNING, advance_free_motion, advance_motion,
                             path_point, place_motion)
from ..kernels.turn_balance import place_settled, settle_turn


class Path:
    """Displacement added to a body's initial position: oscillation, steady
    velocity and circle, summed (the ``terms`` rows of
    :func:`meshwear.kernels.rigid.path_point`).

    Parameters
    ----------
    config : meshwear.scene.PathConfig or None
        None gives the empty path (no displacement).
    """

    def __init__(self, config=None):
        rows = []
        if config is not None and config.oscillation is not None:
            o = config.oscillation
            rows.append([OSCILLATION, *o.axis, 0.0, 0.0, 0.0, o.amplitude, 2.0 * np.pi * o.frequency])
        if config is not None and config.velocity is not None:
            rows.append([STEADY, *config.velocity, 0.0, 0.0, 0.0, 0.0, 0.0])
        if config is not None and config.circle is not None:
            c = config.circle
            normal = np.asarray(c.normal, float)
            e1 = _perpendicular(normal)
            e2 = np.cross(normal, e1)
            rows.append([CIRCLE, *e1, *e2, c.radius, 2.0 * np.pi * c.frequency])
        #: (k, 9) float, see :func:`meshwear.kernels.rigid.path_point`
        self.terms = np.array(rows, dtype=float).reshape(-1, 9)
        omegas = self.terms[:, 8][self.terms[:, 8] > 0.0]
        #: cycle length (s) of the slowest periodic term, None for a steady path
        self.period = 2.0 * np.pi / omegas.min() if len(omegas) else None
        self.buffer = np.zeros((2, 3))

    def displacement(self, t):
        """(3,) displacement (m) at time ``t``. A circle starts at ``radius``
        along its first in-plane axis: ``position`` is the circle's centre."""
        path_point(self.terms, t, self.buffer)
        return self.buffer[0].copy()

    def velocity(self, t):
        """(3,) velocity (m/s) at time ``t``."""
        path_point(self.terms, t, self.buffer)
        return self.buffer[1].copy()


def _perpendicular(normal, hint=None):
    """A unit vector perpendicular to ``normal``: ``hint`` (if given), else the
    world x axis, projected on the plane, or y when that is (nearly) along
    the normal."""
    guesses = [np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])]
    for guess in ([np.asarray(hint, float)] if hint is not None else []) + guesses:
        e = guess - (guess @ normal) * normal
        if np.linalg.norm(e) > 1e-6:
            return e / np.linalg.norm(e)
    raise ValueError("degenerate normal")  # unreachable for a unit normal


#: no per-vertex stiffness scale in the balance
NO_SCALE = np.zeros(0)


class Motion:
    """A motion as the kernels see it: its ``kind`` (:mod:`meshwear.kernels.rigid`),
    ``params`` (40,) and path ``terms``; :meth:`place` and :meth:`advance`
    call the same kernels as the compiled step loop."""

    kind = FIXED
    dynamic_axes = None

    def __init__(self, path=None, start=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 0.0), mass=np.nan,
                 inertia=None, acceleration=(0.0, 0.0, 0.0), carried=0.0):
        self.path = path if path is not None else Path()
        self.params = np.zeros(MOTION_PARAMS)
        self.params[INVERSE_MASS] = 1.0 / mass if np.isfinite(mass) else 0.0
        if inertia is not None:
            self.params[INERTIA] = np.ravel(inertia)
            self.params[INVERSE_INERTIA] = np.linalg.inv(inertia).ravel()
        self.params[ACCELERATION] = acceleration
        self.params[AXIS] = axis
        self.params[START] = start
        self.params[CARRIED] = carried

    def set_turn(self, orientation, axis, rate, center):
        """A steady turn (:func:`meshwear.kernels.rigid.turn`): ``orientation``
        at t = 0 (quaternion), unit ``axis``, ``rate`` (rad/s) and the point
        it turns about at t = 0 (m, carried along the path)."""
        self.params[ORIENTATION] = orientation
        self.params[TURN_AXIS] = axis
        self.params[TURN_RATE] = rate
        self.params[TURN_CENTER] = center

    @property
    def turn_rate(self):
        return float(self.params[TURN_RATE])

    @property
    def terms(self):
        return self.path.terms

    @property
    def start(self):
        return self.params[START]

    @property
    def axis(self):
        return self.params[AXIS]

    def place(self, pose, t):
        """Set the path-driven parts of ``pose`` at time ``t``."""
        place_motion(self.kind, self.params, self.path.terms, self.path.buffer, pose, float(t))

    def advance(self, pose, wrench, t, dt):
        """Advance ``pose`` from ``t`` to ``t + dt`` under the contact ``wrench``."""
        advance_motion(self.kind, self.params, self.path.terms, self.path.buffer, pose, wrench,
                       float(t), float(dt))


class FreeMotion(Motion):
    """Newton-Euler with gravity and a constant force, symplectic Euler step."""

    kind = FREE
    dynamic_axes = "all"

    def __init__(self, mass, inertia, acceleration):
        super().__init__(mass=mass, inertia=np.asarray(inertia, float), acceleration=acceleration)

    # (no path: a free body's first run compiles none of the paths' kernels)
    def place(self, pose, t):
        """A free body has no path-driven part."""

    def advance(self, pose, wrench, t, dt):
        advance_free_motion(self.kind, self.params, self.path.terms, self.path.buffer, pose,
                            wrench, float(t), float(dt))


class PrescribedMotion(Motion):
    """All translations follow ``start + path(t)``; orientation fixed."""

    kind = PRESCRIBED

    def __init__(self, start, path):
        super().__init__(path, start)


class GuidedMotion(Motion):
    """Translation along ``free_axis`` is dynamic (contact, gravity, applied
    force); every other degree of freedom follows ``start + path(t)``. The
    path's component along the free axis is dropped."""

    kind = GUIDED
    dynamic_axes = "axis"

    def __init__(self, start, path, free_axis, mass, acceleration):
        super().__init__(path, start, free_axis, mass=mass, acceleration=acceleration)


class BalancedMotion(Motion):
    """Quasi-static guided body: every degree of freedom but ``free_axis``
    follows ``start + path(t)``; along the axis the body sits where the
    contact normal forces balance the applied ``load`` (N along the axis:
    gravity and the constant force), found by
    :func:`meshwear.kernels.balance.balance_offset`. No inertia, no damping.
    """

    kind = BALANCED

    def __init__(self, start, path, free_axis, load):
        #: contact force the planes must supply along the axis (N): params[CARRIED]
        super().__init__(path, start, free_axis, carried=-float(load))
        self.scratch = np.zeros((2, 0))

    @property
    def carried(self):
        return self.params[CARRIED]

    def ensure_scratch(self, pairs):
        """Grow the balance's work array to ``pairs`` vertex-surface pairs."""
        if self.scratch.shape[1] < pairs:
            self.scratch = np.zeros((2, pairs))
        return self.scratch

    def settle(self, pose, vertices, area_vectors, planes, vertex_planes, active, law):
        """Move ``pose`` along the axis to the balance; False if no contact
        can carry the load (arrays as for
        :func:`meshwear.kernels.balance.balance_offset`)."""
        scratch = self.ensure_scratch(len(active) * (planes.shape[0] + vertex_planes.shape[0]))
        z = balance_offset(vertices, pose, self.axis, planes, vertex_planes, active, area_vectors,
                           law, self.carried, 0.0, scratch, NO_SCALE)
        if not np.isfinite(z):
            return False
        for j in range(3):
            pose[j] += z * self.axis[j]
        return True


class TurningMotion(Motion):
    """Quasi-static guided body under a torque: it follows ``start +
    path(t)`` and its path's steady turn, and turns besides by the settled
    angle at which its contacts' normal forces carry the applied ``torque``
    (N·m about the turn's axis, right-handed: positive turns it the way a
    positive rate does), found by
    :func:`meshwear.kernels.turn_balance.settle_turn`. No inertia, no
    damping. The settled angle is kept in ``params[SETTLED]`` (the next
    step starts from it). Call :meth:`set_turn` before use."""

    kind = TURNING

    def __init__(self, start, path, torque):
        #: torque the contacts must carry about the axis (N·m): params[CARRIED]
        super().__init__(path, start, carried=-float(torque))
        self.scratch = np.zeros((2, 0))

    @property
    def carried(self):
        return self.params[CARRIED]

    @property
    def settled(self):
        """The angle (rad) the body last settled to, beyond its path's turn."""
        return float(self.params[SETTLED])

    ensure_scratch = BalancedMotion.ensure_scratch

    @property
    def turn_axis(self):
        return self.params[TURN_AXIS]

    def center_of(self, pose):
        """(3,) the point the turn's axis passes through with the body at
        ``pose`` (m): the centre of mass less its offset from the axis's
        place at t = 0, turned as the body has turned since."""
        q0, q = self.params[ORIENTATION], pose[3:7]
        # the turn since t = 0: q q0^-1
        w, x, y, z = (q[0] * q0[0] + q[1] * q0[1] + q[2] * q0[2] + q[3] * q0[3],
                      -q[0] * q0[1] + q[1] * q0[0] - q[2] * q0[3] + q[3] * q0[2],
                      -q[0] * q0[2] + q[1] * q0[3] + q[2] * q0[0] - q[3] * q0[1],
                      -q[0] * q0[3] - q[1] * q0[2] + q[2] * q0[1] + q[3] * q0[0])
        turned = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                           [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                           [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        return pose[0:3] - turned @ (self.params[START] - self.params[TURN_CENTER])

    def lever(self, vertices, pose):
        """The largest lever (m) of ``vertices`` (n, 3, body frame) about
        the turn's axis, the body at ``pose``."""
        from ..kernels.contact import rotation_entries

        R = np.array(rotation_entries(np.asarray(pose[3:7], float))).reshape(3, 3)
        x = pose[0:3] + vertices @ R.T
        return float(np.linalg.norm(np.cross(self.turn_axis, x - self.center_of(pose)),
                                    axis=1).max())

    def place(self, pose, t):
        """On the path at ``t``, turned by the angle last settled to."""
        super().place(pose, t)
        place_settled(pose, self.params, self.path.terms, float(t), self.path.buffer)

    def settle(self, pose, vertices, area_vectors, planes, vertex_planes, active, law, t=0.0,
               dt=0.0):
        """Turn ``pose`` (placed at ``t``) to the torque balance, its angular
        velocity given the rate of that turn over ``dt`` (if > 0); False if
        no contact can carry the torque (arrays as for
        :func:`meshwear.kernels.balance.balance_offset`)."""
        scratch = self.ensure_scratch(len(active) * (planes.shape[0] + vertex_planes.shape[0]))
        angle = settle_turn(vertices, pose, self.params, self.path.terms, float(t), float(dt),
                            self.path.buffer, planes, vertex_planes, active, area_vectors, law,
                            scratch)
        return bool(np.isfinite(angle))


class FixedMotion(Motion):
    """The body does not move."""

    kind = FIXED


class MechanismMotion(Motion):
    """A part riding on a body of a MuJoCo mechanism (:mod:`meshwear.mechanism`):
    MuJoCo sets its pose and velocity before every step, the compiled loop
    leaves them (kind ``FIXED``, whose step does not move it). ``mass`` and
    ``inertia`` (MuJoCo's mass, distributed as the mesh's) bound the stable
    contact step; the joints only add to the mass a contact mode moves."""

    kind = FIXED
    dynamic_axes = "all"

    def __init__(self, mass, inertia):
        super().__init__(mass=mass, inertia=np.asarray(inertia, float))

    def place(self, pose, t):
        """The mechanism places it (:meth:`meshwear.mechanism.Mechanism.place`)."""

    def advance(self, pose, wrench, t, dt):
        """The mechanism moves it."""
