"""The two contact models side by side as a ball's wear scar grows: from Hertz to conforming.

A 10 mm steel ball pressed by 10 N on a steel flat (Hertz: a = 69 µm,
p0 = 1.0 GPa), worn by two motions, each run with ``[contact] model =
"half-space"`` (E = 210 GPa, nu = 0.3) and with the Winkler foundation
whose contact has Hertz's radius (K = P / (pi R delta²), delta = a² / 2R):

- reciprocating sliding: +-0.25 mm strokes (gross slip), 150 cycles;
- pin on disc: the ball 20 mm from the axis of a disc turning at 5 rad/s
  (0.1 m/s), 1 s.

The wear coefficient is set so that the scar grows to about four Hertz
radii. Prints, at the start and at the end, each model's contact radius,
peak pressure and deepest wear, and writes the figure
docs/img/elastic_vs_winkler.png (contact radius, peak pressure and deepest
wear against the sliding distance, and the pressure across the contact at
the start and at the end) and the measured section of
docs/examples/elastic_vs_winkler.md. About two minutes here.

    .venv/bin/python benchmarks/elastic_vs_winkler.py [--no-write]
"""

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import write_measured  # noqa: E402

from meshwear.step import stepper  # noqa: E402
from meshwear.contact.halfspace import contact_modulus  # noqa: E402
from meshwear.model.build import build_model, initial_state  # noqa: E402
from meshwear.scene.reader import parse_scene

E, NU, R, LOAD, MU = 210e9, 0.3, 0.005, 10.0, 0.5
E_STAR = contact_modulus((E, E), (NU, NU))
A = (3.0 * LOAD * R / (4.0 * E_STAR)) ** (1.0 / 3.0)
P0 = 3.0 * LOAD / (2.0 * np.pi * A * A)
DELTA_W = A * A / (2.0 * R)
K_WINKLER = LOAD / (np.pi * R * DELTA_W * DELTA_W)

MOTIONS = {
    # name: (ball position, path, disc rotation, duration (s), dt (s), wear coefficient)
    "reciprocating": ([0.0, 0.0, R], {"oscillation": {"axis": [1.0, 0.0, 0.0],
                                                      "amplitude": 2.5e-4, "frequency": 1.0}},
                      None, 150.0, 0.125, 1.3e-12),
    "pin on disc": ([0.02, 0.0, R], {}, {"axis": [0.0, 0.0, 1.0], "rate": 5.0,
                                        "center": [0.0, 0.0, 0.0]}, 1.0, 1e-3, 1.9e-12),
}


def scene(model, motion):
    position, path, rotation, duration, dt, k = MOTIONS[motion]
    if model == "half-space":
        contact = {"model": "half-space", "youngs_modulus": E, "poissons_ratio": NU}
    else:
        contact = {"stiffness_per_area": K_WINKLER}
    contact.update(friction=MU, margin=1e-5)
    surface = {"name": "flat", "type": "plane", "size": 0.06}
    if rotation is not None:
        surface["rotation"] = rotation
    data = {
        "format": 1,
        "run": {"mode": "quasi-static", "duration": duration, "dt": dt, "frames": 0,
                "history": 2, "gravity": [0.0, 0.0, 0.0]},
        "contact": contact,
        "wear": {"law": "energy_density", "coefficient": k},
        "body": [{"name": "ball", "shape": {"type": "sphere", "radius": R, "subdivisions": 4},
                  "resolution": 1e-5, "resolution_reach": 2e-5, "mass": 0.004,
                  "position": position, "force": [0.0, 0.0, -LOAD], "motion": "guided",
                  "path": dict(path, free_axis=[0.0, 0.0, 1.0])}],
        "surface": [surface],
    }
    return parse_scene(data)


def snapshot(model, state):
    """Contact radius (m), peak pressure (Pa), deepest wear (m), friction
    work (J) and the pressure across the contact along x (r, p)."""
    s, b = state.bodies[0], model.bodies[0]
    force = s.normal_force.sum(axis=0)
    loaded = force > 0.0
    x = s.vertices[:, 0:2]
    r = np.hypot(x[:, 0], x[:, 1])
    pressure = force[loaded] / b.area_vectors[loaded, 3]
    band = loaded & (np.abs(x[:, 1]) < 6e-6)
    order = np.argsort(x[band, 0])
    return {"radius": float(r[loaded].max()), "peak": float(pressure.max()),
            "wear": float(s.wear_depth.max()), "work": float(s.friction_work.sum()),
            "profile": (x[band, 0][order], (force[band] / b.area_vectors[band, 3])[order])}


