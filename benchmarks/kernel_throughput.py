"""Throughput of the contact + friction + wear kernel, in vertex-steps per second.

Runs :func:`meshwear.kernels.contact.contact` (numba, 1 and all threads)
and its plain-numpy twin (tests/reference.py) on the same data: a flat grid of
contact points pressed on a plane and sliding back and forth, so the points
stick, slip and reverse like a real fretting contact. Compile time is reported
apart from the steady state. Prints a table, then one JSON line (DESIGN.md §6).

    python benchmarks/kernel_throughput.py [--sizes 10000 100000 1000000]
"""

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import reference  # noqa: E402  (the numpy twin)

from meshwear.kernels import contact  # noqa: E402


def make_case(n):
    """n contact points on a square grid 1 µm into a plane, sliding along x."""
    side = int(np.ceil(np.sqrt(n)))
    g = (np.arange(n) % side, np.arange(n) // side)
    vertices = np.zeros((n, 3))
    vertices[:, 0] = g[0] * 1e-4
    vertices[:, 1] = g[1] * 1e-4
    pose = np.zeros(13)
    pose[3] = 1.0
    pose[2] = -1e-6
    planes = np.zeros((1, 4, 3))
    planes[0, 1, 2] = 1.0
    params = np.zeros((n, 4))  # area vectors: 0.01 mm² each, facing the plane
    params[:, 2], params[:, 3] = -1e-8, 1e-8
    # Winkler contact: 1e12 N/m³ normal and tangential, light damping
    law = contact.make_law(friction=0.3, static_friction=0.3, wear_law="archard",
                           wear_coefficient=1e-15, dt=1e-5,
                           stiffness_per_area=1e12, damping_per_area=1e7,
                           tangential_stiffness_per_area=1e12, tangential_damping_per_area=1e7)
    state = dict(contact_state=np.zeros((1, n), np.int8), tangential=np.zeros((1, n, 4, 3)),
                 normal_force=np.zeros((1, n)), friction_work=np.zeros(n), wear_depth=np.zeros(n),
                 wear_volume=np.zeros(n), wrench=np.zeros(6),
                 vertex_planes=contact.no_mesh_planes(n), active=contact.all_vertices(n))
    return vertices, pose, planes, params, law, np.zeros((0, 3)), state


def drive(kernel, case, steps):
    """Run ``steps`` steps of a ±2 µm oscillation; return wall seconds."""
    vertices, pose, planes, params, law, direction, s = case
    start = time.perf_counter()
    for k in range(steps):
        phase = 2 * np.pi * k / 200.0
        pose[0] = 2e-6 * np.sin(phase)
        pose[7] = 2e-6 * 2 * np.pi / (200 * 1e-5) * np.cos(phase)
        kernel(vertices, pose, planes, s["vertex_planes"], s["active"], params, law, direction,
               s["contact_state"], s["tangential"],
               s["normal_force"], s["friction_work"], s["wear_depth"], s["wear_volume"], s["wrench"])
    return time.perf_counter() - start


def measure(kernel, n, min_seconds=0.5):
    case = make_case(n)
    t0 = time.perf_counter()
    drive(kernel, case, 1)
    first = time.perf_counter() - t0
    steps = 4
    while True:
        elapsed = drive(kernel, case, steps)
        if elapsed >= min_seconds or steps >= 10 ** 6:
            break
        steps = int(steps * max(2.0, 1.2 * min_seconds / max(elapsed, 1e-9)))
    return n * steps / elapsed, first


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--seconds", type=float, default=0.5, help="minimum timed seconds per cell")
    args = parser.parse_args()
    threads = numba.config.NUMBA_NUM_THREADS
    print(f"machine: {platform.machine()} {platform.processor() or ''}, {os.cpu_count()} cores, "
          f"numba {numba.__version__}, {threads} threads, numpy {np.__version__}")
    rows = []
    for n in args.sizes:
        numba.set_num_threads(1)
        serial, compile_serial = measure(contact.contact_serial, n, args.seconds)
        numba.set_num_threads(1)
        par1, _ = measure(contact.contact_parallel, n, args.seconds)
        numba.set_num_threads(threads)
        par, compile_par = measure(contact.contact_parallel, n, args.seconds)
        twin, _ = measure(reference.contact, n, args.seconds)
        rows.append(dict(points=n, serial=serial, parallel_1=par1, parallel_all=par, numpy=twin,
                         first_call_s=max(compile_serial, compile_par)))
    print(f"{'points':>9} {'numba 1 thread':>15} {'numba 1T (prange)':>18} "
          f"{'numba ' + str(threads) + ' threads':>16} {'numpy twin':>12} {'speed-up':>9}")
    for r in rows:
        print(f"{r['points']:>9} {r['serial']:>15.3e} {r['parallel_1']:>18.3e} "
              f"{r['parallel_all']:>16.3e} {r['numpy']:>12.3e} {r['parallel_all'] / r['numpy']:>8.1f}x")
    print("vertex-steps/s; first call (compile or cache load) at most "
          f"{max(r['first_call_s'] for r in rows):.2f} s")
    best = max(rows, key=lambda r: r["parallel_all"])
    print(json.dumps({
        "benchmark": "kernel_throughput",
        "threads": threads,
        "points": best["points"],
        "vertex_steps_per_s": best["parallel_all"],
        "vertex_steps_per_s_1_thread": best["serial"],
        "numpy_vertex_steps_per_s": best["numpy"],
        "speedup_vs_numpy": best["parallel_all"] / best["numpy"],
        "rows": rows,
    }))


if __name__ == "__main__":
    main()
