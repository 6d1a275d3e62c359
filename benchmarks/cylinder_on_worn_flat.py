"""Two-body fretting, a cylinder on a worn flat: both scars and their volumes.

Runs examples/cylinder_on_worn_flat.toml as a user would (building the model,
the run, writing its outputs), compares each part's worn volume with its
``k P s`` (gross slip: ``s = 4 A`` per cycle) and plots both scars across the
stroke: the flat's wear depth along x, and the cylinder's along its
circumference (the arc from its lowest line). Writes
docs/img/cylinder_on_worn_flat.png and the measured section of
docs/examples/cylinder_on_worn_flat.md, prints the figures and, last, one
JSON line.

    .venv/bin/python benchmarks/cylinder_on_worn_flat.py      # about 10 s here
"""

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from common import timed_run, write_measured  # noqa: E402
from meshwear.kernels.contact import rotation_entries  # noqa: E402
from meshwear.scene.reader import load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "cylinder_on_worn_flat.toml"
FIGURE = ROOT / "docs" / "img" / "cylinder_on_worn_flat.png"


def main():
    scene = load_scene(SCENE)
    model, state, result, wall = timed_run(scene)
    body, surface = scene.bodies[0], scene.surfaces[0]
    load = -body.force[2]
    amplitude = body.path.oscillation.amplitude
    cycles = state.time * body.path.oscillation.frequency
    s = 4.0 * amplitude * cycles
    k_cyl, k_flat = scene.wear.coefficient, surface.coefficient
    cyl, part = state.bodies[0], state.parts[0]
    row = {
        "wall": wall, "steps": state.step, "cycles": cycles,
        "cylinder_vertices": len(cyl.wear_depth), "flat_vertices": len(part.depth),
        "cylinder_volume_error": float(cyl.wear_volume.sum() / (k_cyl * load * s) - 1.0),
        "flat_volume_error": float(part.volume.sum() / (k_flat * load * s) - 1.0),
        "cylinder_depth": float(cyl.wear_depth.max()), "flat_depth": float(part.depth.max()),
        "force_sum": float(np.linalg.norm(np.add(result["surfaces"]["flat"]["contact_force"],
                                                 result["bodies"]["cylinder"]["contact_force"]))),
    }
    print(f"  {SCENE.name}: {wall:.1f} s, {state.step} steps, {cycles:.0f} cycles")
    print(f"  cylinder volume vs k P s {row['cylinder_volume_error']:+.1e}, "
          f"flat volume vs k P s {row['flat_volume_error']:+.1e}")
    print(f"  deepest wear: cylinder {1e9 * row['cylinder_depth']:.1f} nm, "
          f"flat {1e9 * row['flat_depth']:.1f} nm")
    plot(model, state, amplitude)
    write_page(row)
    print(json.dumps({"benchmark": "cylinder_on_worn_flat", **row}))


def plot(model, state, amplitude):
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    flat = model.surfaces.per_vertex[0].reference_vertices
    part = state.parts[0]
    # the flat's top face under the cylinder's length, away from its ends
    top = (flat[:, 2] > flat[:, 2].max() - 1e-9) & (np.abs(flat[:, 1]) < 0.0015)
    ax.plot(1e3 * flat[top, 0], 1e9 * part.depth[top], ".", ms=2, color="C0",
            label="flat, along the stroke (x), |y| < 1.5 mm")
    cyl, body = state.bodies[0], model.bodies[0]
    R = np.array(rotation_entries(body.initial_pose[3:7])).reshape(3, 3)
    x = body.reference_vertices @ R.T           # the unworn cylinder, as placed
    worn = cyl.wear_depth > 0.0
    arc = 0.006 * np.arctan2(x[worn, 0], -x[worn, 2])
    ax.plot(1e3 * arc, 1e9 * cyl.wear_depth[worn], ".", ms=2, color="C1",
            label="cylinder, along its circumference (arc from its lowest line)")
    for edge in (-amplitude, amplitude):
        ax.axvline(1e3 * edge, color="0.6", lw=0.8, ls="--")
    ax.set_xlabel("position (mm); dashed: the stroke, ±0.5 mm")
    ax.set_ylabel("wear depth (nm)")
    ax.set_title("Cylinder on a worn flat: both scars after ten cycles")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


def write_page(r):
    write_measured("cylinder_on_worn_flat", [
        ("wall time (build, run, outputs)", f"{r['wall']:.1f} s ({r['steps']} steps, "
         f"{r['cylinder_vertices']:,} cylinder and {r['flat_vertices']:,} flat vertices)"),
        ("cylinder's worn volume vs $k_{cyl} P s$", f"{r['cylinder_volume_error']:+.1e}"),
        ("flat's worn volume vs $k_{flat} P s$", f"{r['flat_volume_error']:+.1e}"),
        ("deepest wear, cylinder / flat",
         f"{1e9 * r['cylinder_depth']:.1f} nm / {1e9 * r['flat_depth']:.1f} nm"),
        ("contact forces on the two parts, summed", f"{r['force_sum']:.1e} N"),
    ], FIGURE.name, "both scars")


if __name__ == "__main__":
    main()
