"""Spur gears under torque, quasi-static (examples/gear_pair_torque_quasi_static.toml)
against the MuJoCo run of the same gears (examples/mechanisms/gear_pair_torque.toml).

Runs the quasi-static example to 10^4 revolutions (or reads a finished run,
``--from OUT``) and to 10^5 (``--long OUT`` reads one; ``--no-long`` skips
it), reads a finished MuJoCo run (``--mujoco OUT``: it takes about 13
minutes; without it the comparison is left out), then:

- each gear's worn volume and the deepest mean wear of its loaded flanks,
  and the flank profile radius by radius, against the MuJoCo run's;
- 0.03 s resolved (three mesh periods after 0.02 s): the pinion's normal
  force per tooth, how often two pairs mesh, one tooth's share where two
  mesh, and the largest force on an unloaded flank;
- the torque balance: the normal forces' torque about the pinion's axis
  at every step of that stretch against the 0.6 N·m.

Writes docs/img/gear_pair_torque_quasi_static.png and the measured section
of docs/examples/gear_pair_torque_quasi_static.md, prints the figures and
one JSON line.

    .venv/bin/python benchmarks/gear_pair_torque_quasi_static.py --mujoco OUT_MUJOCO
"""

import argparse
import json
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from common import write_measured  # noqa: E402
from gear_pair import ALPHA, PITCH, TEETH  # noqa: E402
from gear_pair_torque import flank_profile, last_depths, tooth_and_side  # noqa: E402
from meshwear import cli  # noqa: E402
from meshwear.model.build import build_model, initial_state  # noqa: E402
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run  # noqa: E402
from meshwear.surfaces import quaternion_matrix  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "gear_pair_torque_quasi_static.toml"
FIGURE = ROOT / "docs" / "img" / "gear_pair_torque_quasi_static.png"
#: 10^5 revolutions at 100 rad/s (s)
LONG = 1e5 * 2.0 * np.pi / 100.0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--from", dest="source", type=Path, default=None, metavar="OUT")
    parser.add_argument("--long", type=Path, default=None, metavar="OUT")
    parser.add_argument("--no-long", action="store_true")
    parser.add_argument("--mujoco", type=Path, default=None, metavar="OUT")
    args = parser.parse_args(argv)
    scene = load_scene(SCENE)
    torque = scene.bodies[0].path.rotation.torque
    with tempfile.TemporaryDirectory() as folder:
        out = args.source or Path(folder) / "qs"
        if args.source is None and cli.main(["run", str(SCENE), "-o", str(out), "-q"]) != 0:
            raise SystemExit("the example's run failed")
        summary = json.loads((out / "summary.json").read_text())
        depths = last_depths(out)
        long_summary = None
        if not args.no_long:
            long_out = args.long or Path(folder) / "long"
            if args.long is None and cli.main(["run", str(SCENE), "-o", str(long_out), "-q",
                                               "--set", f"run.duration={LONG!r}"]) != 0:
                raise SystemExit("the 10^5 revolutions' run failed")
            long_summary = json.loads((long_out / "summary.json").read_text())
    model = build_model(scene)
    own = {"pinion": model.bodies[0].reference_vertices - model.bodies[0].origin,
           "wheel": model.surfaces.per_vertex[0].reference_vertices}
    profiles = {name: {side: flank_profile(own[name], depths[name], side)
                       for side in ("loaded", "unloaded")} for name in own}
    volume = {"pinion": summary["bodies"]["pinion"]["wear_volume"],
              "wheel": _surface_volume(summary, "wheel")}
    row = {"revolutions": summary["cycles"], "wall_time_s": summary["wall_time"],
           "resolved_cycles": summary["resolved_cycles"], "jumps": summary.get("jumps"),
           "error_estimate": summary.get("error_estimate")}
    if long_summary is not None:
        row.update(long_revolutions=long_summary["cycles"],
                   long_wall_time_s=long_summary["wall_time"],
                   long_resolved_cycles=long_summary["resolved_cycles"],
                   long_jumps=long_summary.get("jumps"))
    for name in own:
        row[f"{name}_loaded_deepest_um"] = 1e6 * profiles[name]["loaded"]["deepest"]
        row[f"{name}_unloaded_deepest_um"] = 1e6 * profiles[name]["unloaded"]["deepest"]
        row[f"{name}_volume_mm3"] = 1e9 * volume[name]
    mujoco = None
    if args.mujoco is not None:
        m_summary = json.loads((args.mujoco / "summary.json").read_text())
        m_depths = last_depths(args.mujoco)
        mujoco = {name: flank_profile(own[name], m_depths[name], "loaded") for name in own}
        row["mujoco_wall_time_s"] = m_summary["wall_time"]
        for name in own:
            m_volume = (m_summary["bodies"]["pinion"]["wear_volume"] if name == "pinion"
                        else _surface_volume(m_summary, "wheel"))
            row[f"{name}_mujoco_loaded_deepest_um"] = 1e6 * mujoco[name]["deepest"]
            row[f"{name}_mujoco_volume_mm3"] = 1e9 * m_volume
            row[f"{name}_deepest_over_mujoco"] = (profiles[name]["loaded"]["deepest"]
                                                  / mujoco[name]["deepest"])
            row[f"{name}_volume_over_mujoco"] = volume[name] / m_volume
            worn = mujoco[name]["mean"] > 0.1 * mujoco[name]["deepest"]
            ratio = profiles[name]["loaded"]["mean"][worn] / mujoco[name]["mean"][worn]
            row[f"{name}_over_mujoco_median"] = float(np.median(ratio))
            row[f"{name}_over_mujoco_iqr"] = [float(x) for x in np.percentile(ratio, [25, 75])]
    mesh = mesh_forces(scene, torque)
    row.update(mesh["row"])
    plot(profiles, mujoco, mesh, row)
    rows = [
        ("revolutions", f"{row['revolutions']:.6g} (100 rad/s, cycle jumps over a revolution)"),
        ("run time", f"{row['wall_time_s']:.0f} s ({row['resolved_cycles']:.0f} resolved "
                     f"revolutions, {row['jumps']} jumps)"
                     + (f"; the MuJoCo run {row['mujoco_wall_time_s']:.0f} s"
                        if mujoco is not None else "")),
    ]
    if long_summary is not None:
        rows.append(("10^5 revolutions", f"{row['long_wall_time_s']:.0f} s "
                     f"({row['long_resolved_cycles']:.0f} resolved, {row['long_jumps']} jumps)"))
    rows += [
        ("tooth pairs in mesh (0.03 s resolved)",
         f"two for {100 * row['two_pairs_fraction']:.0f} % of the time, one for the rest"),
        ("normal force on the loaded flanks (sum over the teeth)",
         f"mean {row['mesh_force_mean_N']:.1f} N (torque / base radius "
         f"{row['flank_force_expected_N']:.1f} N), {row['mesh_force_min_N']:.1f}"
         f"–{row['mesh_force_max_N']:.1f} N"),
        ("normal forces' torque about the pinion's axis / the torque, every step",
         f"{row['balance_min']:.12f}–{row['balance_max']:.12f}"),
        ("one tooth's force where two pairs mesh / where it meshes alone",
         f"{row['shared_over_alone']:.2f} (median)"),
        ("largest force on an unloaded flank", f"{row['unloaded_force_max_N']:.3g} N"),
        ("deepest wear of the loaded flanks (mean over the flanks), pinion / wheel",
         f"{row['pinion_loaded_deepest_um']:.3f} µm / {row['wheel_loaded_deepest_um']:.3f} µm"
         + (f" (MuJoCo {row['pinion_mujoco_loaded_deepest_um']:.3f} / "
            f"{row['wheel_mujoco_loaded_deepest_um']:.3f} µm)" if mujoco is not None else "")),
        ("worn volume, pinion / wheel",
         f"{row['pinion_volume_mm3']:.3e} / {row['wheel_volume_mm3']:.3e} mm³"
         + (f" (MuJoCo {row['pinion_mujoco_volume_mm3']:.3e} / "
            f"{row['wheel_mujoco_volume_mm3']:.3e} mm³)" if mujoco is not None else "")),
    ]
    if mujoco is not None:
        for name in own:
            rows.append((f"{name}: quasi-static / MuJoCo, deepest, volume, radius by radius "
                         "(median, quartiles)",
                         "{:.3f}, {:.3f}, {:.3f} ({:.3f}–{:.3f})".format(
                             row[f"{name}_deepest_over_mujoco"],
                             row[f"{name}_volume_over_mujoco"],
                             row[f"{name}_over_mujoco_median"],
                             *row[f"{name}_over_mujoco_iqr"])))
    write_measured("gear_pair_torque_quasi_static", rows, FIGURE.name,
                   "flank wear beside the MuJoCo run's; the force per tooth")
    for quantity, value in rows:
        print(f"{quantity:60s} {value}")
    print(json.dumps({"benchmark": "gear_pair_torque_quasi_static", **row}))


