"""Validation cases: an example scene each, run and compared with its closed
form (docs/model.md) at the tolerance of docs/validation.md.

``tests/test_validation.py`` asserts every row; ``benchmarks/validate.py``
runs the same functions, writes ``docs/validation.md`` and draws the plots
from the ``data`` each case returns. Closed forms are computed here from the
scene's own parameters, never from an earlier run.
"""

import dataclasses
from pathlib import Path

import numpy as np

from meshwear.kernels.contact import rotation_entries
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run_scene

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
VALIDATION = EXAMPLES / "validation"


@dataclasses.dataclass
class Row:
    """One line of the report."""

    case: str
    quantity: str
    closed_form: float
    measured: float
    tolerance: float
    unit: str = ""
    relative: bool = True

    @property
    def error(self):
        if self.relative:
            return abs(self.measured - self.closed_form) / abs(self.closed_form)
        return abs(self.measured - self.closed_form)

    @property
    def ok(self):
        return bool(self.error <= self.tolerance)


@dataclasses.dataclass
class Case:
    name: str
    scene: Path
    rows: list
    data: dict = dataclasses.field(default_factory=dict)


class Samples:
    """Observer keeping what the validation plots need at every history sample."""

    def __init__(self):
        self.time, self.pose, self.wrench, self.normal_force, self.wear_depth = [], [], [], [], []
        self.friction_work, self.wear_volume, self.vertices = [], [], []

    def on_frame(self, model, state):
        pass

    def on_sample(self, model, state):
        s = state.bodies[0]
        self.time.append(state.time)
        self.pose.append(s.pose.copy())
        self.wrench.append(s.wrench.copy())
        self.normal_force.append(s.normal_force.sum(axis=0))
        self.wear_depth.append(s.wear_depth.copy())
        self.friction_work.append(s.friction_work.sum())
        self.wear_volume.append(s.wear_volume.sum())

    def arrays(self):
        return {k: np.asarray(v) for k, v in vars(self).items() if v}


def _run(scene, **run_changes):
    if run_changes:
        scene = dataclasses.replace(scene, run=dataclasses.replace(scene.run, **run_changes))
    samples = Samples()
    model, state, _ = run_scene(scene, observers=[samples])
    return model, state, samples.arrays()


def _load(model, scene):
    """The load (N) the planes carry: gravity on the body plus its force, along
    the free axis."""
    body, axis = scene.bodies[0], np.asarray(scene.bodies[0].path.free_axis)
    weight = model.bodies[0].mass * np.asarray(scene.run.gravity)
    return -float((weight + np.asarray(body.force)) @ axis)


def _contact_area(body, pose):
    """Contact areas (n,) of the body on the +z plane at ``pose``."""
    R = np.array(rotation_entries(pose[3:7])).reshape(3, 3)
    return np.maximum(-(body.area_vectors[:, 0:3] @ R.T)[:, 2], 0.0)


def _lowest(model, state):
    """Depth (m) of the deepest vertex below the z = 0 plane."""
    s = state.bodies[0]
    R = np.array(rotation_entries(s.pose[3:7])).reshape(3, 3)
    return -float((s.pose[0:3] + s.vertices @ R.T)[:, 2].min())


# ---------------------------------------------------------------- the cases

def winkler_sphere(loads=(1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0)):
    """Approach of a ball on a Winkler foundation: delta = sqrt(P / (pi K R))."""
    scene = load_scene(VALIDATION / "winkler_sphere.toml")
    K = scene.contact.stiffness_per_area
    R = scene.bodies[0].shape.radius
    model, state, _ = _run(scene)
    P = _load(model, scene)
    delta = _lowest(model, state)
    rows = [Row("Winkler sphere", f"approach at P = {P:g} N", np.sqrt(P / (np.pi * K * R)),
                delta, 1e-2, "m")]
    curve = []
    for load in loads:
        body = dataclasses.replace(scene.bodies[0], force=(0.0, 0.0, -load))
        m, s, _ = _run(dataclasses.replace(scene, bodies=(body,)))
        curve.append((load, _lowest(m, s)))
    curve = np.array(curve)
    data = {"load": curve[:, 0], "approach": curve[:, 1],
            "closed": np.sqrt(curve[:, 0] / (np.pi * K * R)),
            "touching": int((state.bodies[0].contact_state > 0).sum())}
    return Case("winkler_sphere", VALIDATION / "winkler_sphere.toml", rows, data)


