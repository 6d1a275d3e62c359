"""Run the validation cases and write docs/validation.md with its plots.

Every case is an example scene (examples/validation/, examples/pin_on_disc.toml)
compared with its closed form of docs/model.md at its tolerance; the same
functions (tests/cases.py) are asserted by tests/test_validation.py. Prints the
table, then one JSON line with every figure and the run time.

    python benchmarks/validate.py            # or: make validate
"""

import json
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
import cases  # noqa: E402

DOCS = ROOT / "docs"
IMAGES = DOCS / "img"


def tolerance(row):
    if not row.relative:
        return f"{row.tolerance:g}" if row.tolerance else "exactly 0"
    return f"{100 * row.tolerance:g} %"


def error(row):
    return f"{row.error:.1e}" + ("" if row.relative else " (abs.)")


# ---------------------------------------------------------------- plots

def plot_profile(case):
    d = case.data
    r = np.linspace(0.0, 1.2 * np.sqrt(2 * d["R"] * d["h"]), 300)
    closed = np.maximum(d["h"] - (d["R"] - np.sqrt(d["R"] ** 2 - r ** 2)), 0.0)
    fig, ax = plt.subplots(figsize=(6, 3.6))
    near = d["radius"] < r[-1]
    ax.plot(1e3 * d["radius"][near], 1e6 * d["depth"][near], ".", ms=3, label="meshwear, vertices")
    ax.plot(1e3 * r, 1e6 * closed, "k-", lw=1, label=r"flat cap of $V = kPs$")
    ax.set_xlabel("distance from the pin axis (mm)")
    ax.set_ylabel("wear depth (µm)")
    ax.set_title(f"Ball pin after 10 m, archard ({d['vertices']} vertices)")
    ax.legend()
    return save(fig, "sphere_pin_profile.png")


def plot_loop(case):
    d = case.data
    delta, F, kt = d["amplitude"], d["mu_N"], d["k_t"]
    slip = F / kt
    # the parallelogram: stick lines of slope -K_t between the plateaus +-mu N
    x = [-delta, -delta + 2 * slip, delta, delta - 2 * slip, -delta]
    f = [F, -F, -F, F, F]
    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.plot(1e6 * d["x"], d["fx"], "-", lw=1, label="meshwear, quasi-static")
    ax.plot(1e6 * np.array(x), f, "k--", lw=1, label="Jenkins parallelogram")
    ax.set_xlabel("displacement x (µm)")
    ax.set_ylabel("friction force on the block, $F_x$ (N)")
    ax.set_title("Friction loop, δ = 2 µm, μN = 15 N")
    ax.legend(loc="lower left", fontsize=8)
    return save(fig, "jenkins_loop.png")


def plot_approach(case):
    d = case.data
    fig, ax = plt.subplots(figsize=(5, 3.6))
    P = np.geomspace(d["load"].min(), d["load"].max(), 100)
    closed = d["closed"][0] * np.sqrt(P / d["load"][0])
    ax.loglog(P, 1e6 * closed, "k-", lw=1, label=r"$\delta=\sqrt{P/(\pi K R)}$")
    ax.loglog(d["load"], 1e6 * d["approach"], "o", label="meshwear")
    ax.set_xlabel("load P (N)")
    ax.set_ylabel("approach δ (µm)")
    ax.set_title("Winkler sphere, R = 5 mm, K = 1e12 N/m³")
    ax.legend()
    return save(fig, "winkler_approach.png")


def plot_decay(case):
    d = case.data
    fig, ax = plt.subplots(figsize=(5, 3.6))
    s = d["distance"]
    keep = s > 0
    ax.semilogy(1e3 * s[keep], d["spread"][keep], ".", label="meshwear")
    ax.semilogy(1e3 * s[keep], d["spread"][keep][0] * np.exp(-d["rate"] * (s[keep] - s[keep][0])),
                "k-", lw=1, label=r"$\propto e^{-kKs}$")
    ax.set_xlabel("sliding distance s (mm)")
    ax.set_ylabel(r"$p_{max} - p_{min}$ (Pa)")
    ax.set_title("Tilted flat punch, archard")
    ax.legend()
    return save(fig, "punch_decay.png")


