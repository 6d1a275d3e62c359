"""Stress of the compiled kernels' cache: concurrent first runs of several
kinds of scene on one empty cache, with different thread counts, then a
threaded run of the 40 962-vertex fretting ball on what they left
(docs/performance.md, "Kernel cache").

Each round starts an empty ``NUMBA_CACHE_DIR``, starts every run of
:data:`RUNS` at once (``NUMBA_NUM_THREADS`` 1 or 2 by turns, so runs compile
different builds and signatures of the same kernels together, as a sweep's
workers or a cluster sharing a home folder do), waits for them, then runs
the ball with cycle jumps on 2 threads. A crash (a negative exit code:
SIGSEGV is -11) or any exit but 0 counts as a failure. ``--repo`` runs the
meshwear of another checkout (an older commit, to compare).

    .venv/bin/python benchmarks/cache_stress.py [--rounds 3] [--repo PATH]
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: (name, scene, overrides): short runs of each kind of scene
RUNS = [
    ("ball, jumps", "examples/long/sphere_fretting_1e5.toml",
     ["run.duration=20.0", "run.frames=2", "run.history=5"]),
    ("ball, plane", "examples/sphere_on_flat_fretting.toml",
     ["run.duration=0.05", "run.frames=2", "run.history=5"]),
    ("pin on worn disc", "examples/pin_on_worn_disc.toml",
     ["run.duration=0.05", "run.frames=2", "run.history=5"]),
    ("tossed cube", "examples/cube_toss.toml", ["run.duration=0.05", "run.frames=2"]),
    ("mechanism", "examples/mechanisms/pin_on_disc.toml",
     ["run.duration=0.02", "run.frames=2", "run.history=5"]),
]

#: the run on what the round left: the 40 962-vertex ball, cycle jumps, 2 threads
BALL = ("40 962-vertex ball, jumps, 2 threads", "examples/sphere_on_flat_fretting.toml",
        ["run.duration=0.5", "run.frames=2", "run.history=5",
         "wear.acceleration=cycle_jump"])


def command(repo, scene, overrides, out):
    code = "import sys; from meshwear.cli import main; sys.exit(main())"
    args = [sys.executable, "-c", code, "run", str(ROOT / scene), "-o", str(out), "--quiet"]
    for o in overrides:
        args += ["--set", o]
    return args


def start(repo, cache, threads, name, scene, overrides, out):
    env = dict(os.environ, PYTHONPATH=str(repo), NUMBA_CACHE_DIR=str(cache),
               NUMBA_NUM_THREADS=str(threads))
    # (cwd: `python -c` puts it first on sys.path, before PYTHONPATH)
    return subprocess.Popen(command(repo, scene, overrides, out), env=env, cwd=str(repo),
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def round_(repo, work, index):
    cache = work / f"cache-{index}"
    cache.mkdir()
    before = time.perf_counter()
    procs = [(name, threads, start(repo, cache, threads, name, scene, overrides,
                                   work / f"out-{index}-{k}"))
             for k, ((name, scene, overrides), threads)
             in enumerate(zip(RUNS, [1, 2] * len(RUNS)))]
    results = []
    for name, threads, p in procs:
        _, err = p.communicate()
        results.append((name, threads, p.returncode, err.strip().splitlines()[-1:]))
    concurrent = time.perf_counter() - before
    name, scene, overrides = BALL
    before = time.perf_counter()
    p = start(repo, cache, 2, name, scene, overrides, work / f"out-{index}-ball")
    _, err = p.communicate()
    results.append((name, 2, p.returncode, err.strip().splitlines()[-1:]))
    return results, concurrent, time.perf_counter() - before


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--repo", type=Path, default=ROOT,
                        help="the checkout whose meshwear runs (default: this one)")
    args = parser.parse_args(argv)
    failures, rows = 0, []
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            results, concurrent, ball = round_(args.repo.resolve(), Path(tmp), r)
            print(f"round {r + 1}: {len(RUNS)} first runs at once in {concurrent:.0f} s, "
                  f"then the ball in {ball:.0f} s")
            for name, threads, code, last in results:
                bad = code != 0
                failures += bad
                print(f"  {name:<40} {threads} thread(s)  exit {code:>4}"
                      + (f"  {last[0] if last else ''}" if bad else ""))
                rows.append([r + 1, name, threads, code])
    print(f"{failures} failed run(s) of {len(rows)}")
    print(json.dumps({"repo": str(args.repo), "rounds": args.rounds, "failures": failures,
                      "runs": rows}))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
