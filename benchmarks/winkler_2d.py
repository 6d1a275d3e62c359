"""A 2-D reference for fretting wear of a cylinder on a flat, both wearing
(docs/examples/cylinder_on_flat_fretting.md), written apart from meshwear.

The cross-section of a long cylinder (radius R) pressed by a load q per unit
length on a flat and rubbed along x by u(t) = A sin(2 pi t) (t in cycles),
on a Winkler foundation of modulus K (pressure K times the overlap of the two
surfaces, as meshwear's contact points have), both surfaces wearing by
Archard's law, dw = k p ds, in gross slip (ds = |du|; the stick at each
reversal, mu p / K_t of the stroke, about 0.3 % of it here, is neglected).
The flat's wear w_f(x) is kept on a grid fixed to the flat, the cylinder's
w_c(xi) on the same grid fixed to the cylinder; the gap at x is

    g(x) = R - sqrt(R^2 - (x - u)^2) + w_c(x - u) + w_f(x) - delta,

delta the approach that carries q: K sum (-g)_+ dx = q, solved at every step
(the overlap is piecewise linear and monotone in delta: Newton from the last
step's delta). A cycle is resolved at ``steps`` steps; its wear is then
applied ``n`` times (n grows while the wear a jump adds stays under a small
fraction ``share`` of the overlap at the middle of the contact; ``share``
halved changes the scar by less than the printed amount). Nothing here
comes from meshwear: the numbers are the scene's, read from its TOML file.

    .venv/bin/python benchmarks/winkler_2d.py [--scene examples/cylinder_on_flat_fretting.toml]
    .venv/bin/python benchmarks/winkler_2d.py --check   # halves the steps, the jumps and dx

and, given a finished 3-D run of the scene (its frames at whole cycles, when
the cylinder is back at u = 0), compares both scars at the frames' cycles
(the 3-D profiles averaged over the middle tenth of the length) and draws the
profiles at four of them (docs/img/cylinder_on_flat_fretting.png):

    meshwear run examples/cylinder_on_flat_fretting.toml -o OUT
    .venv/bin/python benchmarks/winkler_2d.py --from OUT
"""

import argparse
import json
import time
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "cylinder_on_flat_fretting.toml"
#: a scar's edge: where its depth falls to this share of its deepest
EDGE = 0.1


def parameters(path):
    """The test's numbers from the scene file: R, q (N/m), K, k of the
    cylinder and the flat, A (m), f (Hz), the duration in cycles."""
    scene = tomllib.loads(Path(path).read_text())
    body = scene["body"][0]
    shape = body["shape"]
    flat = scene["surface"][0]
    k = scene["wear"]["coefficient"]
    k_flat = flat.get("wear_coefficient", k) if flat.get("wear", False) else 0.0
    oscillation = body["path"]["oscillation"]
    q = -body["force"][2] / shape["height"]
    cycles = scene["run"]["duration"] * oscillation["frequency"]
    return dict(R=shape["radius"], q=q, K=scene["contact"]["stiffness_per_area"],
                k_body=body.get("wear_coefficient", k), k_flat=k_flat,
                A=oscillation["amplitude"], cycles=cycles, frequency=oscillation["frequency"])


def approach(gap, K, q, dx, delta):
    """The approach delta at which K sum (delta - gap)_+ dx = q (Newton on a
    piecewise-linear increasing function, from ``delta``)."""
    for _ in range(100):
        over = delta - gap
        inside = over > 0.0
        force = K * over[inside].sum() * dx
        slope = K * inside.sum() * dx
        if slope == 0.0:
            delta = gap.min() + 1e-12
            continue
        step = (q - force) / slope
        delta += step
        if abs(step) < 1e-15 * max(abs(delta), 1e-9):
            break
    return delta


