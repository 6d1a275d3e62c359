"""A spur gear pair (examples/gear_pair.toml): the worn flank profiles.

Runs examples/gear_pair.toml as a user would (building the model, the run
with its cycle jumps, writing its outputs), then reads each gear's wear
depth on its flanks against the radius, from root to tip: the flanks roll
without sliding at the pitch circle, so the wear vanishes there and grows
towards tip and root (Flodin and Andersson, Wear 207 (1997)). Checks each
part's worn volume against its Archard coefficient times its load-weighted
sliding (the friction work over the friction coefficient), writes
docs/img/gear_pair.png and the measured section of docs/examples/gear_pair.md,
prints the figures and, last, one JSON line.

    .venv/bin/python benchmarks/gear_pair.py [--revolutions N] [--save NPZ]   # a minute

or reads a finished run of it, of any duration (the section "After 10^5
revolutions" of the page and its figure):

    meshwear run examples/gear_pair.toml -o OUT --set run.duration=62831.85307179586
    .venv/bin/python benchmarks/gear_pair.py --from OUT
"""

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from common import timed_run, write_measured  # noqa: E402
from meshwear.scene.reader import load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "gear_pair.toml"
FIGURE = ROOT / "docs" / "img" / "gear_pair.png"
LONG_FIGURE = ROOT / "docs" / "img" / "gear_pair_long.png"
#: module, teeth and pressure angle of the example's gears (m, -, rad)
MODULE, TEETH, ALPHA = 0.002, 20, np.radians(20.0)
PITCH = 0.5 * MODULE * TEETH


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--revolutions", type=float, default=None,
                        help="instead of the example's 300 (no page written)")
    parser.add_argument("--from", dest="source", type=Path, default=None, metavar="OUT",
                        help="read a finished run of the example (any duration) from its "
                        "output folder instead of running it; writes the long-run section "
                        "of the page and docs/img/gear_pair_long.png")
    parser.add_argument("--save", default=None, metavar="NPZ",
                        help="also save the flank profiles there")
    args = parser.parse_args(argv)
    scene = load_scene(SCENE)
    rate = scene.bodies[0].path.rotation.rate
    if args.source is not None:
        model, depths, totals, result = read_run(scene, args.source)
        wall = result["wall_time"]
    else:
        if args.revolutions is not None:
            scene = scene.set("run.duration", args.revolutions * 2.0 * np.pi / rate)
        model, state, result, wall = timed_run(scene)
        pinion, wheel = state.bodies[0], state.parts[0]
        depths = {"pinion": pinion.wear_depth, "wheel": wheel.depth}
        totals = {"pinion": (pinion.wear_volume.sum(), pinion.friction_work.sum()),
                  "wheel": (wheel.volume.sum(), wheel.work.sum())}
    friction = scene.contact.friction
    coefficients = {"pinion": scene.wear.coefficient,
                    "wheel": model.surfaces.per_vertex[0].law[1]}
    profiles = {
        "pinion": flank_profile(model.bodies[0].reference_vertices - model.bodies[0].origin,
                                depths["pinion"]),
        "wheel": flank_profile(model.surfaces.per_vertex[0].reference_vertices,
                               depths["wheel"]),
    }
    row = {
        "wall": wall, "revolutions": rate * result["time"] / (2.0 * np.pi),
        "resolved_revolutions": result["resolved_cycles"], "jumps": result["jumps"],
        "error_estimate": result["error_estimate"], "jump_limits": result["jump_limits"],
        "pinion_vertices": len(depths["pinion"]), "wheel_vertices": len(depths["wheel"]),
    }
    for name, (volume, work) in totals.items():
        # Archard: volume = k x sum of N |ds| = k x friction work / mu in full slip
        row[f"{name}_volume_error"] = float(volume / (coefficients[name] * work / friction)
                                            - 1.0)
        row[f"{name}_depth"] = float(np.max(depths[name]))
    for name, p in profiles.items():
        for key in ("pitch_over_max", "addendum_max", "dedendum_max", "addendum_at",
                    "dedendum_at"):
            row[f"{name}_{key}"] = p[key]
    print(f"  {SCENE.name}: {wall:.1f} s, {row['revolutions']:.6g} revolutions, "
          f"{row['resolved_revolutions']:.0f} resolved in {row['jumps']} jumps "
          f"(limits {row['jump_limits']}), error estimate {row['error_estimate']:.2e}")
    print(f"  worn volume vs k sum N ds: pinion {row['pinion_volume_error']:+.1e}, "
          f"wheel {row['wheel_volume_error']:+.1e}")
    for name, p in profiles.items():
        print(f"  {name}: deepest {1e6 * p['deepest']:.4f} µm; at the pitch circle "
              f"{p['pitch_over_max']:.3f} of it; deepest above it "
              f"{1e6 * p['addendum_max']:.4f} µm at {1e3 * p['addendum_at']:.2f} mm, below it "
              f"{1e6 * p['dedendum_max']:.4f} µm at {1e3 * p['dedendum_at']:.2f} mm")
    if args.save:
        np.savez(args.save, **{f"{n}_{k}": v for n, p in profiles.items()
                               for k, v in p.items() if isinstance(v, np.ndarray)})
    if args.source is not None:
        plot(profiles, row, LONG_FIGURE)
        write_page(row, "gear_pair_long", LONG_FIGURE)
    elif args.revolutions is None:
        plot(profiles, row, FIGURE)
        write_page(row, "gear_pair", FIGURE)
    print(json.dumps({"benchmark": "gear_pair", **row}))


