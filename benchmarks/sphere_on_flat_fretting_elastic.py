"""examples/sphere_on_flat_fretting_elastic.toml: its run time and its fretting scar against Mindlin.

Runs the example (10^4 fretting cycles with cycle jumps; under a minute
here), or reads a finished run of it with ``--from OUT``, and reads the last
frame's wear depth on the ball. Against Cattaneo and Mindlin (docs/model.md,
"Elastic half-space"): the Hertz radius ``a``, the stick radius
``c = a (1 - Q*/mu P)^(1/3)`` of the stroke, the unworn disc (the vertices
whose wear stays under 1 % of the deepest) and the worn annulus (where the
wear exceeds a tenth of the deepest). Prints the table,
writes docs/img/sphere_on_flat_fretting_elastic.png (wear depth against the
radius, Mindlin's radii marked) and the measured section of
docs/examples/sphere_on_flat_fretting_elastic.md, then one JSON line.

    .venv/bin/python benchmarks/sphere_on_flat_fretting_elastic.py [--from OUT]
"""

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import write_measured  # noqa: E402

from meshwear import cli  # noqa: E402
from meshwear.contact.halfspace import contact_modulus  # noqa: E402
from meshwear.output.export import read_frame, series_frames  # noqa: E402
from meshwear.scene.reader import load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "sphere_on_flat_fretting_elastic.toml"


def mindlin(scene):
    """Hertz's a, the stroke's Q*/mu P and Mindlin's stick radius c (m)."""
    c = scene.contact
    body = scene.bodies[0]
    R = body.shape.radius
    mass = body.density * 4.0 / 3.0 * np.pi * R ** 3
    P = -body.force[2] - mass * scene.run.gravity[2]
    e_star = contact_modulus(c.youngs_modulus, c.poissons_ratio)
    a = (3.0 * P * R / (4.0 * e_star)) ** (1.0 / 3.0)
    compliance = sum(2.0 * (1.0 + n) * (2.0 - n) / e
                     for e, n in zip(c.youngs_modulus, c.poissons_ratio))
    gross = 3.0 * c.friction * P * compliance / (16.0 * a)
    share = 1.0 - (1.0 - body.path.oscillation.amplitude / gross) ** 1.5
    return a, share, a * (1.0 - share) ** (1.0 / 3.0), gross


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--from", dest="source", type=Path, default=None, metavar="OUT",
                        help="read a finished run of the example from its output folder")
    args = parser.parse_args(argv)
    scene = load_scene(SCENE)
    a, share, c, gross = mindlin(scene)
    with tempfile.TemporaryDirectory() as folder:
        out = args.source or Path(folder) / "fretting"
        if args.source is None:
            if cli.main(["run", str(SCENE), "-o", str(out), "-q"]) != 0:
                raise SystemExit("the example's run failed")
        summary = json.loads((out / "summary.json").read_text())
        frames = series_frames(out, "ball")
        last = read_frame(frames[-1][1])
    points = np.asarray(last.points, float)
    depth = np.asarray(last.point_data["wear_depth"], float)
    centre = points[np.argmin(points[:, 2])]
    r = np.hypot(points[:, 0] - centre[0], points[:, 1] - centre[1])
    near = r < 1.5 * a
    worn = near & (depth > 0.1 * depth.max())
    unworn_edge = near & (depth > 0.01 * depth.max())
    rows = [
        ("cycles, wall time", f"{summary['cycles']:.0f}, {summary['wall_time']:.1f} s"),
        ("resolved cycles, jumps, error estimate",
         f"{summary['resolved_cycles']:.0f}, {summary['jumps']}, "
         f"{summary['error_estimate']:.4f}"),
        ("Hertz radius a", f"{a * 1e6:.1f} µm"),
        ("stroke / gross-slip stroke, Q*/mu P", f"{scene.bodies[0].path.oscillation.amplitude / gross:.3f}, {share:.3f}"),
        ("Mindlin stick radius c", f"{c * 1e6:.1f} µm"),
        ("unworn disc (wear under 1 % of the deepest): radius",
         f"{r[unworn_edge].min() * 1e6:.1f} µm ({r[unworn_edge].min() / c - 1.0:+.1%} of c)"),
        ("worn annulus (wear over 10 % of the deepest): inner, outer radius",
         f"{r[worn].min() * 1e6:.1f}, {r[worn].max() * 1e6:.1f} µm"),
        ("deepest wear within 0.9 c, anywhere",
         f"{depth[near & (r < 0.9 * c)].max():.3g} m, {depth.max():.3g} m"),
        ("worn volume", f"{summary['bodies']['ball']['wear_volume']:.4g} m³"),
    ]
    for quantity, value in rows:
        print(f"{quantity:66s} {value}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    ax.plot(r[near] * 1e6, depth[near] * 1e9, ".", ms=2, label="vertices, after 10⁴ cycles")
    ax.axvline(c * 1e6, color="C3", lw=1, label=f"Mindlin stick radius c = {c * 1e6:.1f} µm")
    ax.axvline(a * 1e6, color="k", lw=1, ls="--", label=f"Hertz radius a = {a * 1e6:.1f} µm")
    ax.set_xlabel("distance from the contact's centre (µm)")
    ax.set_ylabel("wear depth (nm)")
    ax.set_title("Ball on flat, fretting in partial slip, half-space contact")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(ROOT / "docs" / "img" / "sphere_on_flat_fretting_elastic.png", dpi=100)
    write_measured("sphere_on_flat_fretting_elastic", rows,
                   "sphere_on_flat_fretting_elastic.png",
                   "wear depth against the radius, Mindlin's radii marked")
    print(json.dumps({"benchmark": "sphere_on_flat_fretting_elastic", "rows": rows,
                      "wall_time_s": summary["wall_time"]}))


if __name__ == "__main__":
    main()