def flat_pin():
    """Uniform wear of a flat-ended pin: w = k p s, p = P / A."""
    scene = load_scene(VALIDATION / "flat_pin.toml")
    model, state, samples = _run(scene)
    body, s = model.bodies[0], state.bodies[0]
    end = body.reference_vertices[:, 2] < body.reference_vertices[:, 2].min() + 1e-12
    sections = scene.bodies[0].shape.sections
    r = scene.bodies[0].shape.radius
    face = 0.5 * sections * r * r * np.sin(2 * np.pi / sections)   # the end polygon
    distance = np.linalg.norm(scene.bodies[0].path.velocity) * model.duration
    k, P = scene.wear.coefficient, _load(model, scene)
    depth = s.wear_depth[end]
    rows = [Row("flat-ended pin, archard", "mean wear depth", k * P / face * distance,
                float(depth.mean()), 5e-3, "m"),
            Row("flat-ended pin, archard", "max / min wear depth", 1.0,
                float(depth.max() / depth.min()), 1e-2, "")]
    return Case("flat_pin", VALIDATION / "flat_pin.toml", rows, {"depth": depth})


def cap_depth(volume, R):
    """Depth h of a spherical cap of ``volume``: pi h^2 (R - h/3) = V (Newton)."""
    h = np.sqrt(volume / (np.pi * R))
    for _ in range(50):
        h -= (np.pi * h * h * (R - h / 3) - volume) / (np.pi * (2 * R * h - h * h))
    return h


def sphere_pin(scene_path=VALIDATION / "sphere_pin.toml", **changes):
    """A ball pin slid 10 m: V = k P s and a flat cap of depth h(V)."""
    scene = load_scene(scene_path)
    if changes:
        scene = _with(scene, **changes)
    model, state, samples = _run(scene)
    body, s = model.bodies[0], state.bodies[0]
    R = body.reference_vertices[:, 2].max() - body.reference_vertices[:, 2].min()
    R = 0.5 * R
    distance = np.linalg.norm(scene.bodies[0].path.velocity) * model.duration
    k, P = scene.wear.coefficient, _load(model, scene)
    volume = float(s.wear_volume.sum())
    h = cap_depth(k * P * distance, R)
    rows = [Row("ball pin slid 10 m, archard", "worn volume", k * P * distance, volume, 1e-2, "m³"),
            Row("ball pin slid 10 m, archard", "max wear depth", h, float(s.wear_depth.max()),
                2e-2, "m")]
    # the worn profile: depth against the distance from the pin's axis
    radius = np.linalg.norm(body.reference_vertices @ _axes(s.pose), axis=1)
    lower = _lowest_half(body, s.pose)
    data = {"radius": radius[lower], "depth": s.wear_depth[lower], "h": h, "R": R,
            "vertices": len(body.reference_vertices)}
    return Case("sphere_pin", scene_path, rows, data)


def _axes(pose):
    """Body-frame coordinates -> world x, y (2 columns of R^T)."""
    R = np.array(rotation_entries(pose[3:7])).reshape(3, 3)
    return R[0:2].T


def _lowest_half(body, pose):
    R = np.array(rotation_entries(pose[3:7])).reshape(3, 3)
    return (body.reference_vertices @ R.T)[:, 2] < 0.0


