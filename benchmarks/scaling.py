"""Per-step cost against mesh size, contact-patch size and counter-surface kind.

    .venv/bin/python benchmarks/scaling.py [--seconds 1.0] [--quick]

The body is a prescribed part made of two sheets: a square contact patch of
P vertices pressed 1 µm into the counter-surface, and a far sheet 10 mm above
it that brings the mesh to N vertices (the bulk of a CAD part that never
touches). It frets ±2 µm at 20 Hz (dynamic mode), or slides at 0.1 m/s.
Only the patch is in the active set, so the per-step cost should follow P,
not N (DESIGN.md §6); against a mesh counter-surface each active vertex also
looks up the face under it.

Prints a table (time per step, vertex-steps per second over the active
vertices, ratio to the reference measured in the same run: the 10⁴-vertex
body on a plane), rewrites its section of docs/performance.md (not with
--quick) and prints, last, one JSON line. Issue targets: 10⁶ vertices with a
1 % patch ≤ 3× the 10⁴-vertex body with the same patch; a mesh
counter-surface ≤ 5× the plane at the same active set.
"""

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import trimesh

from meshwear.model import build_model, initial_state
from meshwear.scene import load_scene
from meshwear.simulate import step

ROOT = Path(__file__).resolve().parents[1]
MARK_START, MARK_END = "<!-- scaling:start -->", "<!-- scaling:end -->"
PATCH_SIDE = 0.01          # m, the contact patch is PATCH_SIDE square
HEIGHT = 0.01              # m, the far sheet's height above the patch

SCENE = """format = 1
[run]
duration = 1.0
dt = 1e-5
frames = 0
history = 2

[contact]
stiffness_per_area = 1e12
damping_per_area = 1e6
friction = 0.3

[wear]
law = "archard"
coefficient = 1e-15

[[body]]
name = "part"
mesh = "{mesh}"
motion = "prescribed"
position = [0.0, 0.0, -1e-6]
[body.path]
{path}

[[surface]]
name = "floor"
{floor}
"""
FRETTING = "oscillation = { axis = [1.0, 0.0, 0.0], amplitude = 2e-6, frequency = 20.0 }"
SLIDING = "velocity = [0.1, 0.0, 0.0]"
PLANE = 'type = "plane"'
BOX = ('type = "mesh"\nshape = { type = "box", size = [0.2, 0.2, 0.01] }\n'
       'position = [0.0, 0.0, -0.005]')


def sheet(side, count, z, down):
    """A square grid sheet of about ``count`` vertices at height ``z``; its
    faces point down (-z) when ``down``."""
    k = max(2, int(round(np.sqrt(count))))
    u = np.linspace(-side / 2, side / 2, k)
    x, y = np.meshgrid(u, u, indexing="ij")
    vertices = np.column_stack([x.ravel(), y.ravel(), np.full(k * k, z)])
    i, j = np.meshgrid(np.arange(k - 1), np.arange(k - 1), indexing="ij")
    a = (i * k + j).ravel()
    faces = np.concatenate([np.column_stack([a, a + k, a + k + 1]),
                            np.column_stack([a, a + k + 1, a + 1])])
    if down:
        faces = faces[:, ::-1]
    return vertices, faces


def part(patch, total):
    """The two-sheet body: ``patch`` vertices facing down at z = 0, the rest
    facing up at HEIGHT (as large as the patch sheet times sqrt of the ratio,
    so its spacing stays CAD-like)."""
    v1, f1 = sheet(PATCH_SIDE, patch, 0.0, down=True)
    rest = max(4, total - len(v1))   # a 4-vertex lid at least: the part has a height
    side = PATCH_SIDE * np.sqrt(max(rest / len(v1), 1.0))
    v2, f2 = sheet(side, rest, HEIGHT, down=False)
    return np.concatenate([v1, v2]), np.concatenate([f1, f2 + len(v1)])


def grid_floor(count):
    """An open counter mesh: a 0.2 m square sheet of about ``count`` faces, facing up."""
    return sheet(0.2, count / 2, 0.0, down=False)


