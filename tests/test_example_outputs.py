"""The examples' outputs tell the truth (docs/outputs.md).

Every history row of every two-body example (a body on a worn counter-part)
balances: the contact forces on the parts sum to zero (Newton's third law:
the counter-part's row is the reaction of the bodies' contacts), in the
rows filled from cycle jumps (``resolved = 0``) as in the resolved ones, and
a filled row shows its parts where they were at the same phase of a
resolved cycle; ``meshwear run``'s history.csv and ``meshwear.run``'s
history agree. And ``meshwear plot``'s default wear map of every example
shows the vertices holding the deepest 10 % of its wear in their colours
(read back from the picture's pixels).

Each example runs short (``--set`` keys), the two-body ones long enough for
cycle jumps where they can jump in a few seconds.
"""

import csv
import importlib.util
from pathlib import Path

import matplotlib
import matplotlib.image
import numpy as np
import pytest

import meshwear
from cases import EXAMPLES
from meshwear.cli import main
from meshwear.output import maps, plots
from meshwear.output.export import worn_parts
from meshwear.scene.reader import load_scene

TURN = 2.0 * np.pi / 10.0          # s: a turn at the examples' 10 rad/s

#: the two-body examples (a worn counter-surface), each with the settings
#: that make it a short run with rows filled from jumps
TWO_BODY = {
    "pin_on_worn_disc.toml": {"run.duration": 5 * TURN, "wear.acceleration": "cycle_jump",
                              "run.history": 41},
    "cylinder_on_worn_flat.toml": {"run.duration": 6.0, "wear.acceleration": "cycle_jump",
                                   "body[0].resolution": 3e-4, "surface[0].resolution": 3e-4,
                                   "run.history": 49},
    "cylinder_on_flat_fretting.toml": {"run.duration": 200.0, "body[0].resolution": 4e-5,
                                       "surface[0].resolution": 4e-5, "run.history": 41},
    # (the gear pair on a coarser mesh of the same gear, made by
    # meshes/make_gear.py: the example's own takes some 30 s to its first jump)
    "gear_pair.toml": {"run.duration": 5 * TURN, "run.dt": 1e-3, "wear.tolerance": 0.05,
                       "run.history": 41},
    # (the same coarser gear; 100 rad/s)
    "gear_pair_torque_quasi_static.toml": {"run.duration": 5 * 2.0 * np.pi / 100.0,
                                           "run.dt": 1e-4, "wear.tolerance": 0.05,
                                           "run.history": 41},
    "shaft_in_worn_bushing.toml": {
        "run.duration": 6 * TURN, "run.dt": 1e-3, "wear.acceleration": "cycle_jump",
        "body[0].shape": {"type": "cylinder", "radius": 0.005, "height": 0.005, "sections": 64},
        "body[0].resolution": 0.01, "run.history": 49},
    "mechanisms/slider_crank.toml": {"run.duration": 0.4, "wear.tolerance": 0.05,
                                     "run.history": 81},
    # (resolved rows only: a revolution is 25 133 steps, a jump needs three)
    "mechanisms/gear_pair_torque.toml": {"run.duration": 0.005, "run.history": 41},
    # (resolved rows only: a swing is no cycle)
    "mechanisms/pendulum_in_bushing.toml": {"run.duration": 0.05, "run.history": 41},
}
#: those whose rows above are all resolved
RESOLVED_ONLY = {"mechanisms/gear_pair_torque.toml", "mechanisms/pendulum_in_bushing.toml"}
#: the other examples: a short run that wears them
SHORT = {
    "block_on_ring.toml": 0.1, "block_on_ring_mesh.toml": 0.1, "cad_part.toml": 0.1,
    "cube_toss.toml": 0.1, "pin_on_disc.toml": 0.1, "pin_on_turning_disc.toml": 0.05,
    "reciprocating_block.toml": 0.008, "sphere_on_flat_fretting.toml": 0.0125,
    "sphere_on_flat_fretting_elastic.toml": 0.05, "step_pin_on_disc.toml": 0.1,
    "mechanisms/pin_on_disc.toml": 0.01,
}

#: force balance, as a share of the load (the largest contact force on a body)
BALANCE = 0.01