def _with(scene, *, subdivisions=None, stiffness=None, law=None, coefficient=None, duration=None):
    """The scene with the ball refined or coarsened, or another contact or wear law."""
    body = scene.bodies[0]
    if subdivisions is not None:
        body = dataclasses.replace(body, shape=dataclasses.replace(body.shape,
                                                                   subdivisions=subdivisions))
    contact, wear, run = scene.contact, scene.wear, scene.run
    if stiffness is not None:  # per point, N/m
        contact = dataclasses.replace(contact, stiffness=stiffness, stiffness_per_area=None)
    if law is not None:
        wear = dataclasses.replace(wear, law=law, coefficient=coefficient)
    if duration is not None:
        run = dataclasses.replace(run, duration=duration)
    return dataclasses.replace(scene, bodies=(body,), contact=contact, wear=wear, run=run)


def tilted_punch():
    """Pressure differences under a sliding punch decay like exp(-k K s)."""
    scene = load_scene(VALIDATION / "tilted_punch.toml")
    model, state, samples = _run(scene)
    body = model.bodies[0]
    face = body.reference_vertices[:, 2] < body.reference_vertices[:, 2].min() + 1e-12
    area = _contact_area(body, samples["pose"][0])[face]
    pressure = samples["normal_force"][:, face] / area
    spread = pressure.max(axis=1) - pressure.min(axis=1)
    speed = np.linalg.norm(scene.bodies[0].path.velocity)
    s = samples["time"] * speed
    keep = (s > 0.0) & (spread > 1e-6 * spread[1])
    rate = -np.polyfit(s[keep], np.log(spread[keep]), 1)[0]
    k, K = scene.wear.coefficient, scene.contact.stiffness_per_area
    rows = [Row("tilted flat punch, archard", "decay rate of pressure differences", k * K, rate,
                5e-2, "1/m")]
    return Case("tilted_punch", VALIDATION / "tilted_punch.toml", rows,
                {"distance": s, "spread": spread, "rate": k * K})


def jenkins_quasi_static():
    """Friction energy per cycle in quasi-static mode; nothing slips below mu N / K_t."""
    scene = load_scene(VALIDATION / "jenkins_quasi_static.toml")
    model, state, samples = _run(scene)
    body = model.bodies[0]
    osc = scene.bodies[0].path.oscillation
    P, mu = _load(model, scene), scene.contact.friction
    face = body.reference_vertices[:, 2] < body.reference_vertices[:, 2].min() + 1e-12
    k_t = scene.contact.stiffness_per_area * _contact_area(body, samples["pose"][0])[face].sum()
    expected = 4 * mu * P * (osc.amplitude - mu * P / k_t)
    t, work = samples["time"], samples["friction_work"]
    period = 1.0 / osc.frequency
    edges = [int(np.abs(t - c * period).argmin()) for c in range(int(round(t[-1] / period)) + 1)]
    per_cycle = np.diff(work[edges])[1:]   # the first cycle loads the springs from zero
    worst = per_cycle[np.abs(per_cycle - expected).argmax()]
    rows = [Row("Jenkins loop, quasi-static", "friction energy per cycle (worst of 2-5)",
                expected, float(worst), 5e-3, "J")]
    # below the slip amplitude: a quarter of mu N / K_t
    small = dataclasses.replace(osc, amplitude=0.25 * mu * P / k_t)
    body_config = dataclasses.replace(scene.bodies[0], path=dataclasses.replace(
        scene.bodies[0].path, oscillation=small))
    m2, s2, _ = _run(dataclasses.replace(scene, bodies=(body_config,)))
    slipped = int((s2.bodies[0].contact_state == 2).sum())
    below = "at a quarter of mu N / K_t:"
    rows += [Row("Jenkins loop, quasi-static", f"{below} points slipping at the end", 0.0,
                 float(slipped), 0.0, relative=False),
             Row("Jenkins loop, quasi-static", f"{below} friction work", 0.0,
                 float(s2.bodies[0].friction_work.sum()), 0.0, "J", relative=False),
             Row("Jenkins loop, quasi-static", f"{below} worn volume", 0.0,
                 float(s2.bodies[0].wear_volume.sum()), 0.0, "m³", relative=False)]
    x = samples["pose"][:, 0] - samples["pose"][0, 0]
    return Case("jenkins_quasi_static", VALIDATION / "jenkins_quasi_static.toml", rows,
                {"x": x, "fx": samples["wrench"][:, 0], "mu_N": mu * P, "k_t": k_t,
                 "amplitude": osc.amplitude})