def run(p, cycles=None, steps=40, dx=0.25e-6, share=0.01, samples=(), half_width=None):
    """Wear profiles of the flat (fixed x) and the cylinder (its own xi) on
    one grid; returns {cycle: (x, w_flat, w_cylinder)} at ``samples`` and at
    the end, and the number of resolved cycles."""
    cycles = p["cycles"] if cycles is None else cycles
    R, q, K, A = p["R"], p["q"], p["K"], p["A"]
    a0 = (1.5 * q * R / K) ** (1.0 / 3.0)
    # wide enough for the scar of the whole run (its edge past 7 a0 by the end)
    span = half_width or 14.0 * a0 + 2.0 * A
    x = np.arange(-span, span + 0.5 * dx, dx)
    w_f, w_c = np.zeros_like(x), np.zeros_like(x)
    t = np.arange(steps + 1) / steps
    u = A * np.sin(2.0 * np.pi * t)
    du = np.abs(np.diff(u))
    out, done, resolved, n, delta = {}, 0.0, 0, 1.0, 0.0
    pending = sorted(set(float(c) for c in samples if 0 < c < cycles))
    while done < cycles:
        cycle_f, cycle_c = np.zeros_like(x), np.zeros_like(x)
        middle = 0.0
        for j in range(steps):
            um = 0.5 * (u[j] + u[j + 1])
            xi = x - um
            # the cylinder's profile and wear where its xi is over x
            profile = R - np.sqrt(np.maximum(R * R - xi * xi, 0.0))
            gap = profile + np.interp(xi, x, w_c) + w_f
            delta = approach(gap, K, q, dx, delta)
            pressure = K * np.maximum(delta - gap, 0.0)
            middle = max(middle, (delta - gap).max())
            cycle_f += p["k_flat"] * pressure * du[j]
            # the cylinder's wear on its own grid: its point xi was over x = xi + um
            cycle_c += p["k_body"] * np.interp(x + um, x, pressure) * du[j]
        resolved += 1
        # the jump: n cycles of this one's wear, n growing while the wear
        # it adds stays under ``share`` of the overlap in the contact
        fastest = max(cycle_f.max(), cycle_c.max(), 1e-300)
        n = min(2.0 * n, max(1.0, share * middle / fastest))
        n = max(1.0, min(n, cycles - done))
        if pending and done + n > pending[0]:
            n = max(1.0, pending[0] - done)
        w_f += n * cycle_f
        w_c += n * cycle_c
        done += n
        while pending and done >= pending[0] - 1e-9:
            out[pending.pop(0)] = (x.copy(), w_f.copy(), w_c.copy())
    out[float(cycles)] = (x.copy(), w_f.copy(), w_c.copy())
    return out, resolved


def scar(x, w):
    """Depth (m) and width (m) of a scar: its deepest wear, and the distance
    between the points where its depth falls to EDGE of that (linear
    between the grid's points)."""
    deepest = float(w.max())
    if deepest <= 0.0:
        return 0.0, 0.0
    level = EDGE * deepest
    above = np.flatnonzero(w >= level)
    i, j = above[0], above[-1]
    left = x[i] if i == 0 else x[i - 1] + (level - w[i - 1]) / (w[i] - w[i - 1]) * (x[i] - x[i - 1])
    right = x[j] if j == len(x) - 1 else x[j] + (w[j] - level) / (w[j] - w[j + 1]) * (x[j + 1] - x[j])
    return deepest, float(right - left)


#: the 3-D profiles are averaged over cuts across this middle band of the
#: length (m): point contacts between a 20 um pad and a 10 um flat leave
#: grooves along the pad's vertex tracks, a vertex apart
BAND, CUTS = 1e-4, 41


def section(path, band=BAND, cuts=CUTS):
    """The wear profile (x, depth) along x of a 3-D frame's surface: its
    depth along cuts by the planes y = const across the middle ``band`` of
    the length (interpolated along each cut, then averaged over the cuts),
    the part within 0.1 mm of z = 0, where the two touch."""
    import pyvista

    mesh = pyvista.read(path)
    profiles = []
    for y in np.linspace(-0.5 * band, 0.5 * band, cuts):
        cut = mesh.slice(normal="y", origin=(0.0, y, 0.0))
        points, depth = np.asarray(cut.points), np.asarray(cut.point_data["wear_depth"])
        keep = np.abs(points[:, 2]) < 1e-4
        order = np.argsort(points[keep, 0])
        profiles.append((points[keep, 0][order], depth[keep][order]))
    lo = max(p[0][0] for p in profiles)
    hi = min(p[0][-1] for p in profiles)
    x = np.arange(lo, hi, 2e-6)              # a grid finer than both meshes
    return x, np.mean([np.interp(x, px, pd) for px, pd in profiles], axis=0)


