"""Two worn parts meshed at different resolutions: the fretting cylinder on a
worn flat (examples/cylinder_on_flat_fretting.toml) with the pad and the
flat at (20, 10), (10, 20), (10, 10) and (20, 20) µm, each scar against the
2-D Winkler reference (benchmarks/winkler_2d.py) at every frame, and the
flat's wear along the pad's axis in the middle of its scar (grooves a pad
vertex apart would show there; docs/model.md, "Worn counter-surfaces").

    .venv/bin/python benchmarks/mesh_ratio.py [--pairs 20,10 10,10] [--cycles N]

Writes docs/img/mesh_ratio.png (the flat's wear across the pad's axis at the
middle of the scar, each pair of resolutions) and, as its last line, one
JSON object with the figures.
"""

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import winkler_2d  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "cylinder_on_flat_fretting.toml"
PAIRS = [(20, 10), (10, 20), (10, 10), (20, 20)]
#: the middle of the scar: the flat's vertices nearest x = 0, away from the
#: pad's ends (|y| under this, m)
MIDDLE_Y = 4e-4


def run(pad_um, flat_um, out, cycles=None):
    """The example with the pad at ``pad_um`` and the flat at ``flat_um``;
    its wall time (s)."""
    code = "import sys; from meshwear.cli import main; sys.exit(main())"
    args = [sys.executable, "-c", code, "run", str(SCENE), "-o", str(out), "--quiet",
            "--set", f"body[0].resolution={pad_um * 1e-6!r}",
            "--set", f"surface[0].resolution={flat_um * 1e-6!r}"]
    if cycles is not None:
        args += ["--set", f"run.duration={float(cycles)!r}"]
    before = time.perf_counter()
    subprocess.run(args, check=True, cwd=str(ROOT))
    return time.perf_counter() - before


def across(out):
    """The flat's wear along the pad's axis in the middle of its scar at the
    last frame: its vertices nearest x = 0 with |y| < MIDDLE_Y, (y (k,),
    depth (k,)), and the scar's depth (the deepest of its profile across
    the middle band, as the 2-D comparison takes it)."""
    import pyvista

    frames = winkler_2d.frames(out, "flat")
    path = frames[max(frames)]
    mesh = pyvista.read(path)
    points, depth = np.asarray(mesh.points), np.asarray(mesh.point_data["wear_depth"])
    top = np.abs(points[:, 2]) < 1e-4
    x0 = points[top, 0][np.argmin(np.abs(points[top, 0]))]
    column = top & (np.abs(points[:, 0] - x0) < 1e-7) & (np.abs(points[:, 1]) < MIDDLE_Y)
    order = np.argsort(points[column, 1])
    scar = winkler_2d.scar(*winkler_2d.section(path))[0]
    return points[column, 1][order], depth[column][order], scar


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", nargs="*", default=None,
                        help="pad,flat resolutions in µm (default: the four)")
    parser.add_argument("--cycles", type=float, default=None)
    parser.add_argument("--keep", type=Path, default=None,
                        help="keep the runs' outputs in this folder")
    parser.add_argument("--figure", type=Path, default=ROOT / "docs" / "img" / "mesh_ratio.png")
    args = parser.parse_args(argv)
    pairs = PAIRS if not args.pairs else [tuple(int(v) for v in p.split(",")) for p in args.pairs]
    p = winkler_2d.parameters(SCENE)
    if args.cycles is not None:
        p["cycles"] = args.cycles
    results, curves = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        base = args.keep or Path(tmp)
        for pad, flat in pairs:
            out = base / f"pad{pad}_flat{flat}"
            wall = run(pad, flat, out, args.cycles)
            rows = winkler_2d.compare(p, out)
            worst_depth = max(abs(d3 / d2 - 1) for _, _, d3, _, d2, _ in rows)
            worst_width = max(abs(w3 / w2 - 1) for _, _, _, w3, _, w2 in rows)
            y, depth, deepest = across(out)
            variation = float(depth.max() - depth.min()) / deepest
            summary = json.loads((out / "summary.json").read_text())
            results.append({"pad_um": pad, "flat_um": flat, "wall_s": round(wall, 1),
                            "resolved_cycles": summary.get("resolved_cycles"),
                            "depth_error": worst_depth, "width_error": worst_width,
                            "across_variation": variation, "rows": rows})
            curves[(pad, flat)] = (y, depth / deepest)
            print(f"pad {pad:>2} µm, flat {flat:>2} µm: {wall:6.1f} s, "
                  f"{summary.get('resolved_cycles')} resolved cycles; largest error over "
                  f"{len(rows) // 2} frames: depth {worst_depth:.2%}, width {worst_width:.2%}; "
                  f"flat across the pad's axis at the scar's middle: {variation:.2%} of its depth")
    if curves:
        _draw(curves, args.figure)
    print(json.dumps({"pairs": results}))


def _draw(curves, figure):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.2))
    for (pad, flat), (y, r) in curves.items():
        order = np.argsort(y)
        ax.plot(y[order] * 1e6, r[order], ".-", ms=3, lw=0.8,
                label=f"pad {pad} µm, flat {flat} µm")
    ax.set_xlabel("y along the pad's axis (µm)")
    ax.set_ylabel("flat's wear at x = 0 (share of the scar's depth)")
    ax.set_title("the flat's wear along the pad's axis at the middle of its scar, last frame")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(figure, dpi=120)


if __name__ == "__main__":
    main()