def pin_on_disc():
    """A flat pin circling on a plane: V = k P s."""
    scene = load_scene(EXAMPLES / "pin_on_disc.toml")
    model, state, samples = _run(scene)
    circle = scene.bodies[0].path.circle
    distance = 2 * np.pi * circle.radius * circle.frequency * model.duration
    k, P = scene.wear.coefficient, _load(model, scene)
    rows = [Row("pin on disc, archard", "worn volume", k * P * distance,
                float(state.bodies[0].wear_volume.sum()), 1e-2, "m³")]
    return Case("pin_on_disc", EXAMPLES / "pin_on_disc.toml", rows,
                {"time": samples["time"], "volume": samples["wear_volume"],
                 "closed": k * P * 2 * np.pi * circle.radius * circle.frequency * samples["time"]})


def mesh_independence(levels=(4, 5, 6), duration=2.0):
    """The ball pin at three mesh levels, per area (Winkler + archard) and per
    point (the published formulation: stiffness per point, `energy` law)."""
    scene = load_scene(VALIDATION / "sphere_pin.toml")
    out = {"levels": list(levels), "vertices": [], "per_area": [], "per_point": []}
    # per point: the stiffness and energy coefficient that match the Winkler
    # run on the middle level (its mean tributary area near the pole)
    from meshwear import geometry

    v, f = geometry.primitive("sphere", radius=scene.bodies[0].shape.radius,
                              subdivisions=levels[1])
    mean_area = geometry.tributary_areas(v, f).mean()
    stiffness = scene.contact.stiffness_per_area * mean_area
    energy_k = scene.wear.coefficient / (scene.contact.friction * mean_area)
    for level in levels:
        a = sphere_pin(subdivisions=level, duration=duration)
        p = sphere_pin(subdivisions=level, duration=duration, stiffness=stiffness, law="energy",
                       coefficient=energy_k)
        out["vertices"].append(a.data["vertices"])
        out["per_area"].append((a.rows[0].measured, a.rows[1].measured))
        out["per_point"].append((p.rows[0].measured, p.rows[1].measured))
    per_area = np.array(out["per_area"])
    change = np.abs(per_area[-1] / per_area[-2] - 1)   # refining the finest level once more
    rows = [Row("mesh independence (per area)", f"relative change of worn volume, level {levels[-2]} -> {levels[-1]}",
                0.0, float(change[0]), 1e-2, "", relative=False),
            Row("mesh independence (per area)", f"relative change of max depth, level {levels[-2]} -> {levels[-1]}",
                0.0, float(change[1]), 1e-2, "", relative=False)]
    return Case("mesh_independence", VALIDATION / "sphere_pin.toml", rows, out)


def mindlin_deresiewicz(mu, load, compliance, a, share):
    """Mindlin and Deresiewicz's energy (J) per fretting cycle of +-share mu P
    on a Hertz contact of radius ``a``, ``compliance`` sum (2 - nu) / G:
    (9/10) (mu P)^2 C / a [1 - (1 - x)^(5/3) - (5x/6)(1 + (1 - x)^(2/3))]."""
    return 0.9 * (mu * load) ** 2 * compliance / a * (
        1.0 - (1.0 - share) ** (5.0 / 3.0)
        - 5.0 * share / 6.0 * (1.0 + (1.0 - share) ** (2.0 / 3.0)))


def fretting_loop(grid, pressure, mu, top, points=41):
    """The half-space solver's fretting loop under ``pressure``: the
    tangential force from +top to -top and back, each point a segment from
    its turning point's shear; its area (J) and the shifts at the two
    turning points (m)."""
    from meshwear.contact.halfspace import solve_shear

    q_top, _, s_top = solve_shear(grid, pressure, mu, top)
    q_bottom, _, s_bottom = solve_shear(grid, pressure, mu, -top, q_top, top, s_top)
    forces = np.linspace(top, -top, points)
    down = [solve_shear(grid, pressure, mu, f, q_top, top, s_top)[2] for f in forces]
    up = [solve_shear(grid, pressure, mu, f, q_bottom, -top, s_bottom)[2] for f in forces[::-1]]
    return float(np.trapezoid(np.array(down) - np.array(up)[::-1], -forces)), s_top, s_bottom


