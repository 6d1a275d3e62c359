"""The half-space pressure at the vertices against Hertz's (docs/model.md, "In a run").

Two balls pressed on a flat with ``[contact] model = "half-space"``, at rest:

- the validation ball, examples/validation/hertz_ball.toml (steel on steel,
  R 5 mm, 10 N, 10 µm triangles within 20 µm of the flat);
- issue 41's ball: steel (E 210 GPa, nu 0.3) on aluminium (E 70 GPa,
  nu 0.33), R 6.35 mm, 20 N, ``resolution = 8e-6``,
  ``resolution_reach = 1.2e-5``, built from the validation ball's scene. Its
  refined mesh is irregular: its vertices' areas vary twofold.

For each: the grid's contact radius and peak pressure (the ellipse fitted to
the cells' pressure) and the approach against Hertz's closed forms (a, p0,
a²/R from E* and R), and the written vertex field ``pressure`` (what a frame
holds, :func:`meshwear.output.fields.body_quantities`) against Hertz's
p0 sqrt(1 - r²/a²) at the vertices inside 0.8 a: the share within 10 %, the
5th, 50th and 95th percentiles of the ratio; beside it, what the field was
before it was read at the vertex's point (each vertex's share of the cells by
the transposed gap weights over its contact area), and the one factor
between a vertex's force over its area and the pressure at its point.
Prints the table, writes docs/img/hertz_vertex_pressure.png (pressure
against r, both balls), then one JSON line. A few seconds a ball here.

    .venv/bin/python benchmarks/hertz_vertex_pressure.py [--no-write]
"""

import argparse
import json
import platform
import sys
import time
import tomllib
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from cases import cell_radii, ellipse_radius  # noqa: E402

from meshwear.contact.halfspace import contact_modulus  # noqa: E402
from meshwear.model.build import build_model, initial_state  # noqa: E402
from meshwear.output.fields import body_quantities  # noqa: E402
from meshwear.scene.reader import parse_scene

VALIDATION = ROOT / "examples" / "validation" / "hertz_ball.toml"
FIGURE = ROOT / "docs" / "img" / "hertz_vertex_pressure.png"


def scenes():
    """(label, scene) of the two balls."""
    base = tomllib.loads(VALIDATION.read_text())
    out = [("steel on steel, R 5 mm, 10 N (validation)", parse_scene(base, str(VALIDATION),
                                                                      VALIDATION.parent))]
    data = tomllib.loads(VALIDATION.read_text())
    data["contact"].update(youngs_modulus=[210e9, 70e9], poissons_ratio=[0.3, 0.33])
    body = data["body"][0]
    body["shape"]["radius"] = 0.00635
    body.update(resolution=8e-6, resolution_reach=1.2e-5, position=[0.0, 0.0, 0.00635],
                force=[0.0, 0.0, -20.0])
    out.append(("steel on aluminium, R 6.35 mm, 20 N (issue 41)",
                parse_scene(data, "steel_on_aluminium", VALIDATION.parent)))
    return out


def measure(label, scene):
    """Hertz's closed forms against the grid and the vertices of ``scene``."""
    c = scene.contact
    e_star = contact_modulus(c.youngs_modulus, c.poissons_ratio)
    R, P = scene.bodies[0].shape.radius, -scene.bodies[0].force[2]
    a = (3.0 * P * R / (4.0 * e_star)) ** (1.0 / 3.0)
    p0, approach = 3.0 * P / (2.0 * np.pi * a * a), a * a / R
    start = time.perf_counter()
    model = build_model(scene)
    state = initial_state(model)
    seconds = time.perf_counter() - start
    s, b = state.bodies[0], model.bodies[0]
    patch = s.elastic
    radius, peak = ellipse_radius(cell_radii(patch), patch.pressure)
    field = body_quantities(b, s, model)["pressure"]
    # before: each vertex's share of the cells (the transposed gap weights)
    # over its contact area
    before = np.zeros_like(field)
    before[patch.index] = (patch.transposed @ (patch.pressure.ravel() * patch.grid.cell_area)
                           / patch.areas)
    r = np.hypot(s.vertices[:, 0], s.vertices[:, 1])
    below = s.vertices[:, 2] < 0.0
    inner = below & (r < 0.8 * a)
    hertz = p0 * np.sqrt(1.0 - (r[inner] / a) ** 2)
    on = patch.loaded
    factor = s.normal_force[0, patch.index[on]] / (patch.areas[on] * field[patch.index[on]])

    def stats(values):
        ratio = values[inner] / hertz
        return {"within_10_percent": float(np.mean(np.abs(ratio - 1.0) <= 0.1)),
                "p5": float(np.percentile(ratio, 5)), "p50": float(np.median(ratio)),
                "p95": float(np.percentile(ratio, 95))}

    shown = below & ((field > 0.0) | (before > 0.0))
    return {
        "label": label, "vertices": len(s.wear_depth), "inner_vertices": int(inner.sum()),
        "grid": list(patch.grid.shape), "cell": patch.grid.spacing[0], "seconds": seconds,
        "a": a, "p0": p0, "approach": approach,
        "radius_error": radius / a - 1.0, "peak_error": peak / p0 - 1.0,
        "approach_error": (patch.approach - patch.heights.min()) / approach - 1.0,
        "field": stats(field), "before": stats(before),
        "force_factor": [float(factor.min()), float(factor.max())],
        "load": float(s.normal_force.sum()), "P": P,
        "plot": {"r": r[shown], "field": field[shown], "before": before[shown]},
    }


