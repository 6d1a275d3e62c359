"""First runs on an empty kernel cache: every example, as a new user meets it.

Each example runs twice through ``meshwear run`` in a fresh process: first
on an empty ``NUMBA_CACHE_DIR`` (what a fresh install, an upgrade or a
changed kernel gives), then again on the cache the first run left. The runs
are shortened to a few hundred steps (or three cycles of a scene with cycle
jumps, so that its jumps compile too): what differs between the two is the
compile. The table gives both wall times, their difference, and whether the
first run printed the compile line (docs/performance.md, "The first run
compiles").

    .venv/bin/python benchmarks/first_run.py [--only NAME ...] [--write]

``--write`` puts the table in docs/performance.md.
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
sys.path.insert(0, str(ROOT / "benchmarks"))

from common import replace_section  # noqa: E402

#: the examples, as paths under the repository
EXAMPLES = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "examples").rglob("*.toml"))
#: the steps of a shortened run (and the cycles of one with cycle jumps)
STEPS, CYCLES = 200, 3
#: the first run's budget here (s): issue 42
BUDGET = 30.0


def overrides(path):
    """``--set`` pairs that shorten the scene at ``path`` to :data:`STEPS`
    steps (or :data:`CYCLES` cycles), with two frames and a few rows."""
    import meshwear
    from meshwear.model.build import build_model

    scene = meshwear.load(ROOT / path)
    model = build_model(scene)
    steps = max(STEPS, CYCLES * model.cycle_steps) if model.cycle_steps else STEPS
    duration = float(min(model.n_steps, steps) * model.dt)
    return [f"run.duration={duration!r}", "run.frames=2", "run.history=5"]


def first_and_second(path, sets, work):
    """Wall times (s) of the first and second run and the first's stderr."""
    cache = Path(tempfile.mkdtemp(dir=work, prefix="cache-"))
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    args = [sys.executable, "-m", "meshwear.cli", "run", str(ROOT / path), "-o",
            str(work / "out"), *[a for s in sets for a in ("--set", s)]]
    times, first_err = [], ""
    for _ in range(2):
        start = time.perf_counter()
        done = subprocess.run(args, env=env, cwd=str(ROOT), capture_output=True, text=True)
        times.append(time.perf_counter() - start)
        if done.returncode != 0:
            raise RuntimeError(f"{path}: exit {done.returncode}: {done.stderr.strip()[-300:]}")
        first_err = first_err or done.stderr
    return times[0], times[1], first_err


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", help="examples whose path contains one of these")
    parser.add_argument("--write", action="store_true", help="write docs/performance.md")
    args = parser.parse_args(argv)
    from meshwear.kernels.notice import STARTING

    chosen = [p for p in EXAMPLES if not args.only or any(o in p for o in args.only)]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for path in chosen:
            sets = overrides(path)
            try:
                first, second, err = first_and_second(path, sets, Path(tmp))
            except RuntimeError as failed:
                print(failed, flush=True)
                continue
            said = STARTING in err
            rows.append((path, first, second, said))
            print(f"{path:<52} first {first:6.1f} s  second {second:5.1f} s  "
                  f"compile {first - second:5.1f} s  line {'yes' if said else 'NO'}"
                  + ("" if first <= BUDGET else f"  over {BUDGET:g} s"), flush=True)
    over = [r for r in rows if r[1] > BUDGET]
    print(f"{len(rows)} example(s); slowest first run {max(r[1] for r in rows):.1f} s; "
          f"{len(over)} over {BUDGET:g} s; compile line printed by "
          f"{sum(r[3] for r in rows)} of {len(rows)}")
    if args.write:
        table = ["<!-- first_run:start -->", "",
                 "<!-- written by benchmarks/first_run.py -->", "",
                 f"| example ({STEPS} steps or {CYCLES} cycles) | first run (s) | "
                 "second run (s) | compiling (s) | line printed |",
                 "|---|---:|---:|---:|---|"]
        table += [f"| `{p}` | {a:.1f} | {b:.1f} | {a - b:.1f} | {'yes' if s else 'no'} |"
                  for p, a, b, s in rows]
        table += ["", "<!-- first_run:end -->"]
        replace_section(ROOT / "docs" / "performance.md", "<!-- first_run:start -->",
                        "<!-- first_run:end -->", "\n".join(table))
    print(json.dumps({"rows": [dict(example=p, first=a, second=b, line=s)
                               for p, a, b, s in rows]}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
