"""What the elastic half-space solver (meshwear/halfspace.py) costs on patch grids, against Tamaas.

For a Hertz sphere on a flat (steel, R = 10 mm, 10 N) on grids of 32² to
256² cells over three contact radii: the normal solve from a uniform start
and warm from the solution at a 5 % lower load (a step of a run), the
Cattaneo-Mindlin shear solve at Q = 0.6 mu P, the solve started from its
own solution (what a converged solver costs to confirm), one FFT
convolution of the grid (the solver's unit of work), and the error of the
peak pressure against Hertz; then a step of a sliding run at looser
tolerances (128²).

When Tamaas (EPFL's contact library, AGPL-3.0: the optional ``bench``
extra, never imported by ``meshwear/``) is importable, the same problem is
solved in the same run by its Polonsky-Keer-Rey solver (tolerance 10⁻¹²),
set up two ways: as issue 42 measured it, periodic on a grid twice as wide
(6 a, 2n cells a side: the periodic images bias its peak), and with its own
DC-FFT operator on the same n² cells (non-periodic: the same discretisation
as ours, so the same peak error). Tamaas starts a solve from the traction
its model holds: its "cold" solves start from zero traction (a uniform
pressure, as ours), its "re-solve" from its own solution, which is what
timing repeated ``solve`` calls measures. Prints our table, the sliding
step's, Tamaas's beside ours (skipped without it) and, last, one JSON line.

    .venv/bin/python benchmarks/halfspace_solver.py [--grids 32 64 128 256] [--workers 1]

Times are the fastest of five calls (of three for Tamaas's), in one
process: on a shared machine, compare medians of a few runs.
"""

import argparse
import json
import os
import platform
import re
import tempfile
import time

import numpy as np
from scipy import fft

from meshwear.contact.halfspace import contact_modulus, make_grid, solve, solve_shear

try:
    import tamaas
except ImportError:                      # the comparison is skipped
    tamaas = None

E, NU, R, LOAD, MU = 210e9, 0.3, 0.01, 10.0, 0.5
TAMAAS_TOLERANCE = 1e-12


def best(function, repeat=5, before=None):
    """The fastest of ``repeat`` calls (s) and the last result; ``before``
    is called ahead of each, untimed."""
    times = []
    for _ in range(repeat):
        if before is not None:
            before()
        start = time.perf_counter()
        out = function()
        times.append(time.perf_counter() - start)
    return min(times), out


def tamaas_iterations(solver, pressure):
    """The iterations of one Tamaas solve: its log's last row (the library
    logs to the process's standard error)."""
    tamaas.set_log_level(tamaas.LogLevel.info)
    saved = os.dup(2)
    with tempfile.TemporaryFile("w+") as log:
        os.dup2(log.fileno(), 2)
        try:
            solver.solve(pressure)
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tamaas.set_log_level(tamaas.LogLevel.error)
        log.seek(0)
        rows = re.findall(r"^\s*(\d+)\s+\S+\s+\S+\s*$", log.read(), re.MULTILINE)
    return int(rows[-1]) if rows else -1


def tamaas_hertz(n, a, p0, periodic):
    """Tamaas on the Hertz problem: periodic on 2n cells over 6 a, or its
    DC-FFT operator on n cells over 3 a. Returns the cold solve's time (s)
    and iterations, the re-solve's time, and the peak pressure's error."""
    m, side = (2 * n, 6.0 * a) if periodic else (n, 3.0 * a)
    model = tamaas.ModelFactory.createModel(tamaas.model_type.basic_2d, [side, side], [m, m])
    e_star = contact_modulus((E, E), (NU, NU))
    model.E, model.nu = e_star * (1.0 - NU * NU), NU     # its E* against a rigid surface
    x = side / m * (np.arange(m) - 0.5 * (m - 1))
    x, y = np.meshgrid(x, x, indexing="ij")
    solver = tamaas.PolonskyKeerRey(model, -(x * x + y * y) / (2.0 * R), TAMAAS_TOLERANCE)
    if not periodic:
        tamaas.ModelFactory.registerNonPeriodic(model, "dcfft")
        solver.setIntegralOperator("dcfft")
    pressure = LOAD / (side * side)
    solver.solve(pressure)                 # its FFT plans, made once per grid

    def reset():
        model.traction[...] = 0.0

    reset()
    iterations = tamaas_iterations(solver, pressure)
    cold, _ = best(lambda: solver.solve(pressure), 3, before=reset)
    again, _ = best(lambda: solver.solve(pressure), 3)
    error = float(np.asarray(model.traction).max() / p0 - 1.0)
    return cold, iterations, again, error


