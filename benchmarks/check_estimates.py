"""``meshwear check``'s run-time estimate against the run, on every example
scene: the estimate printed by ``check`` and the ``wall_time`` of the run's
``summary.json`` (both from the model built to the outputs closed).

    .venv/bin/python benchmarks/check_estimates.py [--skip gear_pair] [SCENE ...]

Prints one row per scene: the seconds ``check`` took to answer, its
estimate, the range it gives a cycle-jumping run (low–high, and the
resolved cycles' range), the run, the estimate's error, and whether the run
landed inside the range (resolved cycles from ``summary.json``).
"""

import argparse
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def meshwear(*args):
    done = subprocess.run([sys.executable, "-m", "meshwear.cli", *map(str, args)],
                          capture_output=True, text=True, cwd=ROOT)
    if done.returncode != 0:
        raise RuntimeError(f"meshwear {' '.join(map(str, args))}: {done.stderr.strip()}")
    return done.stdout


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", type=Path)
    parser.add_argument("--skip", action="append", default=[],
                        help="scene stems left out (repeatable)")
    args = parser.parse_args(argv)
    scenes = [s.resolve() for s in args.scenes] or sorted((ROOT / "examples").rglob("*.toml"))
    scenes = [s for s in scenes if s.stem not in args.skip]
    print(f"{'scene':<36}{'answer (s)':>11}{'estimate (s)':>14}{'range (s)':>18}"
          f"{'cycles':>14}{'run (s)':>10}{'resolved':>10}{'error':>9}  inside", flush=True)
    worst = 0.0
    for scene in scenes:
        start = time.perf_counter()
        text = meshwear("check", scene)
        answer = time.perf_counter() - start
        estimate = float(re.search(r"estimated run time .*?([0-9.e+-]+) s: stepping", text)[1])
        found = re.search(r"range with cycle jumping (\S+)–(\S+) s \(\S+x\), (\S+)–(\S+) of",
                          text)
        with tempfile.TemporaryDirectory() as out:
            meshwear("run", scene, "-o", out, "-q")
            summary = json.loads((Path(out) / "summary.json").read_text())
        wall, resolved = summary["wall_time"], summary.get("resolved_cycles")
        error = estimate / wall - 1.0
        span, cycles, inside = "", "", ""
        if found:
            low, high, few, many = (float(found[i]) for i in range(1, 5))
            span, cycles = f"{low:.3g}–{high:.3g}", f"{few:.0f}–{many:.0f}"
            inside = (f"{'yes' if low <= wall <= high else 'no'} "
                      f"({'yes' if few <= resolved <= many else 'no'})")
        else:
            worst = max(worst, abs(error))
        print(f"{scene.relative_to(ROOT).as_posix():<36}{answer:>11.3g}{estimate:>14.3g}"
              f"{span:>18}{cycles:>14}{wall:>10.3g}"
              f"{'' if resolved is None else f'{resolved:.0f}':>10}{error:>+9.0%}  {inside}",
              flush=True)
    print(f"largest error without jumps {worst:.0%}")


if __name__ == "__main__":
    main()