def _surface_volume(summary, name):
    """A worn surface's worn volume from a run's summary (m³)."""
    surfaces = summary.get("surfaces", {})
    entry = surfaces.get(name, {})
    return float(entry.get("wear_volume", np.nan))


class ToothForces:
    """Observer: the pinion's normal force per tooth and flank, its angle,
    and the normal forces' torque about its axis, at every sample."""

    def __init__(self, vertices):
        self.tooth, self.sign = tooth_and_side(vertices)
        self.angle, self.loaded, self.unloaded, self.balance = [], [], [], []

    def on_sample(self, model, state):
        s = state.bodies[0]
        force = s.normal_force.sum(axis=0)
        q = s.pose[3:7]
        self.angle.append(2.0 * np.arctan2(q[3], q[0]))
        self.loaded.append(np.bincount(self.tooth[self.sign > 0], force[self.sign > 0],
                                       minlength=TEETH))
        self.unloaded.append(np.bincount(self.tooth[self.sign < 0], force[self.sign < 0],
                                         minlength=TEETH))
        # the normal forces' torque about z through the pinion's centre
        x = s.pose[0:3] + s.vertices @ quaternion_matrix(q).T
        normal = s.vertex_planes[0, :, 1]
        f = s.normal_force[0]
        self.balance.append(float(np.sum(f * (x[:, 0] * normal[:, 1] - x[:, 1] * normal[:, 0]))))

    def on_frame(self, model, state):
        pass