def _examples():
    return sorted(str(p.relative_to(EXAMPLES)) for p in
                  list(EXAMPLES.glob("*.toml")) + list(EXAMPLES.glob("mechanisms/*.toml")))


def _coarse_gear(folder):
    """The example's gear (module 2 mm, 20 teeth, 2 mm wide) with 8 points a
    flank and 2 rows across the width, as an STL in ``folder``."""
    spec = importlib.util.spec_from_file_location(
        "make_gear", EXAMPLES.parent / "meshes" / "make_gear.py")
    make_gear = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make_gear)
    import trimesh

    path = Path(folder) / "gear_m2_z20_w2_coarse_mm.stl"
    trimesh.Trimesh(*make_gear.gear_mesh(2.0, 20, 2.0, flank_points=8, layers=2),
                    process=False).export(path)
    return path


def _settings(name, folder):
    if name in TWO_BODY:
        values = dict(TWO_BODY[name])
        if name in ("gear_pair.toml", "gear_pair_torque_quasi_static.toml"):
            gear = str(_coarse_gear(folder))
            values.update({"body[0].mesh": gear, "surface[0].mesh": gear})
    else:
        values = {"run.duration": SHORT[name], "run.history": 2}
    values["run.frames"] = 2
    return values


@pytest.fixture(scope="module")
def example_run(tmp_path_factory):
    """``example_run(name)``: the folder ``meshwear run`` wrote for example
    ``name`` with its short settings, and the settings (run once each)."""
    done = {}

    def run(name):
        if name not in done:
            folder = tmp_path_factory.mktemp(name.replace("/", "_").removesuffix(".toml"))
            values = _settings(name, folder)
            out = folder / "out"
            sets = [a for key, value in values.items() for a in ("--set", f"{key}={_toml(value)}")]
            assert main(["run", str(EXAMPLES / name), "-o", str(out), "-q", *sets]) == 0
            done[name] = out, values
        return done[name]

    return run


def _toml(value):
    """A value as ``--set`` reads it (TOML)."""
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + "}"
    return repr(value)


def _history(path):
    """history.csv as columns (``body`` strings, the rest floats)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {c: np.array([r[c] for r in rows], dtype=object if c == "body" else float)
            for c in rows[0]}


def test_the_two_body_examples_are_those_listed():
    """A new example with a worn counter-surface joins the balance test."""
    worn = {name for name in _examples()
            if any(s.wear for s in load_scene(EXAMPLES / name).surfaces)}
    assert worn == set(TWO_BODY)
    assert set(_examples()) == set(TWO_BODY) | set(SHORT)


@pytest.mark.parametrize("name", sorted(TWO_BODY))
def test_every_history_row_of_a_two_body_example_balances(name, example_run):
    out, values = example_run(name)
    table = _history(out / "history.csv")
    result = meshwear.run(meshwear.load(EXAMPLES / name, values))
    # the API's history is the CLI's history.csv, column for column
    assert list(result.history) == list(table)
    for column, cells in table.items():
        if column == "body":
            assert list(result.history[column]) == list(cells)
        else:
            np.testing.assert_allclose(result.history[column], cells, rtol=1e-12,
                                       atol=1e-12 * max(np.abs(cells).max(), 1e-300),
                                       err_msg=column)
    parts = list(result.parts)
    rows = {p: {c: v[table["body"] == p] for c, v in table.items()} for p in parts}
    bodies = [b.name for b in result.model.bodies]
    force = {p: np.column_stack([rows[p][a] for a in ("fx", "fy", "fz")]) for p in parts}
    load = max(np.linalg.norm(force[b], axis=1).max() for b in bodies)
    assert load > 0.0
    total = sum(force.values())
    filled = rows[parts[0]]["resolved"] == 0
    if name not in RESOLVED_ONLY:
        assert filled.sum() >= 5, f"{name}: {filled.sum()} rows filled from jumps"
    worst = np.linalg.norm(total, axis=1) / load
    assert worst.max() <= BALANCE, (
        f"{name}: the parts' forces sum to {worst.max():.3g} of the load at "
        f"t = {rows[parts[0]]['time'][worst.argmax()]:.6g} s "
        f"({'filled' if filled[worst.argmax()] else 'resolved'} row)")
    _filled_rows_show_the_phase(result.model, rows, parts, filled)


def _filled_rows_show_the_phase(model, rows, parts, filled):
    """Each filled row shows every part where a resolved row at the same
    phase of the cycle has it (the wear moves a part by micrometres): a
    worn surface carried by a mechanism was drawn where a steady turn from
    the jump's end put it."""
    if not filled.any():
        return
    step = np.rint(rows[parts[0]]["time"] / model.dt).astype(np.int64)
    size = max(np.ptp(b.reference_vertices, axis=0).max() for b in model.bodies)
    compared = 0
    for i in np.flatnonzero(filled):
        same = np.flatnonzero(~filled & ((step - step[i]) % model.cycle_steps == 0))
        if not len(same):
            continue
        compared += 1
        for p in parts:
            x = np.column_stack([rows[p][a] for a in ("x", "y", "z")])
            q = np.column_stack([rows[p][a] for a in ("qw", "qx", "qy", "qz")])
            moved = np.linalg.norm(x[same] - x[i], axis=1).min()
            turned = 2.0 * np.arccos(np.clip(np.abs(q[same] @ q[i]), 0.0, 1.0)).min()
            assert moved <= 0.01 * size and turned <= 0.01, (
                f"{p} at t = {rows[p]['time'][i]:.6g} s (filled): {moved:.3g} m, "
                f"{turned:.3g} rad from its pose at the same phase of a resolved cycle")
    assert compared >= 1