def _hertz(scene):
    """Hertz's a, p0 and approach for the half-space ball ``scene``."""
    from meshwear.contact.halfspace import contact_modulus

    c = scene.contact
    e_star = contact_modulus(c.youngs_modulus, c.poissons_ratio)
    R, P = scene.bodies[0].shape.radius, -scene.bodies[0].force[2]
    a = (3.0 * P * R / (4.0 * e_star)) ** (1.0 / 3.0)
    return a, 3.0 * P / (2.0 * np.pi * a * a), a * a / R, P


def ellipse_radius(r2, values):
    """Radius and height of the ellipse ``values^2 = h^2 (1 - r^2 / radius^2)``
    fitted (least squares on the squares) to the positive ``values``."""
    pos = values > 0.0
    slope, intercept = np.polyfit(r2[pos], values[pos] ** 2, 1)
    return float(np.sqrt(-intercept / slope)), float(np.sqrt(intercept))


def cell_radii(patch):
    """Squared distance of each grid cell of a half-space patch from the
    patch's axis (m²)."""
    h = patch.grid.spacing[0]
    x = patch.origin[0] + h * np.arange(patch.grid.shape[0])
    y = patch.origin[1] + h * np.arange(patch.grid.shape[1])
    X, Y = np.meshgrid(x, y, indexing="ij")
    return X * X + Y * Y


def hertz_ball():
    """A ball pressed on a flat, half-space contact: Hertz's ellipse, on the
    grid and at the vertices."""
    from meshwear.model.build import build_model, initial_state
    from meshwear.output.fields import body_quantities

    scene = load_scene(VALIDATION / "hertz_ball.toml")
    model = build_model(scene)
    state = initial_state(model)
    patch = state.bodies[0].elastic
    a, p0, approach, _ = _hertz(scene)
    r2 = cell_radii(patch)
    radius, peak = ellipse_radius(r2, patch.pressure)
    case = "Hertz ball, half-space"
    rows = [Row(case, "contact radius (ellipse fitted to the pressure)", a, radius, 1e-2, "m"),
            Row(case, "peak pressure (the fitted ellipse's)", p0, peak, 1e-2, "Pa"),
            Row(case, "approach", approach, patch.approach - patch.heights.min(), 1e-2, "m")]
    s, b = state.bodies[0], model.bodies[0]
    # the pressure a frame writes: the solved one at each vertex's point
    pressure = body_quantities(b, s, model)["pressure"]
    loaded = pressure > 0.0
    r = np.hypot(s.vertices[:, 0], s.vertices[:, 1])
    inner = (r < 0.8 * a) & (s.vertices[:, 2] < 0.0)
    ratio = pressure[inner] / (p0 * np.sqrt(1.0 - (r[inner] / a) ** 2))
    rows.append(Row(case, "vertices inside 0.8 a whose pressure is within 10 % of Hertz's "
                    "(share)", 1.0, float(np.mean(np.abs(ratio - 1.0) <= 0.1)), 0.05,
                    relative=False))
    return Case("hertz_ball", VALIDATION / "hertz_ball.toml", rows,
                {"a": a, "p0": p0, "r_cells": np.sqrt(r2[patch.pressure > 0.0]),
                 "p_cells": patch.pressure[patch.pressure > 0.0],
                 "r_vertices": r[loaded], "p_vertices": pressure[loaded]})


