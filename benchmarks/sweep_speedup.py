"""Sweep speed-up: 8 runs of a scene on a LocalCluster (``meshwear sweep``,
one process per core, one numba thread each) against the same 8 runs one
after another in one process (``meshwear.run`` in a loop, warm: the kernels
loaded before the clock starts), measured in the same run.

    .venv/bin/python benchmarks/sweep_speedup.py [--runs 8] [--duration S ...] [--page]

Prints both wall times, the ratio and the runs' vertex-steps/s for runs of
two lengths, and what bounds the ratio (the processes slow each other down;
starting the cluster and loading the kernels); ``--page`` writes the table
into docs/sweeps.md. The cluster's time includes starting it and the
workers' imports.
"""

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import meshwear
from meshwear.sweep import from_arguments, run_sweep

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "pin_on_disc.toml"
#: the varied key: the load, so each run differs
KEY = "body[0].force"
#: s of each run: 1000 and 2500 turns of the disc (200 000 and 500 000 steps,
#: about 4 and 11 s of wall time)
DURATIONS = [1000.0, 2500.0]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=8)
    parser.add_argument("--duration", type=float, nargs="+", default=DURATIONS,
                        help="s of each run, one sweep per value (default %(default)s)")
    parser.add_argument("--page", action="store_true", help="write docs/sweeps.md's table")
    args = parser.parse_args(argv)
    # load the kernels before the clock starts: a warm loop
    meshwear.run(meshwear.load(SCENE, {"run.duration": 0.05, "run.frames": 2,
                                       "run.history": 2}))
    table = ["| runs of pin_on_disc | one after another, one process (reference) | "
             f"on a LocalCluster of {_workers()} processes (`meshwear sweep`) | ratio | "
             "a run alone / side by side | ceiling | overhead |",
             "|---|---|---|---|---|---|---|"]
    figures = []
    for duration in args.duration:
        row, numbers = _compare(args.runs, duration)
        table.append(row)
        figures.append(numbers)
        print(table[-1], flush=True)
    notes = [
        "",
        "Vertex-steps/s in brackets. *A run alone / side by side*: a run's own wall time in "
        "the loop and in the cluster, where the processes run at once and each is slower; "
        "*ceiling*: the ratio with no overhead at all (processes × alone / side by side); "
        "*overhead*: starting the cluster, loading the kernels in each worker and closing it.",
    ]
    print("\n".join(table + notes))
    if args.page:
        from common import replace_section

        replace_section(ROOT / "docs" / "sweeps.md", "<!-- speedup -->", "<!-- /speedup -->",
                        "<!-- speedup -->\n" + "\n".join(table + notes) + "\n<!-- /speedup -->")
    print(json.dumps({"benchmark": "sweep_speedup", "workers": _workers(), "runs": args.runs,
                      "sweeps": figures}))
    return 0


def _compare(runs, duration):
    """One table row: ``runs`` runs of ``duration`` s in a loop and in a sweep."""
    loads = [[0.0, 0.0, -(5.0 + i)] for i in range(runs)]
    sweep = from_arguments(SCENE, [f"{KEY}={loads}", f"run.duration=[{duration!r}]"])
    base = meshwear.load(SCENE, {"run.duration": duration})
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        points = 0
        for i, load in enumerate(loads):
            result = meshwear.run(base.set(KEY, load), out=Path(tmp) / f"loop_{i}")
            points += result.model.n_steps * sum(len(b.tributary_area)
                                                 for b in result.model.bodies)
        loop = time.perf_counter() - start
        start = time.perf_counter()
        rows = run_sweep(sweep, Path(tmp) / "sweep", report=lambda line: None)
        cluster = time.perf_counter() - start
    assert all(r["status"] == "ok" for r in rows), rows
    alone = loop / runs
    together = sum(r["wall_time"] for r in rows) / runs
    workers = _workers()
    numbers = {"duration_s": duration, "loop_s": loop, "cluster_s": cluster,
               "ratio": loop / cluster, "ceiling": workers * alone / together,
               "overhead_s": cluster - runs * together / workers,
               "loop_vertex_steps_per_s": points / loop,
               "cluster_vertex_steps_per_s": points / cluster}
    return (f"| {runs} × {duration:g} s | {loop:.1f} s ({points / loop:.3g}) | "
            f"{cluster:.1f} s ({points / cluster:.3g}) | **{loop / cluster:.2f}×** | "
            f"{alone:.2f} s / {together:.2f} s | {numbers['ceiling']:.2f}× | "
            f"{numbers['overhead_s']:.1f} s |"), numbers


def _workers():
    import os

    return os.cpu_count()


if __name__ == "__main__":
    sys.exit(main())
