"""Cycle jumping: what accuracy each speed buys.

For sphere-on-flat fretting (a 20 mm ball, 50 N, ±100 µm, Archard, 10⁴ cycles)
and pin-on-disc (10⁴ turns), runs the fully resolved reference and cycle
jumping, implicit and explicit, at tolerances 1e-1 to 1e-4, and compares wear
depth, profile and volume with the reference. Then runs the 10⁵- and
10⁶-cycle fretting scenes (their default 1001 history rows and 51 frames
recorded in memory) against their closed forms (V = k P s, cap depth).
Prints a table, saves a Pareto plot (docs/img/speed_vs_error.png), rewrites
its section of docs/performance.md, and ends with one JSON line.

    python benchmarks/speed_vs_error.py            # about 3 minutes here
"""

import dataclasses
import json
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
import cases  # noqa: E402  (cap_depth)

from common import replace_section  # noqa: E402
from meshwear.scene.reader import load_scene  # noqa: E402
from meshwear.model.build import build_model, initial_state  # noqa: E402
from meshwear.step.simulate import run  # noqa: E402
from meshwear.longrun.jump_errors import error_estimate  # noqa: E402

TOLERANCES = (1e-1, 1e-2, 1e-3, 1e-4)
FRETTING = ROOT / "examples" / "long" / "sphere_fretting_1e5.toml"
MILLION = ROOT / "examples" / "long" / "sphere_fretting_1e6.toml"
METHODS = ("implicit", "explicit")
PIN = ROOT / "examples" / "pin_on_disc.toml"
FLOOR = 1e-7   # errors below this are drawn at it
MARK_START, MARK_END = "<!-- speed_vs_error:start -->", "<!-- speed_vs_error:end -->"


def fretting(cycles):
    scene = load_scene(FRETTING)
    return dataclasses.replace(scene, run=dataclasses.replace(
        scene.run, duration=float(cycles), frames=0, history=11))


def pin_on_disc(cycles):
    scene = load_scene(PIN)
    return dataclasses.replace(
        scene,
        run=dataclasses.replace(scene.run, duration=float(cycles), dt=0.025, frames=0, history=11),
        wear=dataclasses.replace(scene.wear, coefficient=1e-14, acceleration="cycle_jump"))


class Outputs:
    """Observer that only counts the history rows and frames it is given
    (the cost of filling them is in the timing, not of writing files)."""

    def __init__(self):
        self.rows = self.frames = 0

    def on_sample(self, model, state):
        self.rows += 1

    def on_frame(self, model, state):
        self.frames += 1


def timed(scene):
    """Build the model, then time the run alone (both sides of a comparison
    build the same meshes)."""
    model = build_model(scene)
    state = initial_state(model)
    start = time.perf_counter()
    run(model, state, observers=[Outputs()])
    return model, state, time.perf_counter() - start


def compare(name, scene, rows):
    resolved = dataclasses.replace(scene, wear=dataclasses.replace(scene.wear, acceleration="none"))
    model, ref, ref_wall = timed(resolved)
    cycles = model.duration / model.period
    w_ref = ref.bodies[0].wear_depth
    v_ref = ref.bodies[0].wear_volume.sum()
    rows.append(dict(case=name, method="resolved", tolerance=None, wall=ref_wall,
                     resolved=cycles, cycles=cycles, speedup=1.0, depth_error=0.0,
                     profile_error=0.0, volume_error=0.0, estimate=0.0))
    for method in METHODS:
        for tol in TOLERANCES:
            jumped = dataclasses.replace(scene, wear=dataclasses.replace(
                scene.wear, acceleration="cycle_jump", tolerance=tol, jump=method))
            m, state, wall = timed(jumped)
            w = state.bodies[0].wear_depth
            rows.append(dict(
                case=name, method=method, tolerance=tol, wall=wall, cycles=cycles,
                resolved=state.jump.resolved_steps / m.cycle_steps, speedup=ref_wall / wall,
                depth_error=abs(w.max() / w_ref.max() - 1),
                profile_error=float(np.linalg.norm(w - w_ref) / np.linalg.norm(w_ref)),
                volume_error=abs(state.bodies[0].wear_volume.sum() / v_ref - 1),
                estimate=error_estimate(state)))


def closed_forms(path=FRETTING):
    scene = load_scene(path)
    model, state, wall = timed(scene)
    body = scene.bodies[0]
    stroke = 4 * body.path.oscillation.amplitude * model.duration * body.path.oscillation.frequency
    load = -body.force[2]
    volume = scene.wear.coefficient * load * stroke
    h = cases.cap_depth(volume, body.shape.radius)
    s = state.bodies[0]
    return dict(cycles=model.duration / model.period, history=len(model.sample_steps),
                frames=len(model.frame_steps),
                resolved=state.jump.resolved_steps / model.cycle_steps, wall=wall,
                volume=float(s.wear_volume.sum()), volume_closed=volume,
                volume_error=float(s.wear_volume.sum() / volume - 1),
                depth=float(s.wear_depth.max()), depth_closed=h,
                depth_error=float(s.wear_depth.max() / h - 1))


