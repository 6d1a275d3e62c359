"""Block on ring: the time to an answer and the accuracy of the scar.

Runs examples/block_on_ring.toml (an analytic ring) and
examples/block_on_ring_mesh.toml (a meshed ring) as a user would, timing the
whole run (building the model, the run, writing its outputs), then a
converged run of the analytic ring (tolerance 1e-4, half the time step). On
the block's worn face it compares

* the scar with the ring's arc, ``h - (R - sqrt(R^2 - x^2))``, ``h`` its depth;
* the worn volume with ``k P s``, and ``h`` with the depth of the circular
  segment of that volume;
* each run with the converged one, and the mesh ring with the analytic one,

all as the largest difference over the face's vertices relative to the
scar's depth. Writes docs/img/block_on_ring_profile.png and the measured
section of docs/examples/block_on_ring.md, prints a table and, last, one JSON
line.

    .venv/bin/python benchmarks/block_on_ring.py [--quick]   # about 5 minutes here
"""

import argparse
import dataclasses
import json
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.optimize import brentq  # noqa: E402

from common import replace_section, timed_run  # noqa: E402
from meshwear.scene.reader import load_scene  # noqa: E402
from meshwear.longrun.jump_errors import error_estimate  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ANALYTIC = ROOT / "examples" / "block_on_ring.toml"
MESH = ROOT / "examples" / "block_on_ring_mesh.toml"
PAGE = ROOT / "docs" / "examples" / "block_on_ring.md"
MARK_START, MARK_END = "<!-- block_on_ring:start -->", "<!-- block_on_ring:end -->"


def face(model, state):
    """x (m) and wear depth (m) of the vertices of the block's worn face."""
    body, s = model.bodies[0], state.bodies[0]
    z = body.reference_vertices[:, 2]
    on = z <= z.min() + 1e-9
    return body.reference_vertices[on, 0], s.wear_depth[on]


def segment_depth(volume, radius, width):
    """Depth h of the circular segment of a ring of ``radius`` whose area
    times ``width`` is ``volume``."""
    def area(h):
        return radius ** 2 * np.arccos(1.0 - h / radius) - (radius - h) * np.sqrt(
            2.0 * radius * h - h * h)
    return brentq(lambda h: area(h) * width - volume, 1e-12, radius)


def measure(label, scene, converged=None):
    model, state, _, wall = timed_run(scene)
    x, w = face(model, state)
    s = state.bodies[0]
    ring = next(c for c in scene.surfaces)
    radius = ring.radius if ring.type == "cylinder" else ring.shape.radius
    h = float(w.max())
    arc = np.maximum(h - (radius - np.sqrt(np.maximum(radius ** 2 - x ** 2, 0.0))), 0.0)
    load = -scene.bodies[0].force[2]
    distance = 0.5 * scene.run.duration          # 0.5 m/s at the rim
    volume = float(s.wear_volume.sum())
    closed_volume = scene.wear.coefficient * load * distance
    width = scene.bodies[0].shape.size[1]
    row = dict(case=label, wall=wall, vertices=len(s.wear_depth), face=len(x),
               active=len(s.active),
               resolved=state.jump.resolved_steps / model.cycle_steps,
               cycles=model.n_steps / model.cycle_steps, jumps=state.jump.jumps,
               error_estimate=error_estimate(state),
               depth=h, depth_closed=segment_depth(closed_volume, radius, width),
               volume=volume, volume_closed=closed_volume,
               volume_error=volume / closed_volume - 1.0,
               arc_error=float(np.abs(w - arc).max() / h))
    row["depth_error"] = h / row["depth_closed"] - 1.0
    if converged is not None:
        row["converged_error"] = float(np.abs(w - converged[1]).max() / converged[1].max())
    print(f"  {label:34} {wall:7.1f} s  resolved {row['resolved']:6.0f} of {row['cycles']:.0f}  "
          f"depth {1e6 * h:7.3f} µm  volume {row['volume_error']:+.1e}  arc {row['arc_error']:.1e}"
          + (f"  vs converged {row['converged_error']:.1e}" if converged is not None else ""),
          flush=True)
    return row, (x, w)