def mindlin_fretting():
    """The ball rubbed in partial slip: Cattaneo-Mindlin's force and stick
    radius, Mindlin and Deresiewicz's energy per cycle."""
    from meshwear.model.build import build_model, initial_state
    from meshwear.step.simulate import step

    scene = load_scene(VALIDATION / "mindlin_fretting.toml")
    model = build_model(scene)
    state = initial_state(model)
    a, _, _, P = _hertz(scene)
    c = scene.contact
    mu, nu, E = c.friction, c.poissons_ratio, c.youngs_modulus
    compliance = sum(2.0 * (1.0 + n) * (2.0 - n) / e for e, n in zip(E, nu))
    stroke = scene.bodies[0].path.oscillation.amplitude
    gross = 3.0 * mu * P * compliance / (16.0 * a)
    x = 1.0 - (1.0 - stroke / gross) ** 1.5
    loop = mindlin_deresiewicz(mu, P, compliance, a, x)
    per_cycle = model.cycle_steps or round(1.0 / (scene.bodies[0].path.oscillation.frequency
                                                    * model.dt))
    shift, force, work = [0.0], [0.0], [0.0]
    stick = None
    while state.step < model.n_steps:
        step(model, state)
        s = state.bodies[0]
        shift.append(s.elastic.shift)
        force.append(-s.wrench[0])
        work.append(float(s.friction_work.sum()))
        if state.step == per_cycle // 4:            # the first stroke's end
            patch = s.elastic
            stick, _ = ellipse_radius(cell_radii(patch), mu * patch.pressure - patch.shear)
    force, work = np.array(force), np.array(work)
    second = slice(per_cycle, 2 * per_cycle + 1)
    case = "Cattaneo-Mindlin ball, half-space"
    rows = [Row(case, "largest tangential force in the 2nd cycle", x * mu * P,
                float(force[second].max()), 1e-2, "N"),
            Row(case, "stick radius at the first stroke's end", a * (1.0 - x) ** (1.0 / 3.0),
                stick, 2e-2, "m"),
            Row(case, "friction energy of the 2nd cycle (Mindlin-Deresiewicz)", loop,
                float(work[2 * per_cycle] - work[per_cycle]), 3e-2, "J")]
    return Case("mindlin_fretting", VALIDATION / "mindlin_fretting.toml", rows,
                {"shift": np.array(shift), "force": force, "mu_P": mu * P, "gross": gross,
                 "stroke": stroke, "x": x})


def halfspace_grid():
    """The half-space solver on its grid (meshwear/halfspace.py), steel on
    steel: Hertz's cylinder, the rigid flat punch, Cattaneo-Mindlin's stick
    radius and Mindlin-Deresiewicz's energy at three tangential loads (the
    sphere's Hertz rows are the hertz_ball case's, on a mesh)."""
    from meshwear.contact.halfspace import contact_modulus, make_grid, solve, solve_shear

    E, nu, R, P, mu = 210e9, 0.3, 0.01, 10.0, 0.5
    e_star = contact_modulus((E, E), (nu, nu))
    compliance = 2.0 * 2.0 * (1.0 + nu) * (2.0 - nu) / E
    case, rows = "half-space grid", []
    # a cylinder, plane strain, 1e5 N/m on 128 cells
    load = 1e5
    half = np.sqrt(4.0 * load * R / (np.pi * e_star))
    grid = make_grid((128,), 3.0 * half / 128, (E, E), (nu, nu))
    x = grid.centres[0]
    p = solve(grid, x * x / (2.0 * R), load).traction
    width, _ = ellipse_radius(x * x, p)
    rows += [Row(case, "Hertz cylinder: half-width b = sqrt(4PR / pi E*)", half, width, 1e-2, "m"),
             Row(case, "Hertz cylinder: peak pressure 2P / pi b", 2.0 * load / (np.pi * half),
                 float(p.max()), 1e-2, "Pa")]
    # a rigid flat punch, radius 1 mm, 100 N on 128 x 128 cells
    radius, load = 1e-3, 100.0
    grid = make_grid((128, 128), 2.4 * radius / 128, (E, E), (nu, nu))
    x, y = np.meshgrid(*grid.centres, indexing="ij")
    punch = solve(grid, np.zeros((128, 128)), load, mask=x * x + y * y <= radius * radius)
    rows.append(Row(case, "flat punch: load against 2 a E* delta", 2.0 * radius * e_star
                    * punch.approach, load, 1e-2, "N"))
    # a sphere, 10 N on 64 x 64 cells over three contact radii, then shear
    a = (3.0 * P * R / (4.0 * e_star)) ** (1.0 / 3.0)
    grid = make_grid((64, 64), 3.0 * a / 64, (E, E), (nu, nu))
    x, y = np.meshgrid(*grid.centres, indexing="ij")
    r2 = x * x + y * y
    p = solve(grid, r2 / (2.0 * R), P).traction
    for share in (0.3, 0.6, 0.9):
        q, _, _ = solve_shear(grid, p, mu, share * mu * P)
        stick, _ = ellipse_radius(r2, mu * p - q)
        rows.append(Row(case, f"Cattaneo-Mindlin stick radius at Q = {share} mu P",
                        a * (1.0 - share) ** (1.0 / 3.0), stick, 2e-2, "m"))
    for share in (0.3, 0.6, 0.9):
        loop, _, _ = fretting_loop(grid, p, mu, share * mu * P)
        rows.append(Row(case, f"Mindlin-Deresiewicz energy per cycle at Q* = {share} mu P",
                        mindlin_deresiewicz(mu, P, compliance, a, share), loop, 3e-2, "J"))
    return Case("halfspace_grid", Path(__file__).resolve().parent / "test_halfspace.py", rows)


