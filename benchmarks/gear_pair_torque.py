"""Spur gears transmitting torque (examples/mechanisms/gear_pair_torque.toml).

Runs the example as a user would (10^4 revolutions with cycle jumps, its
outputs written; about eleven minutes here), or reads a finished run of it
(``--from OUT``). Then:

- reads each gear's wear depth on its flanks against the radius, the loaded
  flanks (the pinion's leading ones, the wheel's trailing ones: both on the
  side of larger angle in their own frames) apart from the unloaded ones;
- puts them beside the double-flank example's (examples/gear_pair.toml, run
  to the same 10^4 revolutions, or read with ``--double OUT``), whose 30 N
  press along the line of centres loads both flanks of a tooth with
  30 / (2 sin 20°) = 43.9 N, against 0.6 N·m / r_b = 31.9 N on one flank
  here: the loaded flanks should wear about 31.9 / 43.9 = 0.73 of the
  double-flank ones, with the same profile;
- runs 0.03 s of the mechanism, every step resolved, and sums the pinion's
  contact force per tooth: one tooth pair or two in mesh (the contact ratio
  of the pair), the force of the pair shared where two mesh, and the
  unloaded flanks' force (zero while the teeth stay in mesh: single-flank
  contact).

Writes docs/img/gear_pair_torque.png and the measured section of
docs/examples/gear_pair_torque.md, prints the figures and one JSON line.

    .venv/bin/python benchmarks/gear_pair_torque.py                  # about twelve minutes
    .venv/bin/python benchmarks/gear_pair_torque.py --from OUT [--double OUT2]
"""

