"""How bodies move: paths, and the free, guided, prescribed and fixed motions.

A motion owns one rule: given a body's pose at time ``t`` and the contact
wrench on it, produce the pose at ``t + dt``. Contact never calls back into a
motion, so the step order stays in :func:`meshwear.simulate.step`.

Every motion implements

``place(pose, t)``
    Set the path-driven parts of ``pose`` at time ``t`` (used at ``t = 0``).
``advance(pose, wrench, t, dt)``
    Advance ``pose`` from ``t`` to ``t + dt`` under the contact ``wrench``.
``dynamic_axes``
    The degrees of freedom integrated in time: ``"all"``, ``"axis"`` or ``None``.

In quasi-static runs, :class:`BalancedMotion` (a guided body) also has
``settle``, which puts the body where its contacts carry its load.
"""

import numpy as np

from .kernels.balance import balance_offset
from .kernels.rigid import (CIRCLE, OSCILLATION, STEADY, free_step, guided_step,
                            path_point, place_on_path)


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


def _perpendicular(normal):
    """A unit vector perpendicular to ``normal``: the world x axis projected on
    the plane, or y when x is (nearly) along the normal."""
    for guess in (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        e = guess - (guess @ normal) * normal
        if np.linalg.norm(e) > 1e-6:
            return e / np.linalg.norm(e)
    raise ValueError("degenerate normal")  # unreachable for a unit normal


class FreeMotion:
    """Newton-Euler with gravity and a constant force, symplectic Euler step."""

    dynamic_axes = "all"

    def __init__(self, mass, inertia, acceleration):
        self.inverse_mass = 1.0 / mass
        self.inertia = np.ascontiguousarray(inertia, dtype=float)
        self.inverse_inertia = np.ascontiguousarray(np.linalg.inv(inertia))
        self.acceleration = np.asarray(acceleration, float)

    def place(self, pose, t):
        pass

    def advance(self, pose, wrench, t, dt):
        free_step(pose, wrench, self.inverse_mass, self.inertia, self.inverse_inertia,
                  self.acceleration, dt)


class PrescribedMotion:
    """All translations follow ``start + path(t)``; orientation fixed."""

    dynamic_axes = None

    def __init__(self, start, path):
        self.start = np.asarray(start, float)
        self.path = path
        self.no_axis = np.zeros(3)

    def place(self, pose, t):
        place_on_path(pose, self.start, self.path.terms, self.no_axis, 0.0, 0.0, t,
                      self.path.buffer)

    def advance(self, pose, wrench, t, dt):
        self.place(pose, t + dt)


class GuidedMotion:
    """Translation along ``free_axis`` is dynamic (contact, gravity, applied
    force); every other degree of freedom follows ``start + path(t)``. The
    path's component along the free axis is dropped."""

    dynamic_axes = "axis"

    def __init__(self, start, path, free_axis, mass, acceleration):
        self.axis = np.asarray(free_axis, float)
        self.start = np.asarray(start, float)
        self.path = path
        self.inverse_mass = 1.0 / mass
        self.acceleration = np.asarray(acceleration, float)

    def place(self, pose, t):
        place_on_path(pose, self.start, self.path.terms, self.axis, pose[0:3] @ self.axis,
                      pose[7:10] @ self.axis, t, self.path.buffer)

    def advance(self, pose, wrench, t, dt):
        guided_step(pose, wrench, self.inverse_mass, self.acceleration, self.axis, self.start,
                    self.path.terms, t, dt, self.path.buffer)


class BalancedMotion:
    """Quasi-static guided body: every degree of freedom but ``free_axis``
    follows ``start + path(t)``; along the axis the body sits where the
    contact normal forces balance the applied ``load`` (N along the axis:
    gravity and the constant force), found by
    :func:`meshwear.kernels.balance.balance_offset`. No inertia, no damping.
    """

    dynamic_axes = None

    def __init__(self, start, path, free_axis, load):
        self.axis = np.asarray(free_axis, float)
        self.start = np.asarray(start, float)
        self.path = path
        #: contact force the planes must supply along the axis (N)
        self.carried = -float(load)
        self.scratch = np.zeros((2, 0))

    def place(self, pose, t):
        place_on_path(pose, self.start, self.path.terms, self.axis, pose[0:3] @ self.axis,
                      0.0, t, self.path.buffer)

    def settle(self, pose, vertices, area_vectors, planes, vertex_planes, active, law):
        """Move ``pose`` along the axis to the balance; False if no contact
        can carry the load (arrays as for
        :func:`meshwear.kernels.balance.balance_offset`)."""
        pairs = len(active) * (planes.shape[0] + vertex_planes.shape[0])
        if self.scratch.shape[1] < pairs:
            self.scratch = np.zeros((2, pairs))
        z = balance_offset(vertices, pose, self.axis, planes, vertex_planes, active, area_vectors,
                           law, self.carried, 0.0, self.scratch)
        if not np.isfinite(z):
            return False
        pose[0:3] += z * self.axis
        return True


class FixedMotion:
    """The body does not move."""

    dynamic_axes = None

    def place(self, pose, t):
        pose[7:13] = 0.0

    def advance(self, pose, wrench, t, dt):
        pass