def sliding_step(a, n=128, shift=0.3):
    """A step of a sliding run on the n² grid: the sphere moved by ``shift``
    of a cell along x, solved at looser tolerances from a uniform start
    (cold) and from the unmoved solution (warm). Rows: tolerance,
    iterations and time cold and warm, and the largest error of the
    pressure against the moved sphere's solve at the default tolerance, in
    parts of its peak."""
    grid = make_grid((n, n), 3.0 * a / n, (E, E), (NU, NU))
    x, y = np.meshgrid(*grid.centres, indexing="ij")
    before = solve(grid, (x * x + y * y) / (2.0 * R), LOAD).traction
    x = x - shift * grid.spacing[0]
    gap = (x * x + y * y) / (2.0 * R)
    exact = solve(grid, gap, LOAD).traction
    rows = []
    for tol in (1e-10, 1e-6, 1e-4):
        cold, c = best(lambda: solve(grid, gap, LOAD, tol=tol))
        warm, w = best(lambda: solve(grid, gap, LOAD, tol=tol, start=before))
        rows.append({"tolerance": tol, "cold_ms": 1e3 * cold, "cold_iterations": c.iterations,
                     "warm_ms": 1e3 * warm, "warm_iterations": w.iterations,
                     "cold_error": float(np.abs(c.traction - exact).max() / exact.max()),
                     "warm_error": float(np.abs(w.traction - exact).max() / exact.max())})
    return rows


def ours(grids):
    """Our table: a row per grid, the sliding step's rows, a and p0."""
    e_star = contact_modulus((E, E), (NU, NU))
    a = (3.0 * LOAD * R / (4.0 * e_star)) ** (1.0 / 3.0)
    p0 = 3.0 * LOAD / (2.0 * np.pi * a * a)
    print(f"{platform.machine()}, {os.cpu_count()} cores, scipy.fft workers {fft.get_workers()}; "
          + (f"tamaas {tamaas.__version__}" if tamaas is not None
             else "tamaas not installed (pip install -e '.[bench]'): no comparison"))
    rows = []
    print(f"{'grid':>8}{'FFT conv (ms)':>15}{'cold (ms)':>11}{'iter':>6}{'warm (ms)':>11}"
          f"{'iter':>6}{'shear (ms)':>12}{'re-solve (ms)':>15}{'cold / conv':>13}{'p0 error':>10}")
    for n in grids:
        grid = make_grid((n, n), 3.0 * a / n, (E, E), (NU, NU))
        x, y = np.meshgrid(*grid.centres, indexing="ij")
        gap = (x * x + y * y) / (2.0 * R)
        field = np.random.default_rng(0).random((n, n))
        conv, _ = best(lambda: grid.convolve(field), 5)
        cold, s = best(lambda: solve(grid, gap, LOAD))
        lower = solve(grid, gap, 0.95 * LOAD).traction
        warm, w = best(lambda: solve(grid, gap, LOAD, start=lower))
        shear, _ = best(lambda: solve_shear(grid, s.traction, MU, 0.6 * MU * LOAD))
        again, _ = best(lambda: solve(grid, gap, LOAD, start=s.traction))
        row = {"cells": n * n, "convolution_ms": 1e3 * conv, "cold_ms": 1e3 * cold,
               "cold_iterations": s.iterations, "warm_ms": 1e3 * warm,
               "warm_iterations": w.iterations, "shear_ms": 1e3 * shear,
               "resolve_ms": 1e3 * again, "cold_over_convolution": cold / conv,
               "peak_error": float(s.traction.max() / p0 - 1.0)}
        rows.append(row)
        print(f"{n:>5}²  {row['convolution_ms']:>13.3f}{row['cold_ms']:>11.2f}"
              f"{row['cold_iterations']:>6}{row['warm_ms']:>11.2f}{row['warm_iterations']:>6}"
              f"{row['shear_ms']:>12.2f}{row['resolve_ms']:>15.2f}"
              f"{row['cold_over_convolution']:>13.0f}{row['peak_error']:>10.1e}")
    print("\na step of a sliding run: 128², the sphere moved by 0.3 of a cell, from a uniform "
          "start (cold) and from the unmoved solution (warm)")
    print(f"{'tolerance':>10}{'cold (ms)':>11}{'iter':>6}{'error':>10}{'warm (ms)':>11}{'iter':>6}"
          f"{'error':>10}")
    slide = sliding_step(a)
    for row in slide:
        print(f"{row['tolerance']:>10.0e}{row['cold_ms']:>11.2f}{row['cold_iterations']:>6}"
              f"{row['cold_error']:>10.1e}{row['warm_ms']:>11.2f}{row['warm_iterations']:>6}"
              f"{row['warm_error']:>10.1e}")
    return rows, slide, a, p0