import argparse
import json
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from common import write_measured  # noqa: E402
from gear_pair import ALPHA, MODULE, PITCH, TEETH  # noqa: E402
from meshwear import cli  # noqa: E402
from meshwear.model.build import build_model, initial_state  # noqa: E402
from meshwear.output.export import read_frame, series_frames  # noqa: E402
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "mechanisms" / "gear_pair_torque.toml"
DOUBLE = ROOT / "examples" / "gear_pair.toml"
FIGURE = ROOT / "docs" / "img" / "gear_pair_torque.png"
#: the double-flank example's press along the line of centres (N)
PRESS = 30.0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--from", dest="source", type=Path, default=None, metavar="OUT",
                        help="read a finished run of the example from its output folder")
    parser.add_argument("--double", type=Path, default=None, metavar="OUT",
                        help="read a finished run of examples/gear_pair.toml over the same "
                        "revolutions instead of running it")
    args = parser.parse_args(argv)
    scene = load_scene(SCENE)
    revolutions = scene.run.duration / scene.wear.period
    torque = load_torque(scene)
    with tempfile.TemporaryDirectory() as folder:
        out = args.source or Path(folder) / "torque"
        if args.source is None:
            if cli.main(["run", str(SCENE), "-o", str(out), "-q"]) != 0:
                raise SystemExit("the example's run failed")
        summary = json.loads((out / "summary.json").read_text())
        if summary["status"] != "ok":
            raise SystemExit(f"{out}: the run has not ended well ({summary['status']!r})")
        wall = summary["wall_time"]
        torque_depths = last_depths(out)
        double = args.double or Path(folder) / "double"
        if args.double is None:
            rate = load_scene(DOUBLE).bodies[0].path.rotation.rate
            duration = repr(revolutions * 2.0 * np.pi / rate)
            if cli.main(["run", str(DOUBLE), "-o", str(double), "-q",
                         "--set", f"run.duration={duration}"]) != 0:
                raise SystemExit("the double-flank example's run failed")
        double_summary = json.loads((double / "summary.json").read_text())
        double_depths = last_depths(double)
    model = build_model(scene)
    own = {"pinion": model.bodies[0].reference_vertices - model.bodies[0].origin,
           "wheel": model.surfaces.per_vertex[0].reference_vertices}
    profiles = {name: {side: flank_profile(own[name], torque_depths[name], side)
                       for side in ("loaded", "unloaded")} for name in own}
    double_profiles = {name: flank_profile(own[name], double_depths[name], "both")
                       for name in own}
    mesh = mesh_forces(scene)
    normal = torque / (PITCH * np.cos(ALPHA))
    row = {
        "revolutions": revolutions, "wall_time_s": wall,
        "resolved_cycles": summary["resolved_cycles"], "jumps": summary["jumps"],
        "error_estimate": summary["error_estimate"],
        "double_wall_time_s": double_summary["wall_time"],
        "flank_force_expected_N": normal,
        "flank_force_double_N": PRESS / (2.0 * np.sin(ALPHA)),
        "load_share_expected": normal / (PRESS / (2.0 * np.sin(ALPHA))),
    }
    for name in own:
        loaded, unloaded = profiles[name]["loaded"], profiles[name]["unloaded"]
        row[f"{name}_loaded_deepest_um"] = 1e6 * loaded["deepest"]
        row[f"{name}_unloaded_over_loaded"] = unloaded["deepest"] / loaded["deepest"]
        row[f"{name}_double_deepest_um"] = 1e6 * double_profiles[name]["deepest"]
        # the loaded flank against the double-flank one, radius by radius,
        # where the double-flank wear is more than a tenth of its deepest
        d = double_profiles[name]
        worn = d["mean"] > 0.1 * d["deepest"]
        ratio = loaded["mean"][worn] / d["mean"][worn]
        row[f"{name}_over_double_median"] = float(np.median(ratio))
        row[f"{name}_over_double_iqr"] = [float(x) for x in np.percentile(ratio, [25, 75])]
        row[f"{name}_pitch_over_max"] = loaded["pitch_over_max"]
        row[f"{name}_dedendum_at_mm"] = 1e3 * loaded["dedendum_at"]
    row.update(mesh["row"])
    plot(profiles, double_profiles, mesh, row)
    rows = [
        ("revolutions", f"{revolutions:.6g} (100 rad/s, cycle jumps over a revolution)"),
        ("run time", f"{wall:.0f} s ({row['resolved_cycles']:.0f} resolved revolutions, "
                     f"{row['jumps']} jumps, error estimate {row['error_estimate']:.3g}); "
                     f"the double-flank example to the same revolutions "
                     f"{row['double_wall_time_s']:.0f} s"),
        ("tooth pairs in mesh (0.03 s resolved)",
         f"two for {100 * row['two_pairs_fraction']:.0f} % of the time, one for the rest "
         f"(contact ratio of the pair {row['contact_ratio_expected']:.2f}: "
         f"{100 * (row['contact_ratio_expected'] - 1):.0f} % expected)"),
        ("force on the loaded flanks (normal, sum over the teeth)",
         f"mean {row['mesh_force_mean_N']:.1f} N (torque / base radius "
         f"{row['flank_force_expected_N']:.1f} N), {row['mesh_force_min_N']:.1f}"
         f"–{row['mesh_force_max_N']:.1f} N over three mesh periods"),
        ("one tooth's force where two pairs mesh / where it meshes alone",
         f"{row['shared_over_alone']:.2f} (median)"),
        ("largest force on an unloaded flank", f"{row['unloaded_force_max_N']:.3g} N"),
        ("unloaded / loaded flanks' deepest wear, pinion / wheel",
         f"{row['pinion_unloaded_over_loaded']:.2g} / {row['wheel_unloaded_over_loaded']:.2g}"),
        ("deepest wear of the loaded flanks (mean over the flanks), pinion / wheel",
         f"{row['pinion_loaded_deepest_um']:.3f} µm / {row['wheel_loaded_deepest_um']:.3f} µm "
         f"(double-flank {row['pinion_double_deepest_um']:.3f} / "
         f"{row['wheel_double_deepest_um']:.3f} µm)"),
        ("loaded flank / double-flank wear, radius by radius (median, quartiles), pinion",
         "{:.2f} ({:.2f}–{:.2f}); the flank forces' ratio {:.2f}".format(
             row["pinion_over_double_median"], *row["pinion_over_double_iqr"],
             row["load_share_expected"])),
        ("the same, wheel", "{:.2f} ({:.2f}–{:.2f})".format(
            row["wheel_over_double_median"], *row["wheel_over_double_iqr"])),
        ("wear at the pitch circle / deepest, pinion / wheel",
         f"{row['pinion_pitch_over_max']:.3f} / {row['wheel_pitch_over_max']:.3f}"),
    ]
    write_measured("gear_pair_torque", rows, FIGURE.name,
                   "flank wear beside the double-flank example's; the force per tooth")
    for quantity, value in rows:
        print(f"{quantity:60s} {value}")
    print(json.dumps({"benchmark": "gear_pair_torque", **row}))


