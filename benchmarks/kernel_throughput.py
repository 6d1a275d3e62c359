"""Throughput of the contact + friction + wear kernel, in vertex-steps per second.

Runs :func:`meshwear.kernels.contact.contact` (numba, 1 and all threads)
and its plain-numpy twin (tests/reference.py) on the same data: a flat grid of
contact points pressed on a plane and sliding back and forth, so the points
stick, slip and reverse like a real fretting contact. Compile time is reported
apart from the steady state. Prints a table, then the kernel against the
machine's memory bandwidth (a roofline: the bytes the kernel moves per
vertex-step, counted in :data:`TRAFFIC`, against a STREAM triad measured in the
same run), then one JSON line (docs/performance.md).

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
from numba import njit, prange

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import reference  # noqa: E402  (the numpy twin)

from meshwear.kernels import contact  # noqa: E402

#: Bytes the kernel moves per vertex-step in this benchmark (one plane, every
#: point in contact, Archard wear, no wear direction, no mesh surface), STREAM
#: convention: bytes read plus bytes written, no write-allocate fill counted.
#: Rows: array, bytes read, bytes written, when: "always" every vertex-step,
#: "wear" only in the steps the point wears (Archard: slip steps; the kernel
#: leaves wear_depth, wear_volume and body_vertices alone otherwise).
#: Counted at cache-line granularity where that is what the memory system
#: moves: a pair's friction record tangential[s, i] is 4 x 3 float64 = 96 B, so
#: two records fill three 64-B lines, and every one of those lines holds the
#: friction force F, written every step. Every line of the array is therefore
#: read (the state machine reads the anchor, F0 or the slip velocity in it, and
#: a partly written line must be fetched anyway) and written back: 96 + 96 B,
#: although the kernel touches 24-72 B of each record. normal_force is wholly
#: overwritten, so only its write counts. Per-step data (pose 13, law 13,
#: planes 12 floats, wrench 6) is O(1) per call and left out.
TRAFFIC = (
    ("active", 8, 0, "always"),              # int64 index of the vertex
    ("body_vertices", 24, 0, "always"),      # position in the body frame
    ("body_vertices", 0, 24, "wear"),        # moved by the wear step
    ("area", 32, 0, "always"),               # area vector and its length
    ("contact_state", 1, 1, "always"),       # int8 state, rewritten
    ("tangential", 96, 96, "always"),        # friction record (see above)
    ("normal_force", 0, 8, "always"),        # written only
    ("friction_work", 8, 8, "always"),       # E += energy
    ("wear_depth", 8, 8, "wear"),            # w += dw
    ("wear_volume", 8, 8, "wear"),           # V += dv
)

TRIAD_ELEMENTS = 20_000_000   # 3 x 160 MB, far beyond the last-level cache
TRIAD_BYTES = 24              # per element, STREAM: read b and c, write a


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


def drive(kernel, case, steps, after=None):
    """Run ``steps`` steps of a ±2 µm oscillation; return wall seconds.
    ``after(case)``, if given, is called after every step (untimed use only)."""
    vertices, pose, planes, params, law, direction, s = case
    start = time.perf_counter()
    for k in range(steps):
        phase = 2 * np.pi * k / 200.0
        pose[0] = 2e-6 * np.sin(phase)
        pose[7] = 2e-6 * 2 * np.pi / (200 * 1e-5) * np.cos(phase)
        kernel(vertices, pose, planes, s["vertex_planes"], s["active"], params, law, direction,
               s["contact_state"], s["tangential"],
               s["normal_force"], s["friction_work"], s["wear_depth"], s["wear_volume"], s["wrench"])
        if after is not None:
            after(case)
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


def wear_fraction(periods=10, n=16):
    """Fraction of vertex-steps in which a point wears (and a check that every
    point stays in contact), over whole periods of the benchmark's motion."""
    case = make_case(n)
    drive(contact.contact_serial, case, 200)  # one period to settle
    s = case[-1]
    counts = dict(wear=0, contact=0, last=s["wear_depth"].copy())

    def census(_):
        counts["wear"] += int(np.count_nonzero(s["wear_depth"] > counts["last"]))
        counts["contact"] += int(np.count_nonzero(s["contact_state"][0]))
        counts["last"] = s["wear_depth"].copy()

    drive(contact.contact_serial, case, 200 * periods, after=census)
    total = n * 200 * periods
    if counts["contact"] != total:
        raise RuntimeError("benchmark points left contact: TRAFFIC assumes they never do")
    return counts["wear"] / total


def bytes_per_vertex_step(wear):
    """Bytes read, bytes written per vertex-step from :data:`TRAFFIC`, the
    "wear" rows weighted by the fraction ``wear`` of vertex-steps that wear."""
    weight = {"always": 1.0, "wear": wear}
    read = sum(r * weight[w] for _, r, _, w in TRAFFIC)
    written = sum(x * weight[w] for _, _, x, w in TRAFFIC)
    return read, written


@njit(parallel=True)
def _triad(a, b, c, s):
    for i in prange(a.shape[0]):
        a[i] = b[i] + s * c[i]