def read_run(scene, out):
    """The model of ``scene``, each gear's wear depth in the last frame of a
    finished run in folder ``out``, each one's (worn volume, friction work)
    and the run's summary.json."""
    from meshwear.model.build import build_model
    from meshwear.output.export import read_frame, series_frames

    result = json.loads((out / "summary.json").read_text())
    if result["status"] != "ok":
        raise SystemExit(f"{out}: the run has not ended well (status {result['status']!r})")
    depths = {name: np.asarray(read_frame(series_frames(out, name)[-1][1])
                               .point_data["wear_depth"], float)
              for name in ("pinion", "wheel")}
    totals = {"pinion": result["bodies"]["pinion"], "wheel": result["surfaces"]["wheel"]}
    totals = {k: (v["wear_volume"], v["friction_work"]) for k, v in totals.items()}
    return build_model(scene), depths, totals, result


def flank_profile(vertices, depth):
    """Mean wear depth of the flank vertices against their radius (their own
    frame), both flanks of every tooth: ``radius``, ``mean``, ``max`` per
    radius, and the mean at the pitch circle, tip and root over the deepest."""
    rho = np.hypot(vertices[:, 0], vertices[:, 1])
    base = PITCH * np.cos(ALPHA)
    # flank points: between the base circle and the tip, off the end faces'
    # centre fans (every outline point is on the flanks, tip or root)
    flank = (rho > base + 1e-7) & (rho < PITCH + MODULE - 1e-7)
    radii = np.unique(np.round(rho[flank], 9))
    mean = np.array([depth[flank][np.isclose(rho[flank], r, atol=1e-9)].mean() for r in radii])
    top = np.array([depth[flank][np.isclose(rho[flank], r, atol=1e-9)].max() for r in radii])
    deepest = float(mean.max())
    at = float(np.interp(PITCH, radii, mean))
    above, below = radii > PITCH, radii < PITCH
    return {"radius": radii, "mean": mean, "max": top, "deepest": deepest,
            "pitch_over_max": at / deepest,
            "addendum_max": float(mean[above].max()),
            "addendum_at": float(radii[above][np.argmax(mean[above])]),
            "dedendum_max": float(mean[below].max()),
            "dedendum_at": float(radii[below][np.argmax(mean[below])])}


def plot(profiles, row, figure):
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for k, (name, p) in enumerate(profiles.items()):
        ax.plot(1e3 * p["radius"], 1e6 * p["mean"], "-o", ms=2.5, color=f"C{k}",
                label=f"{name}, mean over the flanks")
    ax.axvline(1e3 * PITCH, color="k", lw=0.8, ls="--")
    ax.text(1e3 * PITCH, ax.get_ylim()[1] * 0.95, " pitch circle", fontsize=8, va="top")
    ax.set_xlabel("radius on the flank (mm): base circle → tip")
    ax.set_ylabel("wear depth (µm)")
    ax.set_title(f"Spur gear pair after {row['revolutions']:.0f} revolutions: flank wear")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(figure, dpi=110)
    plt.close(fig)


def write_page(r, section, figure):
    write_measured("gear_pair", [
        ("wall time (build, run, outputs)",
         f"{r['wall']:.0f} s: {r['revolutions']:.0f} revolutions, "
         f"{r['resolved_revolutions']:.0f} of them resolved, {r['jumps']} jumps "
         f"({r['pinion_vertices']:,} pinion and {r['wheel_vertices']:,} wheel vertices)"),
        ("jumps limited by", ", ".join(f"{k} {v}" for k, v in r["jump_limits"].items() if v)),
        ("estimated error of the wear depth (summary.json)", f"{r['error_estimate']:.1e}"),
        ("worn volume vs $k \\sum N\\lvert ds\\rvert$, pinion / wheel",
         f"{r['pinion_volume_error']:+.1e} / {r['wheel_volume_error']:+.1e}"),
        ("deepest wear of a vertex, pinion / wheel",
         f"{1e6 * r['pinion_depth']:.3f} µm / {1e6 * r['wheel_depth']:.3f} µm"),
        ("wear at the pitch circle (20 mm) / deepest, pinion / wheel",
         f"{r['pinion_pitch_over_max']:.3f} / {r['wheel_pitch_over_max']:.3f}"),
        ("deepest above the pitch circle (addendum), pinion / wheel",
         f"{1e6 * r['pinion_addendum_max']:.3f} µm at {1e3 * r['pinion_addendum_at']:.2f} mm"
         f" / {1e6 * r['wheel_addendum_max']:.3f} µm at {1e3 * r['wheel_addendum_at']:.2f} mm"),
        ("deepest below the pitch circle (dedendum), pinion / wheel",
         f"{1e6 * r['pinion_dedendum_max']:.3f} µm at {1e3 * r['pinion_dedendum_at']:.2f} mm"
         f" / {1e6 * r['wheel_dedendum_max']:.3f} µm at {1e3 * r['wheel_dedendum_at']:.2f} mm"),
    ], figure.name, "the worn flank profiles", section=section)


if __name__ == "__main__":
    main()