def plot(profiles, radius):
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    (x, w), (xm, wm), (xc, wc) = profiles["analytic"], profiles["mesh"], profiles["converged"]
    h = w.max()
    grid = np.linspace(x.min(), x.max(), 600)
    arc = np.maximum(h - (radius - np.sqrt(radius ** 2 - grid ** 2)), 0.0)
    ax.plot(1e3 * xc, 1e6 * wc, "o", ms=5, mfc="none", color="0.6",
            label="converged (tol 1e-4, Δt/2)")
    ax.plot(1e3 * x, 1e6 * w, ".", ms=3, label="analytic ring (tol 1e-2)")
    ax.plot(1e3 * xm, 1e6 * wm, "x", ms=3, label="mesh ring (tol 1e-2)")
    ax.plot(1e3 * grid, 1e6 * arc, "k-", lw=1, label=r"ring's arc $h - (R - \sqrt{R^2 - x^2})$")
    ax.set_xlim(-1.25e3 * np.sqrt(2 * radius * h), 1.25e3 * np.sqrt(2 * radius * h))
    ax.set_xlabel("x across the scar (mm)")
    ax.set_ylabel("wear depth (µm)")
    ax.set_title("Block on ring after 3000 m: the scar on the block")
    ax.legend(fontsize=7)
    fig.tight_layout()
    path = ROOT / "docs" / "img" / "block_on_ring_profile.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def write_page(rows):
    lines = [MARK_START, "", "<!-- written by benchmarks/block_on_ring.py -->", "",
             "| run | wall time | vertices (face) | resolved cycles | scar depth | closed form "
             "| worn volume vs $kPs$ | scar vs arc | vs converged |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        conv = f"{r['converged_error']:.1e}" if "converged_error" in r else "—"
        lines.append(
            f"| {r['case']} | {r['wall']:.1f} s | {r['vertices']:,} ({r['face']:,}) | "
            f"{r['resolved']:.0f} of {r['cycles']:.0f} | {1e6 * r['depth']:.3f} µm | "
            f"{1e6 * r['depth_closed']:.3f} µm | {r['volume_error']:+.1e} | "
            f"{r['arc_error']:.1e} | {conv} |")
    m = rows[1]
    lines += ["", f"Mesh ring against analytic ring: the scars differ by at most "
              f"{m['mesh_vs_analytic']:.1e} of the depth.", "",
              "![the scar on the block](../img/block_on_ring_profile.png)", "", MARK_END]
    replace_section(PAGE, MARK_START, MARK_END, "\n".join(lines))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="no converged run (compare with the arc and k P s only)")
    args = parser.parse_args()
    started = time.perf_counter()
    analytic_scene, mesh_scene = load_scene(ANALYTIC), load_scene(MESH)
    rows, profiles = [], {}
    converged = None
    print("  run                                   wall")
    if not args.quick:
        fine = dataclasses.replace(
            analytic_scene, run=dataclasses.replace(analytic_scene.run,
                                                    dt=0.5 * analytic_scene.run.dt),
            wear=dataclasses.replace(analytic_scene.wear, tolerance=1e-4))
        row, converged = measure("converged (analytic, tol 1e-4, Δt/2)", fine)
        profiles["converged"] = converged
        converged_row = row
    for label, scene in (("analytic ring", analytic_scene), ("mesh ring", mesh_scene)):
        row, profile = measure(label, scene, converged)
        rows.append(row)
        profiles["analytic" if label.startswith("analytic") else "mesh"] = profile
    # the same block mesh in both runs: compare vertex by vertex
    (_, w), (_, wm) = profiles["analytic"], profiles["mesh"]
    rows[1]["mesh_vs_analytic"] = float(np.abs(wm - w).max() / w.max())
    print(f"  mesh ring vs analytic ring: {rows[1]['mesh_vs_analytic']:.1e} of the depth")
    if not args.quick:
        rows.append(converged_row)
        plot(profiles, analytic_scene.surfaces[0].radius)
        write_page(rows)
    print(json.dumps({"benchmark": "block_on_ring", "seconds": time.perf_counter() - started,
                      "rows": rows}))


if __name__ == "__main__":
    main()
