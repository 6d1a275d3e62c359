"""A slider-crank with a worn crank-rod joint (examples/mechanisms/slider_crank.toml).

Runs the example as a user would (10^5 crank revolutions with cycle jumps,
its outputs written), or reads a finished run of it (``--from OUT``). Then
takes the worn pin and bushing of its last frame (in their own frames, as
``meshwear export`` writes them) and runs two crank revolutions of the same
mechanism with the new parts and with the worn ones, every step resolved, to
compare the joint force over the second revolution: how the grown clearance
changes its peaks. Writes docs/img/slider_crank.png (the worn bushing's depth
round its bore, the joint force against the crank angle) and the measured
section of docs/examples/slider_crank.md, and prints one JSON line.

    .venv/bin/python benchmarks/slider_crank.py            # about a minute
    .venv/bin/python benchmarks/slider_crank.py --from OUT
"""

import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import trimesh  # noqa: E402

from common import write_measured  # noqa: E402
from meshwear import cli  # noqa: E402
from meshwear.model.build import build_model, initial_state  # noqa: E402
from meshwear.output.export import part_mesh, read_frame, series_frames  # noqa: E402
from meshwear.output.memory import MemoryHistory  # noqa: E402
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "mechanisms" / "slider_crank.toml"
FIGURE = ROOT / "docs" / "img" / "slider_crank.png"
#: the bushing's bore radius and the pin's radius (m)
BORE, PIN = 0.00505, 0.005


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--from", dest="source", type=Path, default=None, metavar="OUT",
                        help="read a finished run of the example from its output folder")
    args = parser.parse_args(argv)
    scene = load_scene(SCENE)
    revolutions = scene.run.duration / scene.wear.period
    with tempfile.TemporaryDirectory() as folder:
        out = args.source or Path(folder) / "run"
        if args.source is None:
            start = time.perf_counter()
            if cli.main(["run", str(SCENE), "-o", str(out), "-q"]) != 0:
                raise SystemExit("the example's run failed")
            wall = time.perf_counter() - start
        summary = json.loads((out / "summary.json").read_text())
        if args.source is not None:
            wall = summary["wall_time"]
        bushing = read_frame(series_frames(out, "bushing")[-1][1])
        angle, depth = bore_profile(bushing)
        new = one_turn(SCENE.read_text(), None)
        worn = one_turn(SCENE.read_text(), worn_parts(out, Path(folder)))
    row = {
        "revolutions": revolutions, "wall_time_s": wall,
        "resolved_cycles": summary.get("resolved_cycles"), "jumps": summary.get("jumps"),
        "error_estimate": summary.get("error_estimate"),
        "pin_depth_um": 1e6 * summary["bodies"]["pin"]["max_wear_depth"],
        "bushing_depth_um": 1e6 * summary["surfaces"]["bushing"]["max_wear_depth"],
        "peak_force_new_N": float(new[1].max()), "peak_force_worn_N": float(worn[1].max()),
        "mean_force_new_N": float(new[1].mean()), "mean_force_worn_N": float(worn[1].mean()),
        "impacts_new_N": impacts(new), "impacts_worn_N": impacts(worn),
    }
    plot(angle, depth, new, worn, row)
    rows = [
        ("crank revolutions", f"{revolutions:.6g} (20 rev/s, cycle jumps over a turn)"),
        ("run time", f"{wall:.1f} s ({row['resolved_cycles']:.0f} resolved revolutions, "
                     f"{row['jumps']} jumps, error estimate {row['error_estimate']:.3g})"),
        ("deepest wear", f"pin {row['pin_depth_um']:.2f} µm, bushing "
                         f"{row['bushing_depth_um']:.2f} µm (radial clearance 50 µm new)"),
        ("joint force over a revolution, new", f"mean {row['mean_force_new_N']:.1f} N, "
                                               f"peak {row['peak_force_new_N']:.1f} N"),
        ("joint force over a revolution, worn", f"mean {row['mean_force_worn_N']:.1f} N, "
                                                f"peak {row['peak_force_worn_N']:.1f} N"),
        ("impacts as the load turns round (crank 140-175°, 325-355°)",
         "new {:.1f} N and {:.1f} N, worn {:.1f} N and {:.1f} N".format(
             *row["impacts_new_N"], *row["impacts_worn_N"])),
    ]
    write_measured("slider_crank", rows, FIGURE.name,
                   "worn bushing round its bore; joint force over a revolution, new and worn")
    for quantity, value in rows:
        print(f"{quantity:40s} {value}")
    print(json.dumps(row))