# --------------------------------------------------------------- wear maps
#: the deepest wear: the worn vertices at or above this quantile of their depths
DEEPEST = 0.9
#: pixels round a vertex's place in the picture that are read
RADIUS = 3
#: a colour within this (RGB, 0..1) of one of the scale's is that colour
ON_SCALE = 0.06


def _scale_values(picture, places):
    """For each (row, column) of ``places``: the 75th percentile of the wear
    (a share of the scale's top) the picture's pixels within :data:`RADIUS`
    show in the scale's colours (viridis), NaN where none is on the scale
    (the background, text, a place outside the picture)."""
    lut = matplotlib.colormaps["viridis"](np.linspace(0.0, 1.0, 256))[:, :3]
    image = picture[..., :3]
    rows, columns = image.shape[:2]
    dr, dc = np.mgrid[-RADIUS:RADIUS + 1, -RADIUS:RADIUS + 1]
    disc = dr ** 2 + dc ** 2 <= RADIUS ** 2
    out = np.full(len(places), np.nan)
    for k, (r, c) in enumerate(places):
        if not (np.isfinite(r) and 0 <= r < rows and 0 <= c < columns):
            continue
        rr = np.clip(np.rint(r + dr[disc]).astype(int), 0, rows - 1)
        cc = np.clip(np.rint(c + dc[disc]).astype(int), 0, columns - 1)
        distance = np.linalg.norm(image[rr, cc][:, None, :] - lut[None], axis=2)
        nearest = distance.argmin(axis=1)
        on = distance[np.arange(len(nearest)), nearest] < ON_SCALE
        if on.any():
            out[k] = np.percentile(nearest[on] / 255.0, 75)
    return out


def _deepest_shown(picture, places, depth):
    """The share of the vertices holding the deepest wear (:data:`DEEPEST`)
    that the picture shows in their colour: at least half their depth on
    the scale, read round their place."""
    worn = depth > 0.0
    deep = np.flatnonzero(worn & (depth >= np.quantile(depth[worn], DEEPEST)))
    read = _scale_values(picture, places[deep])
    return float(np.mean(np.nan_to_num(read, nan=-1.0) >= 0.5 * depth[deep] / depth.max()))


def _plot(out, dest, monkeypatch, *args):
    """``meshwear plot OUT -d DEST ARGS``: the wear maps it wrote, and where
    each vertex of each part is drawn in its map (kept by a spy on
    :func:`meshwear.output.maps.wear_map`)."""
    places = {}

    def spy(out_dir, name, path, view=None):
        path, places[name] = maps.wear_map(out_dir, name, path, view, pixels=True)
        return path

    monkeypatch.setattr(plots, "wear_map", spy)
    assert main(["plot", str(out), "-d", str(dest), *args]) == 0
    return {name: (matplotlib.image.imread(dest / f"{name}_wear_map.png"), where)
            for name, where in places.items()}