def frames(out, name):
    """{time (s): frame path} of part ``name`` in a run's output folder."""
    import re

    text = (Path(out) / f"{name}.pvd").read_text()
    return {float(t): Path(out) / f for t, f in
            re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', text)}


def compare(p, out, figure=None):
    """Both scars of the 3-D run in ``out`` against this model at its
    frames' cycles; returns the rows (cycle, part, depth and width, 3-D and 2-D)."""
    flat_frames, cylinder_frames = frames(out, "flat"), frames(out, "cylinder")
    frequency = p.get("frequency", 1.0)
    cycles = sorted(t * frequency for t in flat_frames if t > 0)
    profiles, _ = run(p, max(cycles), samples=cycles)
    rows = []
    for c in cycles:
        x, w_f, w_c = profiles[c]
        t = c / frequency
        for name, path, w in (("flat", flat_frames[t], w_f), ("cylinder", cylinder_frames[t], w_c)):
            x3, d3 = section(path)
            rows.append((c, name, *scar(x3, d3), *scar(x, w)))
    if figure is not None:
        _draw(p, profiles, flat_frames, cylinder_frames, cycles, frequency, figure)
    return rows


def _draw(p, profiles, flat_frames, cylinder_frames, cycles, frequency, figure):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    picks = [cycles[int(round(i * (len(cycles) - 1) / 3))] for i in range(4)]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for ax, name, frames_, column in ((axes[0], "flat", flat_frames, 1),
                                      (axes[1], "cylinder", cylinder_frames, 2)):
        for i, c in enumerate(picks):
            x3, d3 = section(frames_[c / frequency])
            x = profiles[c][0]
            colour = f"C{i}"
            ax.plot(x * 1e6, -profiles[c][column] * 1e6, color=colour, lw=1.0,
                    label=f"{c:g} cycles, 2-D")
            ax.plot(x3 * 1e6, -d3 * 1e6, "--", color=colour, lw=1.2,
                    label="3-D (mean, |y| < 50 µm)")
        ax.set_title(f"{name}: wear profile")
        ax.set_xlabel("x (µm)" if name == "flat" else "x on the cylinder, at u = 0 (µm)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("worn depth (µm, down)")
    axes[1].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(figure, dpi=120)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=SCENE)
    parser.add_argument("--cycles", type=float, default=None)
    parser.add_argument("--from", dest="source", type=Path, default=None, metavar="OUT",
                        help="compare with the 3-D run in OUT and draw the profiles")
    parser.add_argument("--figure", type=Path,
                        default=ROOT / "docs" / "img" / "cylinder_on_flat_fretting.png")
    parser.add_argument("--check", action="store_true",
                        help="also run with half the steps per cycle, half the jumps' "
                        "share and half dx, and print the change")
    args = parser.parse_args(argv)
    p = parameters(args.scene)
    if args.source is not None:
        rows = compare(p, args.source, args.figure)
        print(f"{'cycles':>8} {'part':>9} {'depth 3-D':>10} {'2-D':>10} {'diff':>7} "
              f"{'width 3-D':>10} {'2-D':>10} {'diff':>7}   (um)")
        for c, name, d3, w3, d2, w2 in rows:
            print(f"{c:8g} {name:>9} {d3 * 1e6:10.4f} {d2 * 1e6:10.4f} {d3 / d2 - 1:+7.2%} "
                  f"{w3 * 1e6:10.2f} {w2 * 1e6:10.2f} {w3 / w2 - 1:+7.2%}")
        print(json.dumps({"rows": [[c, n, d3, w3, d2, w2] for c, n, d3, w3, d2, w2 in rows]}))
        return
    cycles = args.cycles or p["cycles"]
    before = time.perf_counter()
    profiles, resolved = run(p, cycles)
    wall = time.perf_counter() - before
    x, w_f, w_c = profiles[float(cycles)]
    flat, cylinder = scar(x, w_f), scar(x, w_c)
    line = {"cycles": cycles, "resolved_cycles": resolved, "seconds": round(wall, 1),
            "flat_depth": flat[0], "flat_width": flat[1],
            "cylinder_depth": cylinder[0], "cylinder_width": cylinder[1]}
    print(f"2-D Winkler reference, {cycles:g} cycles ({resolved} resolved, {wall:.1f} s):")
    print(f"  flat:     depth {flat[0] * 1e6:.4f} um, width {flat[1] * 1e6:.2f} um")
    print(f"  cylinder: depth {cylinder[0] * 1e6:.4f} um, width {cylinder[1] * 1e6:.2f} um")
    if args.check:
        fine, _ = run(p, cycles, steps=80, dx=0.125e-6, share=0.005)
        xf, ff, cf = fine[float(cycles)]
        for name, coarse, (xx, ww) in (("flat", flat, (xf, ff)), ("cylinder", cylinder, (xf, cf))):
            d, w = scar(xx, ww)
            print(f"  {name}, refined: depth {d * 1e6:.4f} um ({d / coarse[0] - 1:+.2%}), "
                  f"width {w * 1e6:.2f} um ({w / coarse[1] - 1:+.2%})")
            line[f"{name}_refined_change"] = [d / coarse[0] - 1, w / coarse[1] - 1]
    print(json.dumps(line))


if __name__ == "__main__":
    main()