def measure(folder, patch, total, floor, path, seconds):
    """Seconds per step, active vertices and vertices of one configuration."""
    vertices, faces = part(patch, total)
    mesh = folder / f"part_{patch}_{total}.ply"
    if not mesh.exists():
        trimesh.Trimesh(vertices, faces, process=False).export(mesh)
    scene = folder / "scene.toml"
    scene.write_text(SCENE.format(mesh=mesh.as_posix(), path=path, floor=floor))
    model = build_model(load_scene(scene))
    state = initial_state(model)
    for _ in range(20):                       # compile or load kernels, settle the set
        step(model, state)
    steps, start = 0, time.perf_counter()
    while True:
        for _ in range(50):
            step(model, state)
        steps += 50
        elapsed = time.perf_counter() - start
        if elapsed >= seconds:
            break
    s = state.bodies[0]
    return elapsed / steps, len(s.active), len(s.wear_depth)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=1.0, help="timing per configuration")
    parser.add_argument("--quick", action="store_true", help="stop at 10⁵ vertices")
    args = parser.parse_args()
    top = 100_000 if args.quick else 1_000_000
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        floor_mesh = folder / "grid_floor.stl"
        trimesh.Trimesh(*grid_floor(20_000), process=False).export(floor_mesh)
        grid = f'type = "mesh"\nmesh = "{floor_mesh.as_posix()}"'

        def run(label, patch, total, floor, path=FRETTING):
            t, active, n = measure(folder, patch, total, floor, path, args.seconds)
            rows.append(dict(case=label, patch=patch, vertices=n, active=active, seconds=t,
                             rate=active / t))
            print(f"  {label:34} {n:>9} {active:>7} {t * 1e6:10.1f} µs {active / t:10.3g}",
                  flush=True)
            return t

        print(f"  {'case':34} {'vertices':>9} {'active':>7} {'per step':>13} {'vertex-steps/s':>10}")
        ref = run("plane, mesh size", 10_000, 10_000, PLANE)
        sizes = [n for n in (100_000, 1_000_000) if n <= top]
        for n in sizes:
            run("plane, mesh size", 10_000, n, PLANE)
        for p in (1_000, 100_000):
            run("plane, patch size", p, top, PLANE)
        for n in (10_000, 100_000):
            run("box mesh floor (12 faces)", 10_000, n, BOX)
            run("grid mesh floor (2e4 faces)", 10_000, n, grid)
        run("plane, sliding 0.1 m/s", 10_000, 100_000, PLANE, SLIDING)
        run("grid mesh floor, sliding 0.1 m/s", 10_000, 100_000, grid, SLIDING)

    def find(case, patch, n):
        return next(r["seconds"] for r in rows
                    if r["case"] == case and r["patch"] == patch and abs(r["vertices"] - n) < 0.02 * n)

    print("\n  ratios to the 10⁴-vertex body on a plane (same run):")
    for r in rows:
        print(f"  {r['case']:34} {r['vertices']:>9} {r['active']:>7} {r['seconds'] / ref:8.2f}x")
    size_ratio = find("plane, mesh size", 10_000, top) / ref
    box = find("box mesh floor (12 faces)", 10_000, 10_000) / ref
    fine = find("grid mesh floor (2e4 faces)", 10_000, 10_000) / ref
    sliding = (find("grid mesh floor, sliding 0.1 m/s", 10_000, 100_000)
               / find("plane, sliding 0.1 m/s", 10_000, 100_000))
    print(f"\n  {top:.0e} vertices, 1e4 active vs the 1e4-vertex body: {size_ratio:.2f}x "
          "(target <= 3)")
    print(f"  mesh floor vs plane, same 1e4 active: box {box:.2f}x, 2e4-face grid {fine:.2f}x "
          "(target <= 5)")
    print(f"  sliding (active set refreshed as it goes): grid floor vs plane {sliding:.2f}x")
    if not args.quick:
        write_docs(rows, ref, size_ratio, top, box, fine, sliding)
    print(json.dumps({
        "benchmark": "scaling",
        "reference_seconds_per_step": ref,
        "reference_vertex_steps_per_s": 10_000 / ref,
        "largest_mesh_to_reference": size_ratio,
        "largest_mesh_vertices": top,
        "box_mesh_to_plane": box,
        "grid_mesh_to_plane": fine,
        "sliding_grid_mesh_to_plane": sliding,
        "rows": rows,
    }))


def write_docs(rows, ref, size_ratio, top, box, fine, sliding):
    lines = [MARK_START, "", "## Cost against mesh size, contact patch and counter-surface", "",
             "<!-- written by benchmarks/scaling.py -->", "",
             "```sh", ".venv/bin/python benchmarks/scaling.py", "```", "",
             "A prescribed part fretting ±2 µm (dynamic, Δt = 10 µs): a square contact patch",
             "of *P* vertices pressed 1 µm into the counter-surface, plus a far sheet that",
             "brings the mesh to *N* vertices (the bulk of a CAD part that never touches).",
             "Only the patch is in the [active set](model.md#active-set). *Per step* is the",
             "whole step (active-set check, face lookup, contact kernel, motion); the rate",
             "counts active vertices. Ratios are to the first row, measured in the same run.",
             "",
             "| case | vertices *N* | active | per step | vertex-steps/s | ratio |",
             "|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['vertices']:,} | {r['active']:,} | "
                     f"{r['seconds'] * 1e6:.0f} µs | {r['rate']:.2e} | {r['seconds'] / ref:.2f}× |")
    lines += ["",
              f"- {top:,} vertices with a 1 % patch cost {size_ratio:.2f}× the 10⁴-vertex body",
              "  with the same patch (target ≤ 3×): the cost follows the active vertices.",
              f"- A mesh counter-surface costs {box:.2f}× the plane (a 12-face box) and",
              f"  {fine:.2f}× (a 2·10⁴-face sheet) at the same 10⁴ active vertices (target ≤ 5×):",
              "  the face lookup is the extra.",
              f"- Sliding at 0.1 m/s over the sheet (the active set refreshed every ~10 steps)",
              f"  costs {sliding:.2f}× sliding on the plane, which never refreshes (only motion",
              "  along a plane's normal counts).", "", MARK_END]
    perf = ROOT / "docs" / "performance.md"
    text = perf.read_text()
    section = "\n".join(lines)
    if MARK_START in text:
        text = text[:text.index(MARK_START)] + section + text[text.index(MARK_END) + len(MARK_END):]
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    perf.write_text(text)


if __name__ == "__main__":
    main()