def plot(rows):
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for name, marker in (("sphere-on-flat fretting", "o"), ("pin on disc", "s")):
        ref = next(r for r in rows if r["case"] == name and r["tolerance"] is None)
        drawn = None
        for method, style in (("implicit", "-"), ("explicit", "--")):
            mine = [r for r in rows if r["case"] == name and r["method"] == method]
            errors = [max(r["depth_error"], FLOOR) for r in mine]
            line, = ax.loglog([r["wall"] for r in mine], errors, marker + style,
                              color=drawn.get_color() if drawn else None,
                              mfc="none" if method == "explicit" else None,
                              label=f"{name}, {method}")
            drawn = drawn or line
            if method == "implicit" and max(r["depth_error"] for r in mine) >= FLOOR:
                for r, e in zip(mine, errors):
                    ax.annotate(f"tol {r['tolerance']:g}", (r["wall"], e), fontsize=7,
                                xytext=(4, 2), textcoords="offset points")
        ax.axvline(ref["wall"], color=drawn.get_color(), ls=":", lw=1)
    ax.annotate(f"errors below {FLOOR:g} drawn at it\n(pin on disc: uniform wear)",
                (0.02, 0.04), xycoords="axes fraction", fontsize=7)
    ax.set_xlabel("run time (s); dotted: every cycle resolved")
    ax.set_ylabel("max wear depth error against the resolved run")
    ax.set_title("Cycle jumping, 10⁴ cycles: speed against error")
    ax.legend(fontsize=7)
    fig.tight_layout()
    (ROOT / "docs" / "img").mkdir(exist_ok=True)
    fig.savefig(ROOT / "docs" / "img" / "speed_vs_error.png", dpi=110)
    plt.close(fig)


def _long_line(label, path, target):
    rel = path.relative_to(ROOT).as_posix()
    return (f"**{label}** of the same fretting ([`{rel}`](../{rel})), tolerance 1e-2, "
            f"{target['history']} history rows and {target['frames']} frames: "
            f"{target['resolved']:.0f} of {target['cycles']:.0f} cycles resolved "
            f"({target['cycles'] / target['resolved']:.0f}× fewer), {target['wall']:.1f} s. "
            f"Worn volume {target['volume']:.4e} m³ against $kPs$ = "
            f"{target['volume_closed']:.4e} m³ ({target['volume_error']:+.1e}); deepest wear "
            f"{1e6 * target['depth']:.2f} µm against the flat cap of that volume, "
            f"{1e6 * target['depth_closed']:.2f} µm ({target['depth_error']:+.1e}).")


def markdown(rows, targets):
    lines = [MARK_START, "", "## Long durations: speed against error", "",
             "<!-- written by benchmarks/speed_vs_error.py -->", "",
             "```sh", ".venv/bin/python benchmarks/speed_vs_error.py", "```", "",
             "Cycle jumping (`wear.acceleration = \"cycle_jump\"`, see [the model]"
             "(model.md#long-durations-cycle-jumping)), with implicit jumps (the default) and",
             "explicit ones, against the fully resolved run of the same scene, 10⁴ cycles,",
             "quasi-static. Errors are of the final wear, relative to the resolved run: the",
             "deepest point, the whole profile (L2 over the vertices) and the volume;",
             "*estimate* is the controller's own error estimate. Times are of the run alone",
             "(building the model, the same for all, is left out).", "",
             "| case | jumps | tolerance | wall time | resolved cycles | speed-up | max depth error "
             "| profile error | volume error | estimate |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        tol = "—" if r["tolerance"] is None else f"{r['tolerance']:g}"
        lines.append(f"| {r['case']} | {r['method']} | {tol} | {r['wall']:.1f} s | "
                     f"{r['resolved']:.0f} of {r['cycles']:.0f} | {r['speedup']:.0f}× | "
                     f"{r['depth_error']:.1e} | {r['profile_error']:.1e} | "
                     f"{r['volume_error']:.1e} | {r['estimate']:.1e} |")
    lines += ["", "![speed against error](img/speed_vs_error.png)", "",
              _long_line("10⁵ cycles", FRETTING, targets["1e5"]), "",
              _long_line("10⁶ cycles", MILLION, targets["1e6"]), "", MARK_END]
    return "\n".join(lines)


def main():
    start = time.perf_counter()
    rows = []
    compare("sphere-on-flat fretting", fretting(10_000), rows)
    compare("pin on disc", pin_on_disc(10_000), rows)
    targets = {"1e5": closed_forms(FRETTING), "1e6": closed_forms(MILLION)}
    print(f"{'case':24} {'jumps':>9} {'tol':>7} {'wall s':>8} {'resolved':>9} {'speed-up':>9} "
          f"{'depth err':>10} {'profile err':>11} {'volume err':>10} {'estimate':>9}")
    for r in rows:
        tol = "-" if r["tolerance"] is None else f"{r['tolerance']:g}"
        print(f"{r['case']:24} {r['method']:>9} {tol:>7} {r['wall']:8.2f} {r['resolved']:9.0f} "
              f"{r['speedup']:8.0f}x {r['depth_error']:10.2e} {r['profile_error']:11.2e} "
              f"{r['volume_error']:10.2e} {r['estimate']:9.2e}")
    for label, target in targets.items():
        print(f"{label}-cycle fretting ({target['history']} history rows, {target['frames']} "
              f"frames): {target['resolved']:.0f} of {target['cycles']:.0f} cycles resolved, "
              f"{target['wall']:.1f} s; volume {target['volume_error']:+.2e} against k P s, max "
              f"depth {target['depth_error']:+.2e} against the cap")
    plot(rows)
    replace_section(ROOT / "docs" / "performance.md", MARK_START, MARK_END, markdown(rows, targets))
    print(json.dumps({"benchmark": "speed_vs_error", "seconds": time.perf_counter() - start,
                      "rows": rows, "targets": targets}))


if __name__ == "__main__":
    main()