@pytest.mark.parametrize("name", _examples())
def test_the_default_wear_map_shows_the_deepest_wear_in_colour(name, example_run, tmp_path,
                                                               monkeypatch):
    out, _ = example_run(name)
    drawn = _plot(out, tmp_path, monkeypatch)
    assert set(drawn) == set(worn_parts(out))
    checked = 0
    for part, (picture, places) in drawn.items():
        depth = maps.mesh_fields(out, part)[2]
        if depth.max() <= 0.0:
            continue
        checked += 1
        shown = _deepest_shown(picture, places, depth)
        assert shown >= 0.95, f"{name}, {part}: {shown:.1%} of the deepest wear shown"
    assert checked


def test_the_wear_map_check_fails_on_a_gear_seen_along_its_axis(example_run, tmp_path,
                                                                 monkeypatch):
    """The check can fail: the gear pair's pinion seen along its axis (the
    default before the unrolled map), its worn flanks edge-on."""
    out, _ = example_run("gear_pair.toml")
    (picture, places), = _plot(out, tmp_path, monkeypatch, "--part", "pinion",
                               "--view", "0,0,1").values()
    depth = maps.mesh_fields(out, "pinion")[2]
    assert _deepest_shown(picture, places, depth) < 0.2


def test_a_gear_is_unrolled_and_a_pin_seen_face_on():
    """A pin worn on its end face is looked at from below it; a gear worn
    on the flanks of its teeth (normals all round its axis) is unrolled
    round its axis, as is a bore worn on one side (it faces the axis: no
    view from outside sees it)."""
    import trimesh

    pin = trimesh.creation.cylinder(radius=0.001, height=0.003, sections=24)
    depth = np.where(pin.vertices[:, 2] < -0.0014, 1e-6, 0.0)
    kind, direction, _ = maps.choose_map(pin.vertices, pin.faces, depth)
    assert kind == "view" and direction @ [0.0, 0.0, -1.0] > 0.99
    gear = trimesh.load(EXAMPLES.parent / "meshes" / "gear_m2_z20_w2_mm.stl", process=True)
    flanks = np.abs(gear.vertex_normals[:, 2]) < 0.5
    rng = np.random.default_rng(0)
    depth = np.where(flanks, rng.uniform(0.5, 1.0, len(flanks)) * 3e-6, 0.0)
    kind, _, axis = maps.choose_map(gear.vertices, gear.faces, depth)
    assert kind == "unrolled" and abs(axis[2]) > 0.99
    bushing = trimesh.load(EXAMPLES.parent / "meshes" / "bushing_d10.1_mm.stl", process=True)
    radius = np.linalg.norm(bushing.vertices[:, :2], axis=1)
    below = (radius < radius.mean()) & (bushing.vertices[:, 1] < -0.5 * radius)
    kind, _, axis = maps.choose_map(bushing.vertices, bushing.faces,
                                    np.where(below, 1e-6, 0.0))
    assert kind == "unrolled" and abs(axis[2]) > 0.99


def test_an_unrolled_map_draws_each_vertex_at_its_depth(example_run, tmp_path, monkeypatch):
    """The unrolled gear's picture read back at every vertex drawn gives its
    depth (the scalar interpolated, not its colour): the places a map gives
    are where its vertices are drawn."""
    out, _ = example_run("gear_pair.toml")
    (picture, places), = _plot(out, tmp_path, monkeypatch, "--part", "wheel").values()
    depth = maps.mesh_fields(out, "wheel")[2]
    drawn = np.isfinite(places[:, 0])
    assert drawn.mean() > 0.5
    lut = matplotlib.colormaps["viridis"](np.linspace(0.0, 1.0, 256))[:, :3]
    rows, columns = np.rint(places[drawn]).astype(int).T
    pixels = picture[rows, columns, :3]
    distance = np.linalg.norm(pixels[:, None, :] - lut[None], axis=2)
    on = distance.min(axis=1) < ON_SCALE
    read = distance.argmin(axis=1)[on] / 255.0
    assert on.mean() > 0.8
    assert np.median(np.abs(read - depth[drawn][on] / depth.max())) < 0.01
