"""How far the steps' face lookups look: their cost against the old reach.

On a mesh counter-surface each step finds the face under every active
vertex (its own face, a walk to the next, or a search of the faces' tree
within the lookup's reach; with the uniform grid it replaced, whose cells
listed the faces within the reach, the reach set the cost). The steps look
:data:`meshwear.surfaces.active.QUERY_FRACTION` of the active set's margin
away (the refresh looks the whole margin); before, the steps looked the
whole margin too. This runs the
example scenes with mesh counter-surfaces both ways in the same process
(``QUERY_FRACTION`` = 1 is the old lookup), interleaved, the best of three,
and prints per step, vertex-steps/s and the ratio, and how far the two
runs' wear volumes differ after the same steps.

    .venv/bin/python benchmarks/query_reach.py [--seconds S]   # about 2 minutes

Prints one row per scene and, last, one JSON line.
"""

import argparse
import json
import time
from pathlib import Path

from meshwear.step import stepper
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.surfaces import active

ROOT = Path(__file__).resolve().parents[1]
SCENES = ("gear_pair", "block_on_ring_mesh", "pin_on_turning_disc", "pin_on_worn_disc",
          "shaft_in_worn_bushing", "cylinder_on_worn_flat")
OLD, NEW = 1.0, active.QUERY_FRACTION


def time_steps(name, fraction, steps):
    """(seconds per step, mean active vertices, worn volume) of ``steps``
    steps of example ``name`` with the steps looking ``fraction`` of the margin."""
    active.QUERY_FRACTION = fraction
    try:
        model = build_model(load_scene(ROOT / "examples" / f"{name}.toml"))
        state = initial_state(model)
        stepper.advance(model, state, 20)     # load the kernels, settle the active set
        counted, seen = 0, 0
        start = time.perf_counter()
        while state.step < 20 + steps:
            stepper.advance(model, state, min(state.step + 50, 20 + steps))
            counted += sum(len(s.active) for s in state.bodies)
            seen += 1
        elapsed = time.perf_counter() - start
    finally:
        active.QUERY_FRACTION = NEW
    volume = sum(float(s.wear_volume.sum()) for s in state.bodies)
    return elapsed / steps, counted / max(seen, 1), volume


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=3.0,
                        help="about how long each timing runs (s)")
    parser.add_argument("scenes", nargs="*", default=list(SCENES))
    args = parser.parse_args(argv)
    print(f"{'scene':<24}{'active':>8}{'old per step':>14}{'new per step':>14}"
          f"{'new vertex-steps/s':>20}{'speed-up':>10}{'volume diff':>13}", flush=True)
    rows = []
    for name in args.scenes:
        probe, _, _ = time_steps(name, NEW, 50)
        steps = max(50, min(20000, int(args.seconds / probe)))
        best = {OLD: None, NEW: None}
        for _ in range(3):
            for fraction in (OLD, NEW):
                result = time_steps(name, fraction, steps)
                if best[fraction] is None or result[0] < best[fraction][0]:
                    best[fraction] = result
        (old, _, v_old), (new, n_active, v_new) = best[OLD], best[NEW]
        diff = abs(v_new - v_old) / max(abs(v_old), 1e-300)
        row = {"scene": name, "steps": steps, "active": n_active, "old_per_step": old,
               "new_per_step": new, "vertex_steps_per_s": n_active / new,
               "speedup": old / new, "volume_difference": diff}
        rows.append(row)
        print(f"{name:<24}{n_active:>8.0f}{old * 1e6:>11.0f} µs{new * 1e6:>11.0f} µs"
              f"{row['vertex_steps_per_s']:>20.3g}{row['speedup']:>9.2f}×{diff:>13.1e}",
              flush=True)
    print(json.dumps({"query_fraction": NEW, "rows": rows}))


if __name__ == "__main__":
    main()