def mesh_forces(scene, torque, duration=0.03, settle=0.02):
    """The pinion's normal force per tooth over ``duration`` s, every step
    resolved and sampled; the figures from the last ``duration - settle`` s."""
    short = scene.set({"run.duration": duration, "run.frames": 0, "run.history": 601,
                       "wear.acceleration": "none"})
    model = build_model(short)
    forces = ToothForces(model.bodies[0].reference_vertices - model.bodies[0].origin)
    run(model, initial_state(model), observers=[forces])
    t = np.linspace(0.0, duration, len(forces.angle))
    keep = t >= settle
    loaded = np.asarray(forces.loaded)[keep]
    unloaded = np.asarray(forces.unloaded)[keep]
    total = loaded.sum(axis=1)
    meshing = loaded > 0.02 * total.mean()
    pairs = meshing.sum(axis=1)
    alone = loaded[(pairs == 1)[:, None] & meshing]
    shared = loaded[(pairs == 2)[:, None] & meshing]
    balance = np.asarray(forces.balance)[keep] / -torque
    return {"angle": np.asarray(forces.angle)[keep], "loaded": loaded, "total": total,
            "row": {"flank_force_expected_N": torque / (PITCH * np.cos(ALPHA)),
                    "mesh_force_mean_N": float(total.mean()),
                    "mesh_force_min_N": float(total.min()),
                    "mesh_force_max_N": float(total.max()),
                    "two_pairs_fraction": float(np.mean(pairs == 2)),
                    "shared_over_alone": float(np.median(shared) / np.median(alone)),
                    "unloaded_force_max_N": float(unloaded.sum(axis=1).max()),
                    "balance_min": float(balance.min()), "balance_max": float(balance.max())}}


def plot(profiles, mujoco, mesh, row):
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.4))
    for k, name in enumerate(("pinion", "wheel")):
        for side, style in (("loaded", "-o"), ("unloaded", ":")):
            p = profiles[name][side]
            left.plot(1e3 * p["radius"], 1e6 * p["mean"], style, ms=2.5, color=f"C{k}",
                      label=f"{name}, {side} flanks (quasi-static)")
        if mujoco is not None:
            left.plot(1e3 * mujoco[name]["radius"], 1e6 * mujoco[name]["mean"], "--",
                      color=f"C{k + 2}", label=f"{name}, loaded flanks (MuJoCo)")
    left.axvline(1e3 * PITCH, color="k", lw=0.8, ls="--")
    left.set_xlabel("radius on the flank (mm): base circle → tip")
    left.set_ylabel("wear depth, mean over the flanks (µm)")
    left.set_title(f"flank wear after {row['revolutions']:.0e} revolutions")
    left.legend(fontsize=7)
    phase = np.degrees(np.mod(mesh["angle"], 2.0 * np.pi))
    for tooth in range(TEETH):
        f = mesh["loaded"][:, tooth]
        if f.max() > 0.02 * mesh["total"].mean():
            right.plot(phase, f, lw=1.0, label=f"tooth {tooth}")
    right.plot(phase, mesh["total"], color="k", lw=1.2, label="sum")
    right.set_xlabel("pinion angle (°)")
    right.set_ylabel("normal contact force on the loaded flanks (N)")
    right.set_title("force per pinion tooth, quasi-static")
    right.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