def last_depths(out):
    """Each gear's wear depth in the last frame of a finished run in ``out``."""
    return {name: np.asarray(read_frame(series_frames(out, name)[-1][1])
                             .point_data["wear_depth"], float)
            for name in ("pinion", "wheel")}


def tooth_and_side(vertices):
    """Each vertex's tooth (0 at +x in the gear's own frame) and side: +1 on
    the flank at larger angle than the tooth's centre, -1 on the other."""
    phi = np.arctan2(vertices[:, 1], vertices[:, 0])
    gap = 2.0 * np.pi / TEETH
    tooth = np.round(phi / gap).astype(int)
    return tooth % TEETH, np.sign(phi - tooth * gap)


def flank_profile(vertices, depth, side):
    """Mean wear depth of the flank vertices against their radius (the
    gear's own frame): the ``loaded`` flanks (larger angle: the pinion turns
    that way and drives, the wheel turns the other way and is driven), the
    ``unloaded`` ones, or ``both``."""
    rho = np.hypot(vertices[:, 0], vertices[:, 1])
    base = PITCH * np.cos(ALPHA)
    flank = (rho > base + 1e-7) & (rho < PITCH + MODULE - 1e-7)
    _, sign = tooth_and_side(vertices)
    if side != "both":
        flank &= sign == (1 if side == "loaded" else -1)
    radii = np.unique(np.round(rho[flank], 9))
    mean = np.array([depth[flank][np.isclose(rho[flank], r, atol=1e-9)].mean() for r in radii])
    deepest = float(mean.max())
    below = radii < PITCH
    return {"radius": radii, "mean": mean, "deepest": deepest,
            "pitch_over_max": float(np.interp(PITCH, radii, mean)) / max(deepest, 1e-300),
            "dedendum_at": float(radii[below][np.argmax(mean[below])])}


class ToothForces:
    """Observer: the pinion's normal contact force per tooth and flank at
    every history sample."""

    def __init__(self, vertices):
        self.tooth, self.sign = tooth_and_side(vertices)
        self.time, self.loaded, self.unloaded, self.angle = [], [], [], []

    def on_sample(self, model, state):
        force = state.bodies[0].normal_force.sum(axis=0)
        self.time.append(state.time)
        self.angle.append(float(model.dynamics.columns()["pinion.q"]))
        self.loaded.append(np.bincount(self.tooth[self.sign > 0], force[self.sign > 0],
                                       minlength=TEETH))
        self.unloaded.append(np.bincount(self.tooth[self.sign < 0], force[self.sign < 0],
                                         minlength=TEETH))

    def on_frame(self, model, state):
        pass