def plot(results):
    fig, axes = plt.subplots(1, len(results), figsize=(5.2 * len(results), 3.8))
    for ax, m in zip(np.atleast_1d(axes), results):
        a, p0, d = m["a"], m["p0"], m["plot"]
        rr = np.linspace(0.0, a, 300)
        ax.plot(1e6 * d["r"], 1e-9 * d["before"], ".", ms=2, color="0.7",
                label="before: share of the cells / area")
        ax.plot(1e6 * d["r"], 1e-9 * d["field"], ".", ms=3,
                label="vertex field pressure (at its point)")
        ax.plot(1e6 * rr, 1e-9 * p0 * np.sqrt(1.0 - (rr / a) ** 2), "k-", lw=1, label="Hertz")
        ax.axvline(0.8e6 * a, color="k", ls=":", lw=0.8)
        f = m["field"]
        ax.set_title(f"{m['label']}\n{100 * f['within_10_percent']:.1f} % of "
                     f"{m['inner_vertices']} vertices inside 0.8 a within 10 %", fontsize=9)
        ax.set_xlim(0.0, 1.15e6 * a)
        ax.set_ylim(0.0, 1e-9 * p0 * min(2.6, 1.05 * max(1.0, d["before"].max() / p0)))
        ax.set_xlabel("distance from the axis (µm)")
        ax.set_ylabel("pressure (GPa)")
        ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=100)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="do not write the figure")
    args = parser.parse_args()
    results = [measure(label, scene) for label, scene in scenes()]
    print(f"{platform.node()}, {platform.processor() or platform.machine()}")
    for m in results:
        f, o = m["field"], m["before"]
        print(f"{m['label']}: {m['vertices']} vertices, grid {m['grid'][0]} x {m['grid'][1]} of "
              f"{1e6 * m['cell']:.2f} µm, built and solved in {m['seconds']:.1f} s")
        print(f"  Hertz a {1e6 * m['a']:.2f} µm, p0 {1e-6 * m['p0']:.1f} MPa, approach "
              f"{1e6 * m['approach']:.3f} µm; grid errors: radius {m['radius_error']:+.2e}, "
              f"peak {m['peak_error']:+.2e}, approach {m['approach_error']:+.2e}")
        for name, st in (("vertex field", f), ("before", o)):
            print(f"  {name:12}: {100 * st['within_10_percent']:5.1f} % of {m['inner_vertices']} "
                  f"inside 0.8 a within 10 %; ratio p5 {st['p5']:.3f} p50 {st['p50']:.3f} "
                  f"p95 {st['p95']:.3f}")
        print(f"  force / (area x pressure at the point): {m['force_factor'][0]:.6f} .. "
              f"{m['force_factor'][1]:.6f}; load carried {m['load']:.12g} N of {m['P']:g}")
    if not args.no_write:
        plot(results)
        print(f"wrote {FIGURE.relative_to(ROOT)}")
    print(json.dumps({"benchmark": "hertz_vertex_pressure",
                      "rows": [{k: v for k, v in m.items() if k != "plot"} for m in results]}))


if __name__ == "__main__":
    main()
