"""The wear-law registry (meshwear/kernels/laws.py): each law's compiled
increment against its numpy twin and its closed form, and a new law as one
entry that the scene checks, the dispatch and the twins all see."""

import numpy as np
import pytest
from numba import njit

from meshwear.kernels import laws
from meshwear.scene.settings import WearConfig
from meshwear.scene.checks import SceneError


@njit(cache=True)
def _increments(code, k, energy, load, slip, area):
    depth, volume = np.empty(energy.shape[0]), np.empty(energy.shape[0])
    for i in range(energy.shape[0]):
        depth[i], volume[i] = laws.wear_increment(code, k, energy[i], load[i], slip[i], area[i])
    return depth, volume


def _inputs(n=64, seed=3):
    rng = np.random.default_rng(seed)
    slip = rng.uniform(0.0, 1e-5, n)
    slip[::4] = 0.0                      # pairs that stick
    return (rng.uniform(0.0, 1e-6, n), rng.uniform(0.0, 5.0, n), slip,
            rng.uniform(1e-9, 1e-7, n))


@pytest.mark.parametrize("name", list(laws.LAWS))
def test_compiled_increment_matches_its_twin(name):
    law = laws.LAWS[name]
    energy, load, slip, area = _inputs()
    depth, volume = _increments(law.code, 2e-9, energy, load, slip, area)
    twin_depth, twin_volume = law.twin(2e-9, energy, load, slip, area)
    np.testing.assert_allclose(depth, twin_depth, rtol=1e-14, atol=0.0)
    np.testing.assert_allclose(volume, twin_volume, rtol=1e-14, atol=0.0)


def test_each_law_is_its_closed_form():
    """docs/model.md, "Wear": energy wears a depth k E, energy_density a
    volume k E, archard a volume k N s (nothing while a pair sticks)."""
    energy, load, slip, area = _inputs()
    k = 3e-10
    depth, volume = _increments(laws.code_of("energy"), k, energy, load, slip, area)
    np.testing.assert_allclose(depth, k * energy, rtol=1e-15)
    np.testing.assert_allclose(volume, k * energy * area, rtol=1e-15)
    depth, volume = _increments(laws.code_of("energy_density"), k, energy, load, slip, area)
    np.testing.assert_allclose(volume, k * energy, rtol=1e-15)
    np.testing.assert_allclose(depth * area, k * energy, rtol=1e-14)
    depth, volume = _increments(laws.code_of("archard"), k, energy, load, slip, area)
    np.testing.assert_allclose(volume, k * load * slip, rtol=1e-15)
    assert (volume[slip == 0.0] == 0.0).all() and (depth[slip == 0.0] == 0.0).all()


def test_codes_are_stable():
    """Checkpoints store codes: the first three never move."""
    assert [laws.code_of(n) for n in ("energy", "energy_density", "archard")] == [0, 1, 2]


def test_a_fourth_law_is_one_entry():
    saved = dict(laws.LAWS), laws.wear_increment

    def power(k, energy, load, slip, area):
        volume = k * load * load * slip   # a load exponent of 2
        return volume / area, volume

    def power_twin(k, energy, load, slip, area):
        volume = k * np.asarray(load) ** 2 * slip
        return volume / area, volume

    try:
        law = laws.register("load_squared", power, power_twin, "m/N²",
                            "volume = k N² s (a test law)")
        assert law.code == len(saved[0])
        with pytest.raises(ValueError, match="registered already"):
            laws.register("load_squared", power, power_twin, "m/N²", "again")

        # a kernel compiled after the entry dispatches to it
        @njit
        def increments(code, k, energy, load, slip, area):
            out = np.empty((2, energy.shape[0]))
            for i in range(energy.shape[0]):
                out[0, i], out[1, i] = laws.wear_increment(code, k, energy[i], load[i], slip[i],
                                                           area[i])
            return out

        energy, load, slip, area = _inputs()
        depth, volume = increments(law.code, 1e-9, energy, load, slip, area)
        np.testing.assert_allclose(volume, power_twin(1e-9, energy, load, slip, area)[1],
                                   rtol=1e-14)
        # the scene accepts it by name, and still names the choices when wrong
        assert WearConfig(law="load_squared").law == "load_squared"
        with pytest.raises(SceneError, match="load_squared"):
            WearConfig(law="load_square")
    finally:
        laws.LAWS.clear()
        laws.LAWS.update(saved[0])
        laws.wear_increment = saved[1]