def mesh_forces(scene, duration=0.03, settle=0.02):
    """The pinion's contact force per tooth over ``duration`` s of the
    mechanism from its keyframe, every step resolved; the figures from the
    last ``duration - settle`` s (three mesh periods)."""
    short = scene.set({"run.duration": duration, "run.frames": 0, "run.history": 3001,
                       "wear.acceleration": "none"})
    model = build_model(short)
    forces = ToothForces(model.bodies[0].reference_vertices - model.bodies[0].origin)
    start = time.perf_counter()
    run(model, initial_state(model), observers=[forces])
    wall = time.perf_counter() - start
    t = np.asarray(forces.time)
    keep = t >= settle
    loaded = np.asarray(forces.loaded)[keep]
    unloaded = np.asarray(forces.unloaded)[keep]
    total = loaded.sum(axis=1)
    # a tooth in mesh carries more than 2 % of the pair's force
    meshing = loaded > 0.02 * total.mean()
    pairs = meshing.sum(axis=1)
    alone = loaded[(pairs == 1)[:, None] & meshing]
    shared = loaded[(pairs == 2)[:, None] & meshing]
    ra, rb = PITCH + MODULE, PITCH * np.cos(ALPHA)
    mjcf = mechanism_model(scene)
    centre = float(np.linalg.norm(mjcf.body("wheel").pos - mjcf.body("pinion").pos))
    alpha_w = np.arccos(2.0 * rb / centre)
    # the length of contact over the base pitch, both gears alike
    ratio = (2.0 * np.sqrt(ra ** 2 - rb ** 2) - centre * np.sin(alpha_w)) / (
        2.0 * np.pi * rb / TEETH)
    return {"time": t[keep], "angle": np.asarray(forces.angle)[keep], "loaded": loaded,
            "total": total, "row": {
                "mesh_wall_time_s": wall,
                "mesh_force_mean_N": float(total.mean()), "mesh_force_min_N": float(total.min()),
                "mesh_force_max_N": float(total.max()),
                "two_pairs_fraction": float(np.mean(pairs == 2)),
                "more_pairs_fraction": float(np.mean(pairs > 2)),
                "contact_ratio_expected": float(ratio),
                "shared_over_alone": float(np.median(shared) / np.median(alone)),
                "unloaded_force_max_N": float(unloaded.sum(axis=1).max())}}


def mechanism_model(scene):
    """The example's MuJoCo model."""
    import mujoco

    return mujoco.MjModel.from_xml_path(str(SCENE.parent / scene.mechanism.model))


def load_torque(scene):
    """The resisting torque on the wheel (N·m): the ``load`` actuator's input,
    from the scene's controls or else its keyframe."""
    controls = dict(scene.mechanism.controls or {})
    if "load" in controls:
        return float(controls["load"])
    mjcf = mechanism_model(scene)
    return float(mjcf.key(scene.mechanism.keyframe).ctrl[mjcf.actuator("load").id])


def plot(profiles, double_profiles, mesh, row):
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.4))
    for k, name in enumerate(("pinion", "wheel")):
        for side, style in (("loaded", "-o"), ("unloaded", ":")):
            p = profiles[name][side]
            left.plot(1e3 * p["radius"], 1e6 * p["mean"], style, ms=2.5, color=f"C{k}",
                      label=f"{name}, {side} flanks (torque)")
        d = double_profiles[name]
        left.plot(1e3 * d["radius"], 1e6 * row["load_share_expected"] * d["mean"], "--",
                  color=f"C{k + 2}",
                  label=f"{name}, double-flank example × {row['load_share_expected']:.2f}")
    left.axvline(1e3 * PITCH, color="k", lw=0.8, ls="--")
    left.set_xlabel("radius on the flank (mm): base circle → tip")
    left.set_ylabel("wear depth, mean over the flanks (µm)")
    left.set_title(f"flank wear after {row['revolutions']:.0e} revolutions")
    left.legend(fontsize=7)
    period = 2.0 * np.pi / TEETH
    phase = np.degrees(np.mod(mesh["angle"], 2.0 * np.pi))
    for tooth in range(TEETH):
        f = mesh["loaded"][:, tooth]
        if f.max() > 0.02 * mesh["total"].mean():
            right.plot(phase, f, lw=1.0, label=f"tooth {tooth}")
    right.plot(phase, mesh["total"], color="k", lw=1.2, label="sum")
    right.set_xlabel("pinion angle (°)")
    right.set_ylabel("normal contact force on the loaded flanks (N)")
    right.set_title(f"force per pinion tooth ({np.degrees(period):.0f}° a mesh period)")
    right.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
