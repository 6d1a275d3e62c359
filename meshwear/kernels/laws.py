"""Wear laws: one registry names each law, its kernel increment and its numpy twin.

A law turns what one contact pair did in one step into the wear of one part
(docs/model.md, "Wear laws"): its increment is

    depth, volume = increment(k, energy, load, slip, area)

with ``k`` the part's coefficient, ``energy`` the friction energy the pair
dissipated in the step (J), ``load`` its normal force (N), ``slip`` the
distance it slipped (m; zero in stick) and ``area`` its contact area (m²,
above zero). The worn body's kernel applies the depth to its vertex and adds
the volume to its worn volume; a worn counter-part takes the volume and
spreads it over the vertices of the face under the contact.

Adding a law is one :func:`register` call: a name, a numba function (inlined
into every kernel that wears: :func:`wear_increment` dispatches on the law's
code) and its numpy twin (the tests' reference, array at a time). The scene
checks, :func:`meshwear.kernels.contact.make_law` and the tests read the
names and codes from :data:`LAWS`; nothing else lists them. The anchor is
pynndescent's named distances: a dict from name to compiled function.
"""

from dataclasses import dataclass

import numpy as np
from .jit import njit


@dataclass(frozen=True)
class WearLaw:
    """One registry entry: ``increment`` (numba, scalars) and ``twin``
    (numpy, arrays) map ``(k, energy, load, slip, area)`` to ``(depth,
    volume)``; ``unit`` is the unit of its coefficient, ``summary`` one line
    for the docs and the scene errors."""

    name: str
    code: int
    increment: object
    twin: object
    unit: str
    summary: str


#: name -> :class:`WearLaw`, in code order
LAWS = {}


def register(name, increment, twin, unit, summary):
    """Add a law; its code is its place in :data:`LAWS`. Kernels compiled
    before the call do not know it (register at import, as the ones below)."""
    if name in LAWS:
        raise ValueError(f"wear law {name!r} is registered already")
    LAWS[name] = WearLaw(name, len(LAWS), njit(inline="always")(increment), twin, unit, summary)
    global wear_increment
    wear_increment = _dispatch(tuple(law.increment for law in LAWS.values()))
    return LAWS[name]


def code_of(name):
    """The kernel code of the law called ``name`` (KeyError if none)."""
    return LAWS[name].code


def name_of(code):
    """The name of the law of kernel code ``code``."""
    return next(name for name, law in LAWS.items() if law.code == code)


def _dispatch(increments):
    """``wear_increment(code, k, energy, load, slip, area)``: the increment of
    law ``code``, built as a chain of tests (numba compiles each link with the
    functions it holds as constants and inlines the whole chain)."""
    @njit(inline="always")
    def unknown(code, k, energy, load, slip, area):
        return 0.0, 0.0

    link = unknown
    for code, increment in enumerate(increments):
        link = _link(code, increment, link)
    return link


def _link(code, increment, rest):
    @njit(inline="always")
    def link(c, k, energy, load, slip, area):
        if c == code:
            return increment(k, energy, load, slip, area)
        return rest(c, k, energy, load, slip, area)
    return link


wear_increment = None


# ------------------------------------------------------------------ the laws
# (codes 0, 1, 2 are stored in checkpoints: append, never reorder)

def _energy(k, energy, load, slip, area):
    depth = k * energy
    return depth, depth * area


def _energy_twin(k, energy, load, slip, area):
    depth = k * np.asarray(energy, float)
    return depth, depth * area


register("energy", _energy, _energy_twin, "m/J",
         "depth = k E: the dissipated energy wears a depth (Fouvry's energy law, per point)")


def _energy_density(k, energy, load, slip, area):
    volume = k * energy
    return volume / area, volume


def _energy_density_twin(k, energy, load, slip, area):
    volume = k * np.asarray(energy, float)
    return volume / area, volume


register("energy_density", _energy_density, _energy_density_twin, "m³/J",
         "volume = k E: the dissipated energy wears a volume (Fouvry's energy law)")


def _archard(k, energy, load, slip, area):
    volume = k * load * slip
    return volume / area, volume


def _archard_twin(k, energy, load, slip, area):
    volume = k * np.asarray(load, float) * slip
    return volume / area, volume


register("archard", _archard, _archard_twin, "1/Pa",
         "volume = k N s: load times slip distance (Archard; k = K/H)")