def bore_profile(mesh):
    """Deepest wear (m) of the bushing's bore round its circumference, in
    degree bins of the angle about its axis (its own frame: the rod's)."""
    origin = np.asarray(mesh.field_data["origin"], float)
    q = np.asarray(mesh.field_data["orientation"], float)
    w, x, y, z = q / np.linalg.norm(q)
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    local = (np.asarray(mesh.points, float) - origin) @ R
    depth = np.asarray(mesh.point_data["wear_depth"], float)
    radius = np.hypot(local[:, 0], local[:, 1])
    bore = radius < 0.5 * (BORE + 0.008)
    angle = np.degrees(np.arctan2(local[bore, 1], local[bore, 0]))
    bins = np.floor(angle).astype(int) + 180
    deepest = np.zeros(360)
    np.maximum.at(deepest, bins % 360, depth[bore])
    return np.arange(360) - 179.5, deepest


def worn_parts(out, folder):
    """The last frame's worn pin and bushing as STL files (metres, own frames)."""
    paths = {}
    for name in ("pin", "bushing"):
        vertices, faces, _ = part_mesh(out, name, -1)
        paths[name] = folder / f"{name}.stl"
        trimesh.Trimesh(vertices, faces, process=False).export(paths[name])
    return paths


def one_turn(text, parts):
    """Crank angle (rad) and joint force (N) over the second of two resolved
    revolutions of the example, with the new parts or the worn ones."""
    text = text.replace('model = "slider_crank.xml"',
                        f'model = "{(SCENE.parent / "slider_crank.xml").as_posix()}"')
    text = text.replace('acceleration = "cycle_jump"', 'acceleration = "none"')
    if parts is None:
        text = text.replace('mesh = "../../meshes/', f'mesh = "{(ROOT / "meshes").as_posix()}/')
    else:
        text = text.replace('shape = { type = "cylinder", radius = 0.005, height = 0.0028, '
                            'sections = 128 }', f'mesh = "{parts["pin"].as_posix()}"')
        text = text.replace('mesh = "../../meshes/bushing_d10.1_mm.stl"\nunits = "mm"',
                            f'mesh = "{parts["bushing"].as_posix()}"')
    with tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False) as f:
        f.write(text)
    scene = load_scene(f.name, [("run.duration", 0.1), ("run.frames", 0),
                                ("run.history", 801)])
    Path(f.name).unlink()
    model = build_model(scene)
    history = MemoryHistory()
    start = time.perf_counter()
    run(model, initial_state(model), observers=[history])
    print(f"  two resolved revolutions in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    pin = history.rows["pin"]
    second = pin["time"] >= 0.05
    angle = np.mod(pin["crank.q"][second], 2.0 * math.pi)
    force = np.linalg.norm(pin["wrench"][second, 0:2], axis=1)
    order = np.argsort(angle)
    return angle[order], force[order]


def impacts(turn):
    """The largest force (N) where the load turns round and the pin crosses
    the clearance: crank at 140-175° and at 325-355°."""
    angle = np.degrees(turn[0])
    return [float(turn[1][(angle >= a) & (angle <= b)].max()) for a, b in ((140, 175),
                                                                          (325, 355))]


def plot(angle, depth, new, worn, row):
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    left.plot(angle, 1e6 * depth, color="C3")
    left.set_xlabel("angle round the bore in the rod's frame (°; 0 = towards the slider)")
    left.set_ylabel("deepest wear (µm)")
    left.set_title(f"bushing after {row['revolutions']:.0e} revolutions")
    left.set_xlim(-180, 180)
    right.plot(np.degrees(new[0]), new[1], label="new (50 µm clearance)", color="C0")
    right.plot(np.degrees(worn[0]), worn[1], label=f"worn ({row['revolutions']:.0e} rev)",
               color="C3")
    right.set_xlabel("crank angle (°)")
    right.set_ylabel("pin-bushing contact force (N)")
    right.set_title("joint force over a revolution")
    right.legend()
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=110)


if __name__ == "__main__":
    main()