def plot_mesh(case):
    d = case.data
    n = np.array(d["vertices"])
    area, point = np.array(d["per_area"]), np.array(d["per_point"])
    fig, axes = plt.subplots(1, 2, figsize=(8, 3.4))
    for ax, j, label in ((axes[0], 0, "worn volume (mm³)"), (axes[1], 1, "max wear depth (µm)")):
        scale = 1e9 if j == 0 else 1e6
        ax.semilogx(n, scale * area[:, j], "o-", label="per area (Winkler) + archard")
        ax.semilogx(n, scale * point[:, j], "s--", label="per point + energy (published)")
        ax.set_xticks(n, [f"{v:,}" for v in n])
        ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        ax.set_xlabel("vertices of the ball mesh")
        ax.set_ylabel(label)
        ax.set_ylim(bottom=0)
    axes[0].legend(fontsize=8)
    fig.suptitle("Ball pin slid 2 m: the same scene on three meshes")
    return save(fig, "mesh_dependence.png")


def plot_pin_on_disc(case):
    d = case.data
    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.plot(d["time"], 1e12 * d["volume"], "-", label="meshwear")
    ax.plot(d["time"], 1e12 * d["closed"], "k--", lw=1, label=r"$kPs$")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("worn volume (10⁻¹² m³)")
    ax.set_title("Pin on disc, archard")
    ax.legend()
    return save(fig, "pin_on_disc_volume.png")


def plot_hertz(case):
    d = case.data
    r = np.linspace(0.0, d["a"], 200)
    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.plot(1e6 * d["r_cells"], 1e-9 * d["p_cells"], ".", ms=2, color="0.6", label="grid cells")
    ax.plot(1e6 * d["r_vertices"], 1e-9 * d["p_vertices"], ".", ms=3,
            label="vertices (the pressure at their points)")
    ax.plot(1e6 * r, 1e-9 * d["p0"] * np.sqrt(1.0 - (r / d["a"]) ** 2), "k-", lw=1,
            label="Hertz")
    ax.set_xlabel("distance from the axis (µm)")
    ax.set_ylabel("pressure (GPa)")
    ax.set_title("Ball on flat, half-space: R = 5 mm, P = 10 N")
    ax.legend(fontsize=8)
    return save(fig, "hertz_ball.png")


def plot_mindlin(case):
    d = case.data
    mu_p, gross, stroke, x = d["mu_P"], d["gross"], d["stroke"], d["x"]
    top = x * mu_p
    q = np.linspace(-top, top, 200)
    # the two branches of Mindlin and Deresiewicz's loop
    down = stroke - 2.0 * gross * (1.0 - (1.0 - (top - q) / (2.0 * mu_p)) ** (2.0 / 3.0))
    up = -stroke + 2.0 * gross * (1.0 - (1.0 - (q + top) / (2.0 * mu_p)) ** (2.0 / 3.0))
    first = np.linspace(0.0, top, 100)
    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.plot(1e6 * d["shift"], d["force"], "o-", ms=3, lw=0.8, label="meshwear, 8 steps a cycle")
    ax.plot(1e6 * down, q, "k-", lw=1, label="Mindlin-Deresiewicz")
    ax.plot(1e6 * up, q, "k-", lw=1)
    ax.plot(1e6 * gross * (1.0 - (1.0 - first / mu_p) ** (2.0 / 3.0)), first, "k:", lw=1,
            label="Cattaneo-Mindlin, first loading")
    ax.set_xlabel("stroke (µm)")
    ax.set_ylabel("tangential force Q (N)")
    ax.set_title("Ball on flat in partial slip, half-space")
    ax.legend(fontsize=8)
    return save(fig, "mindlin_loop.png")


PLOTS = {"hertz_ball": plot_hertz, "mindlin_fretting": plot_mindlin,
         "sphere_pin": plot_profile, "jenkins_quasi_static": plot_loop,
         "winkler_sphere": plot_approach, "tilted_punch": plot_decay,
         "mesh_independence": plot_mesh, "pin_on_disc": plot_pin_on_disc}


def save(fig, name):
    IMAGES.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(IMAGES / name, dpi=110)
    plt.close(fig)
    return f"img/{name}"


# ---------------------------------------------------------------- report

