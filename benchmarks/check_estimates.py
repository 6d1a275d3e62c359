"""``meshwear check``'s run-time estimate against the run, on every example
scene: the estimate printed by ``check`` and the ``wall_time`` of the run's
``summary.json`` (both from the model built to the outputs closed).

    .venv/bin/python benchmarks/check_estimates.py [--skip gear_pair] [SCENE ...]

Prints one row per scene: estimate, run, and the estimate's error.
"""

import argparse
import json
import re
import subprocess
import sys
import tempfile
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
    print(f"{'scene':<36}{'estimate (s)':>14}{'run (s)':>10}{'error':>9}", flush=True)
    worst = 0.0
    for scene in scenes:
        text = meshwear("check", scene)
        estimate = float(re.search(r"estimated run time .*?([0-9.e+-]+) s: stepping", text)[1])
        with tempfile.TemporaryDirectory() as out:
            meshwear("run", scene, "-o", out, "-q")
            wall = json.loads((Path(out) / "summary.json").read_text())["wall_time"]
        error = estimate / wall - 1.0
        worst = max(worst, abs(error))
        print(f"{scene.relative_to(ROOT).as_posix():<36}{estimate:>14.3g}{wall:>10.3g}"
              f"{error:>+9.0%}", flush=True)
    print(f"largest error {worst:.0%}")


if __name__ == "__main__":
    main()
