"""A shaft turning in a worn bushing: both scars and their volumes.

Runs examples/shaft_in_worn_bushing.toml as a user would (building the model,
the run, writing its outputs), compares each part's worn volume with its
``k P s`` (``s = omega R t``, the shaft's surface sliding over the bore) and
plots both scars against the angle round the axis: the bushing's wear on its
loaded side, the shaft's all round. Writes docs/img/shaft_in_worn_bushing.png
and the measured section of docs/examples/shaft_in_worn_bushing.md, prints
the figures and, last, one JSON line.

    .venv/bin/python benchmarks/shaft_in_worn_bushing.py      # about 25 s here
"""

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from common import timed_run, write_measured  # noqa: E402
from meshwear.scene.reader import load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "shaft_in_worn_bushing.toml"
FIGURE = ROOT / "docs" / "img" / "shaft_in_worn_bushing.png"


def main():
    scene = load_scene(SCENE)
    model, state, result, wall = timed_run(scene)
    body, surface = scene.bodies[0], scene.surfaces[0]
    load = float(np.linalg.norm(body.force))
    rate, radius = body.path.rotation.rate, body.shape.radius
    s = rate * radius * state.time
    k_shaft, k_bushing = scene.wear.coefficient, surface.coefficient
    shaft, part = state.bodies[0], state.parts[0]
    bore = model.surfaces.per_vertex[0].reference_vertices
    worn = part.depth > 0.0
    angle = np.degrees(np.arctan2(bore[worn, 1], bore[worn, 0]))
    row = {
        "wall": wall, "steps": state.step, "turns": rate * state.time / (2.0 * np.pi),
        "shaft_vertices": len(shaft.wear_depth), "bushing_vertices": len(part.depth),
        "shaft_volume_error": float(shaft.wear_volume.sum() / (k_shaft * load * s) - 1.0),
        "bushing_volume_error": float(part.volume.sum() / (k_bushing * load * s) - 1.0),
        "shaft_depth": float(shaft.wear_depth.max()), "bushing_depth": float(part.depth.max()),
        # the bushing's worn arc: every worn bore vertex within this angle of -x
        "bushing_arc": float(np.abs(180.0 - np.abs(angle)).max()),
        "force_sum": float(np.linalg.norm(np.add(result["surfaces"]["bushing"]["contact_force"],
                                                 result["bodies"]["shaft"]["contact_force"]))),
    }
    print(f"  {SCENE.name}: {wall:.1f} s, {state.step} steps, {row['turns']:.2f} turns")
    print(f"  shaft volume vs k P s {row['shaft_volume_error']:+.1e}, "
          f"bushing volume vs k P s {row['bushing_volume_error']:+.1e}")
    print(f"  deepest wear: shaft {1e9 * row['shaft_depth']:.1f} nm, "
          f"bushing {1e9 * row['bushing_depth']:.1f} nm; bushing worn within "
          f"{row['bushing_arc']:.1f}° of the load")
    plot(model, state)
    write_page(row)
    print(json.dumps({"benchmark": "shaft_in_worn_bushing", **row}))


def plot(model, state):
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    bore = model.surfaces.per_vertex[0].reference_vertices
    part = state.parts[0]
    inner = np.hypot(bore[:, 0], bore[:, 1]) < 0.0051
    angle = np.degrees(np.arctan2(bore[inner, 1], -bore[inner, 0]))
    ax.plot(angle, 1e9 * part.depth[inner], ".", ms=2, color="C0",
            label="bushing's bore (angle from the load's direction)")
    shaft, body = state.bodies[0], model.bodies[0]
    x = body.reference_vertices
    side = np.hypot(x[:, 0], x[:, 1]) > 0.00499
    right = ax.twinx()
    right.plot(np.degrees(np.arctan2(x[side, 1], x[side, 0])), 1e9 * shaft.wear_depth[side], ".",
               ms=2, color="C1", label="shaft (angle in its own frame), right axis")
    right.set_ylim(0.0, 1.3e9 * shaft.wear_depth.max())
    right.set_ylabel("shaft's wear depth (nm)", color="C1")
    ax.set_xlabel("angle round the axis (°)")
    ax.set_ylabel("bushing's wear depth (nm)", color="C0")
    ax.set_title("Shaft in a worn bushing: both scars after one turn")
    lines = ax.get_legend_handles_labels(), right.get_legend_handles_labels()
    ax.legend(lines[0][0] + lines[1][0], lines[0][1] + lines[1][1], fontsize=7,
              loc="upper left")
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


def write_page(r):
    write_measured("shaft_in_worn_bushing", [
        ("wall time (build, run, outputs)", f"{r['wall']:.1f} s ({r['steps']} steps, "
         f"{r['shaft_vertices']:,} shaft and {r['bushing_vertices']:,} bushing vertices)"),
        ("shaft's worn volume vs $k_{shaft} P s$", f"{r['shaft_volume_error']:+.1e}"),
        ("bushing's worn volume vs $k_{bushing} P s$", f"{r['bushing_volume_error']:+.1e}"),
        ("deepest wear, shaft / bushing",
         f"{1e9 * r['shaft_depth']:.1f} nm / {1e9 * r['bushing_depth']:.1f} nm"),
        ("bushing worn within", f"{r['bushing_arc']:.1f}° of the load's direction"),
        ("contact forces on the two parts, summed", f"{r['force_sum']:.1e} N"),
    ], FIGURE.name, "both scars")


if __name__ == "__main__":
    main()