def run(model_name, motion, samples=15):
    model = build_model(scene(model_name, motion))
    state = initial_state(model)
    start = time.perf_counter()
    out = [(0.0, snapshot(model, state))]
    for stop in np.linspace(0, model.n_steps, samples + 1)[1:].astype(int):
        stepper.advance(model, state, int(stop))
        out.append((state.time, snapshot(model, state)))
    return out, time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true",
                        help="print only; leave the docs page and the figure as they are")
    args = parser.parse_args()
    results = {}
    print(f"Hertz: a = {A * 1e6:.1f} µm, p0 = {P0 / 1e9:.3f} GPa; Winkler K = {K_WINKLER:.3g} N/m³")
    print(f"{'motion':>14}{'model':>12}{'':>6}{'radius (µm)':>13}{'peak (GPa)':>12}"
          f"{'max wear (µm)':>15}{'wall (s)':>10}")
    for motion in MOTIONS:
        for name in ("half-space", "winkler"):
            series, wall = run(name, motion)
            results[(motion, name)] = series
            for label, (_, snap) in (("start", series[0]), ("end", series[-1])):
                print(f"{motion:>14}{name:>12}{label:>6}{snap['radius'] * 1e6:>13.1f}"
                      f"{snap['peak'] / 1e9:>12.3f}{snap['wear'] * 1e6:>15.3f}"
                      f"{wall if label == 'end' else float('nan'):>10.1f}")
    rows = []
    for motion in MOTIONS:
        h, w = results[(motion, "half-space")], results[(motion, "winkler")]
        for label, k in (("start", 0), ("end", -1)):
            hs, ws = h[k][1], w[k][1]
            rows.append((f"{motion}, {label}: contact radius, half-space / Winkler",
                         f"{hs['radius'] * 1e6:.1f} / {ws['radius'] * 1e6:.1f} µm"))
            rows.append((f"{motion}, {label}: peak pressure, half-space / Winkler",
                         f"{hs['peak'] / 1e9:.3f} / {ws['peak'] / 1e9:.3f} GPa"))
            if k == -1:
                rows.append((f"{motion}, end: deepest wear, half-space / Winkler",
                             f"{hs['wear'] * 1e6:.2f} / {ws['wear'] * 1e6:.2f} µm "
                             f"({hs['wear'] / ws['wear'] - 1.0:+.1%})"))
    rows.insert(0, ("Hertz contact radius a, peak pressure p0",
                    f"{A * 1e6:.1f} µm, {P0 / 1e9:.3f} GPa"))
    print(json.dumps({"benchmark": "elastic_vs_winkler", "rows": rows}))
    if args.no_write:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 4, figsize=(16, 7.5))
    for row, motion in enumerate(MOTIONS):
        ax_r, ax_p, ax_w, ax_profile = axes[row]
        for name, style in (("half-space", "-"), ("winkler", "--")):
            series = results[(motion, name)]
            work = np.array([snap["work"] for _, snap in series])
            distance = work / (MU * LOAD) * 1e3
            ax_r.plot(distance, [s["radius"] * 1e6 for _, s in series], style, label=name)
            ax_p.plot(distance, [s["peak"] / 1e9 for _, s in series], style, label=name)
            ax_w.plot(distance, [s["wear"] * 1e6 for _, s in series], style, label=name)
            for k, colour in ((0, "C0"), (-1, "C3")):
                x, p = series[k][1]["profile"]
                ax_profile.plot(x * 1e6, p / 1e9, style, color=colour,
                                label=f"{name}, {'start' if k == 0 else 'end'}")
        ax_r.axhline(A * 1e6, color="grey", lw=0.8)
        ax_r.set(xlabel="sliding distance (mm)", ylabel="contact radius (µm)",
                 title=f"{motion}: contact radius")
        ax_p.set(xlabel="sliding distance (mm)", ylabel="peak pressure (GPa)",
                 title=f"{motion}: peak pressure")
        ax_w.set(xlabel="sliding distance (mm)", ylabel="deepest wear (µm)",
                 title=f"{motion}: deepest wear")
        ax_profile.set(xlabel="x (µm)", ylabel="pressure (GPa)",
                       title=f"{motion}: pressure across the contact")
        for ax in (ax_r, ax_p, ax_w, ax_profile):
            ax.legend(fontsize=7)
    fig.tight_layout()
    root = Path(__file__).resolve().parents[1]
    fig.savefig(root / "docs" / "img" / "elastic_vs_winkler.png", dpi=90)
    write_measured("elastic_vs_winkler", rows, "elastic_vs_winkler.png",
                   "contact radius, peak pressure and deepest wear of both models")


if __name__ == "__main__":
    main()
