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
"""

import numpy as np

from .kernels.rigid import axis_step, free_step


class Path:
    """Displacement added to a body's initial position: oscillation, steady
    velocity and circle, summed.

    Parameters
    ----------
    config : meshwear.scene.PathConfig
    """

    def __init__(self, config):
        self.terms = []
        if config.oscillation is not None:
            o = config.oscillation
            self.terms.append(("oscillation", np.asarray(o.axis, float), o.amplitude,
                               2.0 * np.pi * o.frequency))
        if config.velocity is not None:
            self.terms.append(("velocity", np.asarray(config.velocity, float), 0.0, 0.0))
        if config.circle is not None:
            c = config.circle
            normal = np.asarray(c.normal, float)
            e1 = _perpendicular(normal)
            e2 = np.cross(normal, e1)
            self.terms.append(("circle", np.stack([e1, e2]), c.radius, 2.0 * np.pi * c.frequency))
        frequencies = [t[3] / (2.0 * np.pi) for t in self.terms if t[3] > 0.0]
        #: cycle length (s) of the periodic part, None for a steady path
        self.period = 1.0 / min(frequencies) if frequencies else None

    def displacement(self, t):
        """(3,) displacement (m) at time ``t``; zero at ``t = 0`` except for a
        circle, which starts at ``radius`` along its first in-plane axis."""
        out = np.zeros(3)
        for kind, vec, amplitude, omega in self.terms:
            if kind == "oscillation":
                out += amplitude * np.sin(omega * t) * vec
            elif kind == "velocity":
                out += t * vec
            else:
                out += amplitude * (np.cos(omega * t) * vec[0] + np.sin(omega * t) * vec[1])
        return out

    def velocity(self, t):
        """(3,) velocity (m/s) at time ``t``."""
        out = np.zeros(3)
        for kind, vec, amplitude, omega in self.terms:
            if kind == "oscillation":
                out += amplitude * omega * np.cos(omega * t) * vec
            elif kind == "velocity":
                out += vec
            else:
                out += amplitude * omega * (-np.sin(omega * t) * vec[0] + np.cos(omega * t) * vec[1])
        return out


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
    """All degrees of freedom follow ``start + path(t)``; orientation fixed."""

    dynamic_axes = None

    def __init__(self, start, path):
        self.start = np.asarray(start, float)
        self.path = path

    def place(self, pose, t):
        pose[0:3] = self.start + self.path.displacement(t)
        pose[7:10] = self.path.velocity(t)
        pose[10:13] = 0.0

    def advance(self, pose, wrench, t, dt):
        self.place(pose, t + dt)


class GuidedMotion:
    """Translation along ``free_axis`` is dynamic (contact, gravity, applied
    force); every other degree of freedom follows ``start + path(t)``. The
    path's component along the free axis is dropped."""

    dynamic_axes = "axis"

    def __init__(self, start, path, free_axis, mass, acceleration):
        self.axis = np.asarray(free_axis, float)
        self.across = np.eye(3) - np.outer(self.axis, self.axis)
        self.start = np.asarray(start, float)
        self.path = path
        self.inverse_mass = 1.0 / mass
        self.acceleration = np.asarray(acceleration, float)

    def place(self, pose, t):
        along = pose[0:3] @ self.axis
        rate = pose[7:10] @ self.axis
        pose[0:3] = self.across @ (self.start + self.path.displacement(t)) + along * self.axis
        pose[7:10] = self.across @ self.path.velocity(t) + rate * self.axis
        pose[10:13] = 0.0

    def advance(self, pose, wrench, t, dt):
        rate = axis_step(pose, wrench, self.inverse_mass, self.acceleration, self.axis, dt)
        along = pose[0:3] @ self.axis + dt * rate
        pose[0:3] = self.across @ (self.start + self.path.displacement(t + dt)) + along * self.axis
        pose[7:10] = self.across @ self.path.velocity(t + dt) + rate * self.axis


class FixedMotion:
    """The body does not move."""

    dynamic_axes = None

    def place(self, pose, t):
        pose[7:13] = 0.0

    def advance(self, pose, wrench, t, dt):
        pass