def against_tamaas(rows, a, p0):
    """Tamaas on each of our rows' grids, printed beside ours (added to the rows)."""
    tamaas.set_log_level(tamaas.LogLevel.error)
    print("\nagainst Tamaas, the same problem (ms; iterations in brackets; ratio: ours / Tamaas)")
    print(f"{'grid':>6}{'ours cold':>16}{'Tamaas 2n periodic':>21}{'ratio':>7}"
          f"{'Tamaas DC-FFT':>17}{'ratio':>7}{'ours re-solve':>15}{'Tamaas re-solve':>17}"
          f"{'ratio':>7}{'p0 error: ours':>16}{'periodic':>10}{'DC-FFT':>10}")
    for row in rows:
        n = int(round(row["cells"] ** 0.5))
        periodic = tamaas_hertz(n, a, p0, periodic=True)
        dcfft = tamaas_hertz(n, a, p0, periodic=False)
        row["tamaas"] = {
            "periodic_cold_ms": 1e3 * periodic[0], "periodic_iterations": periodic[1],
            "periodic_resolve_ms": 1e3 * periodic[2], "periodic_peak_error": periodic[3],
            "dcfft_cold_ms": 1e3 * dcfft[0], "dcfft_iterations": dcfft[1],
            "dcfft_resolve_ms": 1e3 * dcfft[2], "dcfft_peak_error": dcfft[3]}
        t = row["tamaas"]
        print(f"{n:>3}²  {row['cold_ms']:>9.2f} ({row['cold_iterations']:>3})"
              f"{t['periodic_cold_ms']:>14.2f} ({t['periodic_iterations']:>3})"
              f"{row['cold_ms'] / t['periodic_cold_ms']:>7.2f}"
              f"{t['dcfft_cold_ms']:>10.2f} ({t['dcfft_iterations']:>3})"
              f"{row['cold_ms'] / t['dcfft_cold_ms']:>7.2f}"
              f"{row['resolve_ms']:>15.2f}{t['periodic_resolve_ms']:>17.2f}"
              f"{row['resolve_ms'] / t['periodic_resolve_ms']:>7.2f}"
              f"{row['peak_error']:>16.1e}{t['periodic_peak_error']:>10.1e}"
              f"{t['dcfft_peak_error']:>10.1e}")



def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grids", type=int, nargs="+", default=[32, 64, 128, 256],
                        help="cells a side of each grid")
    parser.add_argument("--workers", type=int, default=1,
                        help="threads of our FFTs (scipy.fft.set_workers; Tamaas runs serial)")
    args = parser.parse_args()
    with fft.set_workers(args.workers):
        rows, slide, a, p0 = ours(args.grids)
    if tamaas is not None:
        against_tamaas(rows, a, p0)
    print(json.dumps({"benchmark": "halfspace_solver", "workers": args.workers,
                      "tamaas": tamaas.__version__ if tamaas is not None else None,
                      "rows": rows, "sliding_step": slide}))


if __name__ == "__main__":
    main()