ALL = (winkler_sphere, flat_pin, sphere_pin, tilted_punch, jenkins_quasi_static, pin_on_disc,
       mesh_independence, hertz_ball, mindlin_fretting, halfspace_grid)


def arc_chord(u, radius, track):
    """Length of the circle of radius ``track + u`` (about a disc's axis)
    inside a pin's face of ``radius`` a centred ``track`` R off the axis:
    the time a disc point at offset u from the track's centre line spends
    under the pin per turn, times its speed. 2 sqrt(a² - u²) is its limit for
    R >> a; at a / R = 0.2 the arc is 6 % longer outside the centre line at
    u = 0.6 a and 6 % shorter inside."""
    rho = track + np.asarray(u, float)
    cos = np.clip((rho ** 2 + track ** 2 - radius ** 2) / (2.0 * rho * track), -1.0, 1.0)
    return 2.0 * rho * np.arccos(cos)


def on_hat_functions(vertices, faces, density, order=12):
    """A mesh's lumped projection of a depth ``density(points)`` (a function
    of (..., 3) points): at each vertex the integral of its hat function times
    the density over the hat function's integral, by a (order+1)(order+2)/2
    point rule per face. Wear spread by barycentric weights and divided by
    tributary areas converges to it."""
    b = np.array([(i, j, order - i - j) for i in range(order + 1)
                  for j in range(order + 1 - i)], float) + 1.0 / 3.0
    b /= b.sum(axis=1, keepdims=True)
    tri = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    values = density(np.einsum("kc,fcd->fkd", b, tri))
    num, den = np.zeros(len(vertices)), np.zeros(len(vertices))
    for c in range(3):
        np.add.at(num, faces[:, c], area * (b[:, c] * values).mean(axis=1))
        np.add.at(den, faces[:, c], area * b[:, c].mean())
    return num / den


def disc_track(vertices, faces, face_height, track, pin_radius, pressure, coefficient, turns):
    """The track a flat pin (``pin_radius`` a, mean ``pressure`` p) wears in a
    disc's running face (its vertices at z = ``face_height``) at ``track``
    radius R in ``turns`` turns, Archard ``coefficient`` k: depth k p c(u)
    per turn (:func:`arc_chord`), projected on the disc mesh
    (:func:`on_hat_functions`). Returns the depth at each vertex and its
    offset u from the track's centre line."""
    def law(points):
        u = np.linalg.norm(points[..., :2], axis=-1) - track
        on_face = np.abs(points[..., 2] - face_height) < 1e-9
        return np.where(on_face, coefficient * pressure * turns * arc_chord(u, pin_radius, track),
                        0.0)

    return (on_hat_functions(vertices, faces, law),
            np.linalg.norm(vertices[:, :2], axis=1) - track)
