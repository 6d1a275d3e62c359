"""What the elastic half-space solver (meshwear/halfspace.py) costs on patch grids.

For a Hertz sphere on a flat (steel, R = 10 mm, 10 N) on grids of 32² to
256² cells over three contact radii: the normal solve from a uniform start
and warm from the solution at a 5 % lower load (a step of a run), the
Cattaneo-Mindlin shear solve at Q = 0.6 mu P, each against the same run's
reference, one FFT convolution of the grid (the solver's unit of work), and
the error of the peak pressure against Hertz. Prints a table and, last, one
JSON line.

    .venv/bin/python benchmarks/halfspace_solver.py
"""

import json
import time

import numpy as np

from meshwear.halfspace import contact_modulus, make_grid, solve, solve_shear

E, NU, R, LOAD, MU = 210e9, 0.3, 0.01, 10.0, 0.5


def best(function, repeat=3):
    """The fastest of ``repeat`` calls (s) and the last result."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        out = function()
        times.append(time.perf_counter() - start)
    return min(times), out


def main():
    e_star = contact_modulus((E, E), (NU, NU))
    a = (3.0 * LOAD * R / (4.0 * e_star)) ** (1.0 / 3.0)
    p0 = 3.0 * LOAD / (2.0 * np.pi * a * a)
    rows = []
    print(f"{'grid':>8}{'FFT conv (ms)':>15}{'cold (ms)':>11}{'iter':>6}{'warm (ms)':>11}"
          f"{'iter':>6}{'shear (ms)':>12}{'cold / conv':>13}{'p0 error':>10}")
    for n in (32, 64, 128, 256):
        grid = make_grid((n, n), 3.0 * a / n, (E, E), (NU, NU))
        x, y = np.meshgrid(*grid.centres, indexing="ij")
        gap = (x * x + y * y) / (2.0 * R)
        field = np.random.default_rng(0).random((n, n))
        conv, _ = best(lambda: grid.convolve(field), 5)
        cold, s = best(lambda: solve(grid, gap, LOAD))
        lower = solve(grid, gap, 0.95 * LOAD).traction
        warm, w = best(lambda: solve(grid, gap, LOAD, start=lower))
        shear, _ = best(lambda: solve_shear(grid, s.traction, MU, 0.6 * MU * LOAD))
        row = {"cells": n * n, "convolution_ms": 1e3 * conv, "cold_ms": 1e3 * cold,
               "cold_iterations": s.iterations, "warm_ms": 1e3 * warm,
               "warm_iterations": w.iterations, "shear_ms": 1e3 * shear,
               "cold_over_convolution": cold / conv,
               "peak_error": float(s.traction.max() / p0 - 1.0)}
        rows.append(row)
        print(f"{n:>5}²  {row['convolution_ms']:>13.3f}{row['cold_ms']:>11.2f}"
              f"{row['cold_iterations']:>6}{row['warm_ms']:>11.2f}{row['warm_iterations']:>6}"
              f"{row['shear_ms']:>12.2f}{row['cold_over_convolution']:>13.0f}"
              f"{row['peak_error']:>10.1e}")
    print(json.dumps({"benchmark": "halfspace_solver", "rows": rows}))


if __name__ == "__main__":
    main()