def main():
    start = time.perf_counter()
    results, timings = [], {}
    for run in cases.ALL:
        t0 = time.perf_counter()
        results.append(run())
        timings[run.__name__] = time.perf_counter() - t0
    elapsed = time.perf_counter() - start
    images = {c.name: PLOTS[c.name](c) for c in results if c.name in PLOTS}

    header = f"{'case':34} {'quantity':56} {'closed form':>12} {'meshwear':>12} {'error':>9} {'tol':>8}"
    print(header)
    for c in results:
        for r in c.rows:
            print(f"{r.case[:34]:34} {r.quantity[:56]:56} {r.closed_form:12.6g} {r.measured:12.6g} "
                  f"{r.error:9.2e} {r.tolerance:8.0e} {'ok' if r.ok else 'FAIL'}")
    print(f"validation run time {elapsed:.1f} s")
    write_markdown(results, images, timings, elapsed)
    print(json.dumps({
        "benchmark": "validate",
        "seconds": elapsed,
        "all_ok": bool(all(r.ok for c in results for r in c.rows)),
        "rows": [dict(case=r.case, quantity=r.quantity, closed_form=r.closed_form,
                      measured=float(r.measured), error=float(r.error), tolerance=r.tolerance,
                      ok=bool(r.ok))
                 for c in results for r in c.rows],
        "case_seconds": timings,
    }))