def triad_bandwidth(threads, repeats=10):
    """Best-of-``repeats`` STREAM triad bandwidth (bytes/s) on ``threads`` threads,
    24 bytes per element (no write-allocate fill of ``a`` counted)."""
    a = np.empty(TRIAD_ELEMENTS)
    b = np.full(TRIAD_ELEMENTS, 1.0)
    c = np.full(TRIAD_ELEMENTS, 2.0)
    numba.set_num_threads(threads)
    _triad(a, b, c, 3.0)  # compile, and touch every page
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        _triad(a, b, c, 3.0)
        best = min(best, time.perf_counter() - t0)
    return TRIAD_BYTES * TRIAD_ELEMENTS / best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--seconds", type=float, default=0.5, help="minimum timed seconds per cell")
    parser.add_argument("--repeats", type=int, default=3,
                        help="measurements per cell, the best kept (the machine is shared)")
    args = parser.parse_args()
    threads = numba.config.NUMBA_NUM_THREADS
    print(f"machine: {platform.machine()} {platform.processor() or ''}, {os.cpu_count()} cores, "
          f"numba {numba.__version__}, {threads} threads, numpy {np.__version__}")
    # the triad before and after the kernel runs, best of both: the machine is shared
    triad_1 = triad_bandwidth(1)
    triad_all = triad_bandwidth(threads)
    rows = []
    for n in args.sizes:
        row = dict(points=n, serial=0.0, parallel_1=0.0, parallel_all=0.0, numpy=0.0)
        for repeat in range(args.repeats):  # best of the repeats, interleaved
            numba.set_num_threads(1)
            serial, compile_serial = measure(contact.contact_serial, n, args.seconds)
            numba.set_num_threads(1)
            par1, _ = measure(contact.contact_parallel, n, args.seconds)
            numba.set_num_threads(threads)
            par, compile_par = measure(contact.contact_parallel, n, args.seconds)
            twin, _ = measure(reference.contact, n, args.seconds)
            if repeat == 0:
                row["first_call_s"] = max(compile_serial, compile_par)
            for key, rate in (("serial", serial), ("parallel_1", par1), ("parallel_all", par),
                              ("numpy", twin)):
                row[key] = max(row[key], rate)
        rows.append(row)
    print(f"{'points':>9} {'numba 1 thread':>15} {'numba 1T (prange)':>18} "
          f"{'numba ' + str(threads) + ' threads':>16} {'numpy twin':>12} {'speed-up':>9}")
    for r in rows:
        print(f"{r['points']:>9} {r['serial']:>15.3e} {r['parallel_1']:>18.3e} "
              f"{r['parallel_all']:>16.3e} {r['numpy']:>12.3e} {r['parallel_all'] / r['numpy']:>8.1f}x")
    print(f"vertex-steps/s, best of {args.repeats}; first call (compile or cache load) at most "
          f"{max(r['first_call_s'] for r in rows):.2f} s")

    # roofline: the bytes each vertex-step moves against the triad bandwidth
    wear = wear_fraction()
    read, written = bytes_per_vertex_step(wear)
    per_step = read + written
    triad_1 = max(triad_1, triad_bandwidth(1))
    triad_all = max(triad_all, triad_bandwidth(threads))
    numba.set_num_threads(threads)
    print(f"\nbytes per vertex-step: {per_step:.1f} ({read:.1f} read + {written:.1f} written; "
          f"the point wears in {100 * wear:.0f} % of the steps)")
    print(f"triad a = b + s c, {TRIAD_ELEMENTS / 1e6:.0f}M float64 per array, best of 2 x 10: "
          f"{triad_1 / 1e9:.1f} GB/s on 1 thread, {triad_all / 1e9:.1f} GB/s on {threads}")
    print(f"{'points':>9} {'bytes/v-step':>13} {'1 thread GB/s':>14} {'roofline':>9} "
          f"{str(threads) + ' threads GB/s':>15} {'roofline':>9}")
    for r in rows:
        r["bytes_per_vertex_step"] = per_step
        r["roofline_fraction_1_thread"] = r["serial"] * per_step / triad_1
        r["roofline_fraction"] = r["parallel_all"] * per_step / triad_all
        print(f"{r['points']:>9} {per_step:>13.1f} {r['serial'] * per_step / 1e9:>14.2f} "
              f"{100 * r['roofline_fraction_1_thread']:>8.0f}% "
              f"{r['parallel_all'] * per_step / 1e9:>15.2f} {100 * r['roofline_fraction']:>8.0f}%")
    print("roofline: kernel bytes/s (vertex-steps/s x bytes per vertex-step) over the triad's "
          "on as many threads")
    best = max(rows, key=lambda r: r["parallel_all"])
    largest = max(rows, key=lambda r: r["points"])
    print(json.dumps({
        "benchmark": "kernel_throughput",
        "threads": threads,
        "points": best["points"],
        "vertex_steps_per_s": best["parallel_all"],
        "vertex_steps_per_s_1_thread": best["serial"],
        "numpy_vertex_steps_per_s": best["numpy"],
        "speedup_vs_numpy": best["parallel_all"] / best["numpy"],
        "bytes_per_vertex_step": per_step,
        "bytes_read_per_vertex_step": read,
        "bytes_written_per_vertex_step": written,
        "wear_fraction": wear,
        "triad_bytes_per_s": triad_all,
        "triad_bytes_per_s_1_thread": triad_1,
        "roofline_points": largest["points"],
        "roofline_fraction": largest["roofline_fraction"],
        "roofline_fraction_1_thread": largest["roofline_fraction_1_thread"],
        "rows": rows,
    }))


if __name__ == "__main__":
    main()
