"""Pin on a worn disc: both parts' wear against their closed forms.

Runs examples/pin_on_worn_disc.toml as a user would (building the model, the
run, writing its outputs) and compares

* each part's worn volume with its ``k P s`` (``s`` the mean sliding distance
  of the pin's face, ``omega t (R + a^2 / 8 R)``);
* the disc's track across its width with ``k p c(u)`` per turn, ``c(u)`` the
  arc of the circle of radius ``R + u`` inside the pin's face, projected on
  the disc mesh (``tests/cases.py``), as the largest difference over the
  running-face vertices within 0.8 a of the centre line, relative to the
  centre depth;
* the forces on the two parts and their friction work.

Writes docs/img/pin_on_worn_disc_track.png and the measured section of
docs/examples/pin_on_worn_disc.md, prints a table and, last, one JSON line.

    .venv/bin/python benchmarks/pin_on_worn_disc.py      # about 20 s here
"""

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from common import timed_run, write_measured  # noqa: E402
from meshwear.scene.reader import load_scene

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
import cases  # noqa: E402

SCENE = ROOT / "examples" / "pin_on_worn_disc.toml"
FIGURE = ROOT / "docs" / "img" / "pin_on_worn_disc_track.png"


def main():
    scene = load_scene(SCENE)
    model, state, result, wall = timed_run(scene)
    body, surface = scene.bodies[0], scene.surfaces[0]
    a, load = body.shape.radius, -body.force[2]
    track = float(np.hypot(*body.position[:2]))
    omega = surface.rotation.rate
    k_pin, k_disc = scene.wear.coefficient, surface.coefficient
    face = 0.5 * surface.shape.height          # the running face, in the mesh's own frame
    s = omega * state.time * (track + a * a / (8.0 * track))
    turns = omega * state.time / (2.0 * np.pi)
    pressure = load / (np.pi * a * a)
    pin, part = state.bodies[0], state.parts[0]
    disc = model.surfaces.per_vertex[0]
    expected, u = cases.disc_track(disc.reference_vertices, disc.faces, face, track, a, pressure,
                                   k_disc, turns)
    running = np.abs(disc.reference_vertices[:, 2] - face) < 1e-9
    near = running & (np.abs(u) < 0.8 * a)
    centre = k_disc * pressure * 2.0 * a * turns
    row = {
        "wall": wall, "steps": state.step, "turns": turns,
        "pin_vertices": len(pin.wear_depth), "disc_vertices": len(part.depth),
        "pin_volume_error": float(pin.wear_volume.sum() / (k_pin * load * s) - 1.0),
        "disc_volume_error": float(part.volume.sum() / (k_disc * load * s) - 1.0),
        "track_error": float(np.abs(part.depth[near] - expected[near]).max() / centre),
        "track_rms": float(np.sqrt(np.mean((part.depth[near] - expected[near]) ** 2)) / centre),
        "centre_depth": float(centre), "max_disc_depth": float(part.depth.max()),
        "work_difference": float(part.work.sum() / pin.friction_work.sum() - 1.0),
        "force_sum": float(np.linalg.norm(np.add(result["surfaces"]["disc"]["contact_force"],
                                                 result["bodies"]["pin"]["contact_force"]))),
    }
    print(f"  {SCENE.name}: {wall:.1f} s, {state.step} steps, {turns:.1f} turns")
    print(f"  pin volume vs k_pin P s   {row['pin_volume_error']:+.1e}")
    print(f"  disc volume vs k_disc P s {row['disc_volume_error']:+.1e}")
    print(f"  disc track vs arc law     {row['track_error']:.1e} of the centre depth "
          f"(rms {row['track_rms']:.1e})")
    print(f"  friction work, disc vs pin {row['work_difference']:+.1e}; "
          f"forces on the two add up to {row['force_sum']:.1e} N")
    plot(u, part.depth, running, expected, a, track, k_disc * pressure * turns)
    write_page(row)
    print(json.dumps({"benchmark": "pin_on_worn_disc", **row}))


def plot(u, depth, running, expected, a, track, scale):
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    near = running & (np.abs(u) < 1.3 * a)
    ax.plot(1e3 * u[near], 1e9 * depth[near], ".", ms=2, color="0.55",
            label="disc vertices (running face)")
    order = np.argsort(u[near])
    ax.plot(1e3 * u[near][order], 1e9 * expected[near][order], "-", lw=0.8, color="C0",
            label=r"$k\,p\,c(u)$ per turn, projected on the mesh")
    grid = np.linspace(-a, a, 400)
    ax.plot(1e3 * grid, 1e9 * scale * cases.arc_chord(grid, a, track), "k-", lw=1.2,
            label=r"arc law $k\,p\,c(u)$ per turn")
    ax.plot(1e3 * grid, 1e9 * scale * 2.0 * np.sqrt(a * a - grid ** 2), "k--", lw=0.8,
            label=r"straight chord $2\sqrt{a^2-u^2}$ ($R \gg a$)")
    ax.set_xlabel("u across the track, from its centre line (mm)")
    ax.set_ylabel("disc wear depth (nm)")
    ax.set_title("Pin on a worn disc: the track after ten turns")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


def write_page(r):
    write_measured("pin_on_worn_disc", [
        ("wall time (build, run, outputs)", f"{r['wall']:.1f} s ({r['steps']} steps, "
         f"{r['pin_vertices']:,} pin and {r['disc_vertices']:,} disc vertices)"),
        ("pin's worn volume vs $k_{pin} P s$", f"{r['pin_volume_error']:+.1e}"),
        ("disc's worn volume vs $k_{disc} P s$", f"{r['disc_volume_error']:+.1e}"),
        ("disc track vs the arc law (largest, within 0.8 a)",
         f"{r['track_error']:.1e} of the centre depth (rms {r['track_rms']:.1e})"),
        ("friction work, disc vs pin", f"{r['work_difference']:+.1e}"),
        ("contact forces on the two parts, summed", f"{r['force_sum']:.1e} N"),
    ], FIGURE.name, "the disc's track")


if __name__ == "__main__":
    main()