def write_markdown(results, images, timings, elapsed):
    lines = [
        "# Validation",
        "",
        "<!-- generated by benchmarks/validate.py: edit that script, not this page -->",
        "",
        "Each case is an example scene run by meshwear and compared with its closed form",
        "(docs/model.md) at the tolerance in its row (the half-space solver's own closed",
        "forms on its grid, without a scene, are the rows of \"half-space grid\").",
        "`tests/test_validation.py` asserts",
        "the same rows in `make test`; this page and its plots are written by",
        "",
        "```sh",
        ".venv/bin/python benchmarks/validate.py     # or: make validate",
        "```",
        "",
        f"which took {elapsed:.0f} s on the 2-core development machine.",
        "The physics tests of the dynamic mode (Jenkins loop with inertia, stopping",
        "distance, slopes, tossed cube, corner, stability) are listed in",
        "[physics tests](physics-tests.md).",
        "",
        "| case | quantity | closed form | meshwear | error | tolerance | scene |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in results:
        scene = c.scene.relative_to(ROOT).as_posix()
        for r in c.rows:
            unit = f" {r.unit}" if r.unit else ""
            lines.append(f"| {r.case} | {r.quantity} | {r.closed_form:.6g}{unit} | "
                         f"{r.measured:.6g}{unit} | {error(r)} | {tolerance(r)} | "
                         f"[`{Path(scene).name}`](../{scene}) |")
    lines += ["", "All rows " + ("pass." if all(r.ok for c in results for r in c.rows)
                                 else "**do not pass**: see the table."), ""]
    lines += sections(results, images)
    (DOCS / "validation.md").write_text("\n".join(lines) + "\n", encoding="utf-8")


def sections(results, images):
    by = {c.name: c for c in results}
    mesh = by["mesh_independence"].data
    area, point = np.array(mesh["per_area"]), np.array(mesh["per_point"])
    w = by["winkler_sphere"].data
    out = [
        "## Winkler sphere: approach against load",
        "",
        f"A ball of radius 5 mm ({w['touching']} vertices in contact at 10 N) pressed on a",
        "Winkler foundation, quasi-static. Over two decades of load the approach follows",
        r"$\sqrt{P/(\pi K R)}$; the deviation is the discretisation of the contact",
        "disc by the vertices and is largest at the lowest load, where fewest touch.",
        "",
        f"![approach against load]({images['winkler_sphere']})",
        "",
        "## Ball pin: worn profile",
        "",
        "After 10 m of sliding the ball has worn a flat cap. Every vertex's wear depth",
        "against its distance from the pin axis lies on the profile of a flat cap whose",
        r"volume is $kPs$: $w(r) = h - (R - \sqrt{R^2 - r^2})$.",
        "",
        f"![worn profile]({images['sphere_pin']})",
        "",
        "## Tilted punch: pressure differences decay",
        "",
        "A flat punch tilted by 0.5 µrad carries more pressure on one side; Archard",
        "wear removes most there. The spread of the pressure across the face decays",
        r"exponentially at the rate $kK$ (fitted over the whole run; the explicit",
        r"wear update per step, $kK\,\mathrm ds = 0.01$, accounts for the 0.5 % bias).",
        "",
        f"![decay]({images['tilted_punch']})",
        "",
        "## Jenkins loop without inertia",
        "",
        "The quasi-static reciprocating block traces the Jenkins parallelogram exactly:",
        r"stick lines of slope $-K_t$ and slip plateaus at $\pm\mu N$. Below the slip",
        r"amplitude $\mu N/K_t$ the loop closes to a line: nothing slips, nothing wears.",
        "",
        f"![friction loop]({images['jenkins_quasi_static']})",
        "",
        "## Pin on disc",
        "",
        f"![pin on disc]({images['pin_on_disc']})",
        "",
        "## Per area or per point: mesh dependence",
        "",
        "The ball pin of above, slid 2 m, on the icosphere at three refinement levels",
        f"({', '.join(str(n) for n in mesh['vertices'])} vertices), with the two",
        "formulations:",
        "",
        "- **per area** (Winkler: `stiffness_per_area`, `archard` or `energy_density`): worn",
        f"  volume {area[0, 0]:.4g}, {area[1, 0]:.4g}, {area[2, 0]:.4g} m³ and max depth",
        f"  {1e6 * area[0, 1]:.2f}, {1e6 * area[1, 1]:.2f}, {1e6 * area[2, 1]:.2f} µm: the same",
        "  on every mesh, within "
        f"{100 * max(abs(area[2, 0] / area[1, 0] - 1), abs(area[2, 1] / area[1, 1] - 1)):.2f} %"
        " from the middle to the finest;",
        "- **per point** (the published formulation: `stiffness` in N/m per vertex and the",
        "  `energy` law, coefficients matched to the per-area run on the middle mesh):",
        f"  volume {point[0, 0]:.4g}, {point[1, 0]:.4g}, {point[2, 0]:.4g} m³ and max depth",
        f"  {1e6 * point[0, 1]:.2f}, {1e6 * point[1, 1]:.2f}, {1e6 * point[2, 1]:.2f} µm. Each",
        "  refinement multiplies the number of contact points by four, so the contact gets",
        "  four times stiffer and each point's energy, hence its wear, four times smaller.",
        "",
        f"![mesh dependence]({images['mesh_independence']})",
        "",
        "**When to use which.** Use *per area* for any wear prediction: the results",
        "converge as the mesh is refined, and the pressure is a real pressure. Use *per",
        "point* only to reproduce the published model or a calibration made with it on",
        "the same mesh: its coefficients belong to one mesh.",
        "",
        "## Elastic half-space: Hertz",
        "",
        "The ball with `[contact] model = \"half-space\"` (E = 210 GPa, ν = 0.3 for both",
        "parts): its vertices' gaps on the grid, the pressure solved, the pressure read",
        "back at each vertex's point and its force that pressure times its contact area",
        "([the model](model.md#in-a-run)). The grid's pressure is Hertz's ellipse, and so",
        "is the vertex field `pressure` a frame writes; the vertices carry the load",
        "exactly.",
        "",
        f"![Hertz pressure]({images['hertz_ball']})",
        "",
        "The same at rest on a refined mesh whose vertices' areas vary twofold (issue 41's",
        "steel ball, R 6.35 mm, on aluminium, 20 N, 8 µm triangles within 12 µm of the",
        "flat), with the vertex field as it was before it was read at the vertex's point",
        "(each vertex's share of the cells over its area: 59 % within 10 % of Hertz's",
        "inside 0.8 a, where now all are), written by",
        "`benchmarks/hertz_vertex_pressure.py`:",
        "",
        "![vertex pressure against Hertz](img/hertz_vertex_pressure.png)",
        "",
        "## Elastic half-space: Cattaneo-Mindlin and Mindlin-Deresiewicz",
        "",
        "The same ball rubbed below gross slip, 8 steps a cycle: the tangential force",
        "against the stroke follows Mindlin's first loading and Mindlin and",
        "Deresiewicz's loop (each step solved at its stroke: the loop does not depend",
        "on the step, only on the turning points being steps).",
        "",
        f"![fretting loop]({images['mindlin_fretting']})",
    ]
    return out


if __name__ == "__main__":
    main()
