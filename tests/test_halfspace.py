"""The elastic half-space solver (meshwear/halfspace.py) against the closed
forms of docs/physics-tests.md: Hertz (sphere and cylinder on a flat), the
rigid flat punch, Cattaneo-Mindlin's stick radius and Mindlin-Deresiewicz's
energy per fretting cycle. Two steel bodies, E = 210 GPa, nu = 0.3."""

import numpy as np
import pytest

from meshwear.contact.halfspace import contact_modulus, make_grid, solve, solve_shear

from cases import fretting_loop, mindlin_deresiewicz

E, NU = 210e9, 0.3
G = E / (2.0 * (1.0 + NU))
E_STAR = contact_modulus((E, E), (NU, NU))
R, LOAD, MU = 0.01, 10.0, 0.5
#: Hertz: contact radius, peak pressure and approach of the sphere
A = (3.0 * LOAD * R / (4.0 * E_STAR)) ** (1.0 / 3.0)
P0 = 3.0 * LOAD / (2.0 * np.pi * A * A)
APPROACH = A * A / R


def _ellipse_fit(r2, p):
    """``(peak, radius)`` of ``p = peak sqrt(1 - r^2 / radius^2)`` fitted
    to the cells carrying more than a third of the peak (p^2 is linear in
    r^2)."""
    k = p > p.max() / 3.0
    c0, c1 = np.linalg.lstsq(np.vstack([np.ones(k.sum()), r2[k]]).T, p[k] ** 2, rcond=None)[0]
    return np.sqrt(c0), np.sqrt(-c0 / c1)


@pytest.fixture(scope="module")
def sphere():
    n = 64
    grid = make_grid((n, n), 3.0 * A / n, (E, E), (NU, NU))
    x, y = np.meshgrid(*grid.centres, indexing="ij")
    solution = solve(grid, (x * x + y * y) / (2.0 * R), LOAD)
    return grid, x * x + y * y, solution


def test_hertz_sphere_contact_radius_peak_pressure_and_approach(sphere):
    grid, r2, solution = sphere
    p = solution.traction
    assert p.sum() * grid.cell_area == pytest.approx(LOAD, rel=1e-12)
    peak, radius = _ellipse_fit(r2, p)
    assert radius == pytest.approx(A, rel=0.01)
    assert p.max() == pytest.approx(P0, rel=0.01)
    assert peak == pytest.approx(P0, rel=0.01)
    assert solution.approach == pytest.approx(APPROACH, rel=0.01)
    # the contact conditions: no overlap, no gap under pressure
    assert solution.gap.min() >= -1e-6 * APPROACH
    assert np.all(np.abs(solution.gap[p > 0.0]) <= 1e-6 * APPROACH)


def test_hertz_cylinder_on_a_flat_half_width_and_peak_pressure():
    """Plane strain, a load per unit length."""
    load = 1e5                                                   # N/m
    half = np.sqrt(4.0 * load * R / (np.pi * E_STAR))
    peak = 2.0 * load / (np.pi * half)
    n = 128
    grid = make_grid((n,), 3.0 * half / n, (E, E), (NU, NU))
    x = grid.centres[0]
    p = solve(grid, x * x / (2.0 * R), load).traction
    fitted, width = _ellipse_fit(x * x, p)
    assert width == pytest.approx(half, rel=0.01)
    assert p.max() == pytest.approx(peak, rel=0.01)
    assert fitted == pytest.approx(peak, rel=0.01)


def test_a_rigid_flat_punch_takes_p_equal_2_a_e_star_delta():
    radius, load, n = 1e-3, 100.0, 128
    grid = make_grid((n, n), 2.4 * radius / n, (E, E), (NU, NU))
    x, y = np.meshgrid(*grid.centres, indexing="ij")
    solution = solve(grid, np.zeros((n, n)), load, mask=x * x + y * y <= radius * radius)
    assert load == pytest.approx(2.0 * radius * E_STAR * solution.approach, rel=0.01)


@pytest.mark.parametrize("share", [0.3, 0.6, 0.9])
def test_cattaneo_mindlin_stick_radius(sphere, share):
    grid, r2, solution = sphere
    q, stick, shift = solve_shear(grid, solution.traction, MU, share * MU * LOAD)
    assert q.sum() * grid.cell_area == pytest.approx(share * MU * LOAD, rel=1e-9)
    assert np.all(np.abs(q) <= MU * solution.traction * (1.0 + 1e-9))
    # the stick reserve mu p - q is Mindlin's (c / a) mu p0 sqrt(1 - r^2 / c^2)
    _, stick_radius = _ellipse_fit(r2, MU * solution.traction - q)
    assert stick_radius == pytest.approx(A * (1.0 - share) ** (1.0 / 3.0), rel=0.02)
    # and the bodies shift by 3 mu P C_t / (16 a) [1 - (1 - Q / mu P)^(2/3)]
    compliance = 2.0 * (2.0 - NU) / G
    expected = 3.0 * MU * LOAD * compliance / (16.0 * A) * (1.0 - (1.0 - share) ** (2.0 / 3.0))
    assert shift == pytest.approx(expected, rel=0.01)


@pytest.mark.parametrize("share", [0.3, 0.6, 0.9])
def test_mindlin_deresiewicz_energy_per_fretting_cycle(sphere, share):
    """Q from +Q* to -Q* and back, every point a segment solved from the
    turning point's shear: the loop's area against
    (9/10) mu^2 P^2 C_t / a [1 - (1 - x)^(5/3) - (5x/6)(1 + (1 - x)^(2/3))]."""
    grid, _, solution = sphere
    loop, s_top, s_bottom = fretting_loop(grid, solution.traction, MU, share * MU * LOAD)
    expected = mindlin_deresiewicz(MU, LOAD, 2.0 * (2.0 - NU) / G, A, share)
    assert loop == pytest.approx(expected, rel=0.03)
    assert s_bottom == pytest.approx(-s_top, rel=1e-3)           # the loop closes


def test_a_warm_start_converges_to_the_same_pressure_in_fewer_iterations(sphere):
    grid, r2, solution = sphere
    x, y = np.meshgrid(*grid.centres, indexing="ij")
    gap = (x * x + y * y) / (2.0 * R)
    heavier = solve(grid, gap, 1.05 * LOAD)
    warm = solve(grid, gap, 1.05 * LOAD, start=solution.traction)
    assert warm.iterations < heavier.iterations
    assert np.abs(warm.traction - heavier.traction).max() <= 1e-6 * heavier.traction.max()


def test_the_iterations_hardly_grow_with_the_grid_and_each_convolves_about_once():
    """Work counts (docs/model.md, "Elastic half-space"): the preconditioned
    gradient's iterations on Hertz's sphere barely grow from 32² to 128²
    cells (the plain gradient's double), and an iteration convolves its
    direction only, the traction again only where the contact changed."""
    iterations, convolutions = {}, {}
    for n in (32, 128):
        grid = make_grid((n, n), 3.0 * A / n, (E, E), (NU, NU))
        count = []
        convolve = grid.convolve
        grid.convolve = lambda traction, kernel="normal": (count.append(1),
                                                           convolve(traction, kernel))[1]
        x, y = np.meshgrid(*grid.centres, indexing="ij")
        solution = solve(grid, (x * x + y * y) / (2.0 * R), LOAD)
        assert solution.traction.max() == pytest.approx(P0, rel=0.01)
        iterations[n], convolutions[n] = solution.iterations, len(count)
    assert iterations[128] <= 1.5 * iterations[32]
    assert convolutions[128] < 2 * iterations[128]
