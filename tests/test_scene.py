"""Scene files (docs/scene-format.md): valid input maps onto the dataclasses with the
documented defaults; bad input raises one SceneError line naming file and key."""

import dataclasses
import math
import pickle
from pathlib import Path

import pytest

from meshwear.scene.reader import Scene, load_scene, parse_scene
from meshwear.scene.parts import (BodyConfig, Circle, Oscillation, PathConfig, RotationConfig,
                                  ShapeConfig, SurfaceConfig)
from meshwear.scene.settings import ContactConfig, RunConfig, WearConfig
from meshwear.scene.checks import SceneError

FULL = """
format = 1

[run]
mode = "dynamic"
duration = 2.0
dt = 2e-5
frames = 11
history = 201
gravity = [0.0, 0.0, -1.62]

[contact]
stiffness_per_area = 1e12
damping = 0
friction = 0.25
static_friction = 0.4
tangential_stiffness = 5e5

[wear]
law = "archard"
coefficient = 2.75e-14
direction = "vertex_normal"
acceleration = "cycle_jump"
period = 0.1
tolerance = 0.02

[[body]]
name = "pin"
mesh = "meshes/pin.obj"
units = "mm"
resolution = 2e-4
mass = 0.5
position = [0, 0, 0.01]
orientation = [2.0, 0.0, 0.0, 0.0]
motion = "guided"
force = [0.0, 0.0, -10.0]
[body.path]
oscillation = { axis = [3.0, 4.0, 0.0], amplitude = 5e-5, frequency = 10 }
velocity = [0.1, 0.0, 0.0]
free_axis = [0.0, 0.0, 2.0]

[[body]]
name = "ball_2"
shape = { type = "sphere", radius = 0.005 }
motion = "prescribed"
[body.path]
circle = { radius = 0.01, frequency = 1.0 }

[[surface]]
name = "floor"
normal = [0.0, 0.0, 5.0]
size = 0.1

[[surface]]
name = "disc"
type = "mesh"
shape = { type = "cylinder", radius = 0.05, height = 0.01 }
position = [0.0, 0.0, -0.005]
rotation = { axis = [0, 0, 1], rate = 10.0 }
"""

OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"

# a minimal valid scene that the bad cases below edit
MINIMAL = """format = 1

[[body]]
name = "block"
shape = { type = "box", size = [0.01, 0.01, 0.005] }
"""

FLOOR = '\n[[surface]]\nname = "floor"\n'


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_full_scene_parses_to_the_given_values(tmp_path):
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "pin.obj").write_text(OBJ)
    scene = load_scene(write(tmp_path, FULL))

    assert scene.format == 1
    assert scene.source == str(tmp_path / "scene.toml")
    assert scene.base_dir == tmp_path.resolve()
    assert scene.run == RunConfig(duration=2.0, dt=2e-5, frames=11, history=201,
                                  gravity=(0.0, 0.0, -1.62))
    c = scene.contact
    assert (c.stiffness, c.stiffness_per_area) == (None, 1e12)
    assert (c.damping, c.damping_per_area) == (0.0, None)
    assert (c.friction, c.static_friction) == (0.25, 0.4)
    assert c.tangential == ((5e5, None), (0.0, None))
    assert scene.wear == WearConfig(law="archard", coefficient=2.75e-14, direction="vertex_normal",
                                    acceleration="cycle_jump", period=0.1, tolerance=0.02)

    pin, ball = scene.bodies
    assert pin.name == "pin"
    assert pin.mesh == tmp_path.resolve() / "meshes" / "pin.obj"
    assert pin.shape is None and pin.units == "mm" and pin.resolution == 2e-4
    assert (pin.density, pin.mass) == (None, 0.5)
    assert pin.position == (0.0, 0.0, 0.01) and isinstance(pin.position[0], float)
    assert pin.orientation == (1.0, 0.0, 0.0, 0.0)  # normalised
    assert pin.force == (0.0, 0.0, -10.0) and pin.motion == "guided"
    assert pin.path.oscillation == Oscillation(axis=(0.6, 0.8, 0.0), amplitude=5e-5, frequency=10.0)
    assert pin.path.velocity == (0.1, 0.0, 0.0)
    assert pin.path.free_axis == (0.0, 0.0, 1.0)
    assert pin.path.circle is None

    assert ball.shape == ShapeConfig(type="sphere", radius=0.005, subdivisions=3)
    assert ball.density == 7850.0 and ball.mass is None
    assert ball.path == PathConfig(circle=Circle(radius=0.01, frequency=1.0, normal=(0.0, 0.0, 1.0)))

    floor, disc = scene.surfaces
    assert floor == SurfaceConfig(name="floor", type="plane", point=(0.0, 0.0, 0.0),
                                  normal=(0.0, 0.0, 1.0), size=0.1)
    assert disc.type == "mesh" and disc.mesh is None
    assert disc.shape == ShapeConfig(type="cylinder", radius=0.05, height=0.01, sections=32)
    assert disc.position == (0.0, 0.0, -0.005)
    assert disc.rotation == RotationConfig(axis=(0.0, 0.0, 1.0), rate=10.0, center=(0.0, 0.0, 0.0))


def test_minimal_scene_gets_the_documented_defaults(tmp_path):
    scene = load_scene(write(tmp_path, MINIMAL + FLOOR))
    assert scene.run == RunConfig(mode="dynamic", duration=1.0, dt="auto", frames=51, history=1001,
                                  gravity=(0.0, 0.0, -9.81))
    c = scene.contact
    assert (c.stiffness, c.stiffness_per_area, c.damping, c.damping_per_area) == (1e6, None, 20.0, None)
    assert (c.friction, c.static_friction) == (0.3, 0.3)
    assert c.tangential == ((1e6, None), (20.0, None))
    assert scene.wear == WearConfig(law="energy", coefficient=1e-9, direction="contact_normal",
                                    acceleration="none", period=None, tolerance=0.01)
    (body,) = scene.bodies
    assert body.units == "m" and body.density == 7850.0 and body.motion == "free"
    assert body.position == body.velocity == body.angular_velocity == body.force == (0.0, 0.0, 0.0)
    assert body.orientation == (1.0, 0.0, 0.0, 0.0) and body.path is None
    (floor,) = scene.surfaces
    assert floor.type == "plane" and floor.normal == (0.0, 0.0, 1.0) and floor.size is None


def test_single_body_table_counts_as_one_body(tmp_path):
    text = MINIMAL.replace("[[body]]", "[body]")
    assert [b.name for b in load_scene(write(tmp_path, text)).bodies] == ["block"]


def test_no_surfaces_is_allowed():
    scene = parse_scene({"format": 1, "body": {"name": "b", "shape": {"type": "box", "size": [1, 1, 1]}}})
    assert scene.surfaces == () and scene.source == "<scene>"


def test_replace_makes_a_validated_variant(tmp_path):
    scene = load_scene(write(tmp_path, MINIMAL))
    variant = dataclasses.replace(scene, run=dataclasses.replace(scene.run, dt=1e-4))
    assert variant.run.dt == 1e-4 and variant.bodies == scene.bodies
    with pytest.raises(SceneError, match="dt: must be > 0"):
        dataclasses.replace(scene.run, dt=-1.0)
    with pytest.raises(SceneError, match=r"static_friction: 0.3 is below friction = 0.5"):
        dataclasses.replace(scene.contact, friction=0.5)
    assert dataclasses.replace(scene.contact, friction=0.5, static_friction=0.6).friction == 0.5
    per_area = dataclasses.replace(scene.contact, stiffness=None, stiffness_per_area=1e12)
    assert (per_area.stiffness, per_area.stiffness_per_area) == (None, 1e12)
    with pytest.raises(SceneError, match="body.*motion"):
        dataclasses.replace(scene, run=dataclasses.replace(scene.run, mode="quasi-static"))


def test_dataclasses_are_frozen_and_accept_numpy_vectors():
    np = pytest.importorskip("numpy")
    run = RunConfig(gravity=np.array([0.0, 0.0, -9.81]))
    assert run.gravity == (0.0, 0.0, -9.81) and type(run.gravity) is tuple
    with pytest.raises(dataclasses.FrozenInstanceError):
        run.dt = 1.0
    assert ContactConfig(stiffness=np.float64(2e6)).stiffness == 2e6


def test_scene_error_is_a_value_error_and_keeps_its_parts():
    err = SceneError("a.toml", "run.dt", "must be > 0,\n got -1")
    assert isinstance(err, ValueError)
    assert (err.source, err.key, err.message) == ("a.toml", "run.dt", "must be > 0,\n got -1")
    assert str(err) == "a.toml: run.dt: must be > 0, got -1"
    assert str(pickle.loads(pickle.dumps(err))) == str(err)


def test_unknown_key_suggests_the_closest_one(tmp_path):
    path = write(tmp_path, MINIMAL + "[contact]\nstifness = 1e6\n")
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(info.value) == f"{path}: contact.stifness: unknown key (did you mean 'stiffness'?)"
    assert info.value.key == "contact.stifness"


def test_unknown_enum_value_lists_the_allowed_ones(tmp_path):
    path = write(tmp_path, MINIMAL + '[wear]\nlaw = "archrd"\n')
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(info.value) == (f"{path}: wear.law: 'archrd' is not one of 'energy', "
                               "'energy_density', 'archard' (did you mean 'archard'?)")


def test_missing_scene_file(tmp_path):
    with pytest.raises(SceneError, match="nothere.toml: file not found"):
        load_scene(tmp_path / "nothere.toml")


def test_toml_syntax_error_names_the_line(tmp_path):
    path = write(tmp_path, "format = 1\n[run]\ndt = = 3\n")
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert info.value.key.startswith("line 3")
    assert str(info.value).startswith(f"{path}: line 3") and "\n" not in str(info.value)


def _body(extra="", shape='shape = { type = "box", size = [0.01, 0.01, 0.005] }', name="block"):
    return f'\n[[body]]\nname = "{name}"\n{shape}\n{extra}\n'


GUIDED_PATH = '[body.path]\noscillation = { axis = [1, 0, 0], amplitude = 1e-5, frequency = 5 }\n'

# (id, scene text after "format = 1" -- or all of it after "FORMAT:" --, part of the error's key)
BAD = [
    ("unknown top-level key", "title = 'x'" + _body(), "title"),
    ("unknown nested key", "[run]\ndurration = 1.0\n" + _body(), "run.durration"),
    ("unknown body key", _body("densty = 1.0"), "body[0].densty"),
    ("missing format", "FORMAT:" + _body(), "format"),
    ("format = 2", "FORMAT:format = 2\n" + _body(), "format"),
    ("format as a string", "FORMAT:format = '1'\n" + _body(), "format"),
    ("negative dt", "[run]\ndt = -1e-5\n" + _body(), "run.dt"),
    ("dt > duration", "[run]\nduration = 0.1\ndt = 0.2\n" + _body(), "run.dt"),
    ("dt a word", "[run]\ndt = 'fast'\n" + _body(), "run.dt"),
    ("non-numeric value", "[run]\nduration = 'abc'\n" + _body(), "run.duration"),
    ("bool is not a number", "[contact]\nfriction = true\n" + _body(), "contact.friction"),
    ("float frames", "[run]\nframes = 2.5\n" + _body(), "run.frames"),
    ("history 1", "[run]\nhistory = 1\n" + _body(), "run.history"),
    ("vector of wrong length", "[run]\ngravity = [0.0, -9.81]\n" + _body(), "run.gravity"),
    ("vector of strings", _body("velocity = ['a', 'b', 'c']"), "body[0].velocity"),
    ("NaN value", "[contact]\nstiffness = nan\n" + _body(), "contact.stiffness"),
    ("inf in a vector", _body("position = [0.0, inf, 0.0]"), "body[0].position"),
    ("zero normal", _body() + FLOOR + "normal = [0, 0, 0]\n", "surface[0].normal"),
    ("zero quaternion", _body("orientation = [0, 0, 0, 0]"), "body[0].orientation"),
    ("quaternion of 3", _body("orientation = [1, 0, 0]"), "body[0].orientation"),
    ("unknown law", "[wear]\nlaw = 'archrd'\n" + _body(), "wear.law"),
    ("unknown mode", "[run]\nmode = 'static'\n" + _body(), "run.mode"),
    ("tolerance 1", "[wear]\ntolerance = 1.0\n" + _body(), "wear.tolerance"),
    ("negative wear coefficient", "[wear]\ncoefficient = -1e-9\n" + _body(), "wear.coefficient"),
    ("unknown motion", _body("motion = 'sliding'"), "body[0].motion"),
    ("both stiffness forms", "[contact]\nstiffness = 1e6\nstiffness_per_area = 1e12\n" + _body(),
     "contact.stiffness_per_area"),
    ("both tangential damping forms",
     "[contact]\ntangential_damping = 1\ntangential_damping_per_area = 1\n" + _body(),
     "contact.tangential_damping"),
    ("zero stiffness", "[contact]\nstiffness = 0\n" + _body(), "contact.stiffness"),
    ("negative damping", "[contact]\ndamping = -1\n" + _body(), "contact.damping"),
    ("static_friction < friction", "[contact]\nfriction = 0.5\nstatic_friction = 0.4\n" + _body(),
     "contact.static_friction"),
    ("both mesh and shape", _body('mesh = "m.obj"'), "body[0].shape"),
    ("neither mesh nor shape", _body(shape=""), "body[0].mesh"),
    ("missing mesh file", _body(shape='mesh = "missing.stl"'), "body[0].mesh"),
    ("mesh not a string", _body(shape="mesh = 3"), "body[0].mesh"),
    ("guided without path", _body("motion = 'guided'"), "body[0].path"),
    ("guided without free_axis", _body("motion = 'guided'\n" + GUIDED_PATH), "body[0].path.free_axis"),
    ("prescribed with free_axis",
     _body("motion = 'prescribed'\n" + GUIDED_PATH + "free_axis = [0, 0, 1]"), "body[0].path.free_axis"),
    ("free with path", _body(GUIDED_PATH), "body[0].path"),
    ("fixed with velocity", _body("motion = 'fixed'\nvelocity = [1, 0, 0]"), "body[0].velocity"),
    ("unknown path key", _body("motion = 'prescribed'\n[body.path]\nvelocty = [1, 0, 0]"),
     "body[0].path.velocty"),
    ("oscillation without frequency",
     _body("motion = 'prescribed'\n[body.path]\noscillation = { axis = [1, 0, 0], amplitude = 1 }"),
     "body[0].path.oscillation.frequency"),
    ("zero oscillation axis",
     _body("motion = 'prescribed'\n[body.path]\noscillation = { axis = [0, 0, 0], amplitude = 1, "
           "frequency = 1 }"), "body[0].path.oscillation.axis"),
    ("duplicate body names", _body() + _body(), "body[1].name"),
    ("body and surface share a name", _body() + '\n[[surface]]\nname = "block"\n', "surface[0].name"),
    ("unsafe name", _body(name="my pin"), "body[0].name"),
    ("missing name", '\n[[body]]\nshape = { type = "box", size = [1, 1, 1] }\n', "body[0].name"),
    ("bad units", _body(shape='mesh = "m.obj"\nunits = "km"'), "body[0].units"),
    ("units with a shape", _body('units = "mm"'), "body[0].units"),
    ("quasi-static with a free body", "[run]\nmode = 'quasi-static'\n" + _body(), "body[0].motion"),
    ("box shape without size", _body(shape='shape = { type = "box" }'), "body[0].shape.size"),
    ("sphere with size", _body(shape='shape = { type = "sphere", radius = 1, size = [1, 1, 1] }'),
     "body[0].shape.size"),
    ("shape without type", _body(shape='shape = { radius = 1 }'), "body[0].shape.type"),
    ("unknown shape type", _body(shape='shape = { type = "cube", size = [1, 1, 1] }'),
     "body[0].shape.type"),
    ("too many subdivisions", _body(shape='shape = { type = "sphere", radius = 1, subdivisions = 9 }'),
     "body[0].shape.subdivisions"),
    ("negative box size", _body(shape='shape = { type = "box", size = [1, -1, 1] }'),
     "body[0].shape.size"),
    ("negative density", _body("density = -1.0"), "body[0].density"),
    ("both density and mass", _body("density = 7800.0\nmass = 1.0"), "body[0].mass"),
    ("empty body list", "body = []\n", "body"),
    ("no body at all", "[run]\ndt = 1e-5\n", "body"),
    ("body is not a table", "body = 3\n", "body"),
    ("run is not a table", "run = 3\n" + _body(), "run"),
    ("mesh key on a plane", _body() + FLOOR + 'mesh = "m.obj"\n', "surface[0].mesh"),
    ("plane key on a mesh surface",
     _body() + FLOOR + 'type = "mesh"\nshape = { type = "box", size = [1, 1, 1] }\nnormal = [0, 0, 1]\n',
     "surface[0].normal"),
    ("unknown surface type", _body() + FLOOR + 'type = "plain"\n', "surface[0].type"),
    ("negative plane size", _body() + FLOOR + "size = -1.0\n", "surface[0].size"),
    ("rotation without rate",
     _body() + FLOOR + 'type = "mesh"\nshape = { type = "box", size = [1, 1, 1] }\n'
     'rotation = { axis = [0, 0, 1] }\n', "surface[0].rotation.rate"),
    ("cycle_jump without a period", "[wear]\nacceleration = 'cycle_jump'\n" + _body(), "wear.period"),
]


@pytest.mark.parametrize("text,key", [(t, k) for _, t, k in BAD], ids=[i for i, _, _ in BAD])
def test_bad_scene_raises_one_line_naming_file_and_key(tmp_path, text, key):
    (tmp_path / "m.obj").write_text(OBJ)
    text = text[len("FORMAT:"):] if text.startswith("FORMAT:") else "format = 1\n" + text
    path = write(tmp_path, text, name="bad_scene.toml")
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: ")
    assert "bad_scene.toml" in message
    assert key in info.value.key, message
    assert message.startswith(f"{path}: {info.value.key}: ")
    assert info.value.message



@pytest.mark.parametrize("first_line,expected", [
    ("format = 2", "version 2 is not supported"),
    ("format = '1'", "expected the integer 1"),
    ("format = 1.0", "expected the integer 1"),
    ("", "format: missing"),
])
def test_format_must_be_one(tmp_path, first_line, expected):
    path = write(tmp_path, first_line + "\n" + _body())
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert info.value.key == "format"
    assert expected in str(info.value)


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_non_finite_numbers_are_rejected_everywhere(value):
    with pytest.raises(SceneError, match="finite"):
        RunConfig(duration=value)
    with pytest.raises(SceneError, match="finite"):
        Circle(radius=1.0, frequency=1.0, normal=(0.0, value, 1.0))
    with pytest.raises(SceneError, match="finite"):
        BodyConfig(name="b", shape=ShapeConfig(type="box", size=(1, 1, 1)), mass=value)


def test_shape_keys_of_another_type_are_named(tmp_path):
    path = write(tmp_path, "format = 1\n" + _body(shape='shape = { type = "box", size = [1, 1, 1], '
                                                        'radius = 1 }'))
    with pytest.raises(SceneError, match=r"body\[0\].shape.radius: does not apply to a box"):
        load_scene(path)


def test_mesh_surface_with_path_and_rotation(tmp_path):
    (tmp_path / "disc.obj").write_text(OBJ)
    text = MINIMAL + """
[[surface]]
name = "disc"
type = "mesh"
mesh = "disc.obj"
units = "mm"
rotation = { axis = [0, 0, 2], rate = -3.0, center = [1, 0, 0] }
[surface.path]
velocity = [0.0, 0.1, 0.0]
"""
    (surface,) = load_scene(write(tmp_path, text)).surfaces
    assert surface.mesh == (tmp_path / "disc.obj").resolve() and surface.units == "mm"
    assert surface.rotation == RotationConfig(axis=(0.0, 0.0, 1.0), rate=-3.0, center=(1.0, 0.0, 0.0))
    assert surface.path == PathConfig(velocity=(0.0, 0.1, 0.0))


def test_quasi_static_accepts_guided_prescribed_and_fixed_bodies(tmp_path):
    text = ("format = 1\n[run]\nmode = 'quasi-static'\n"
            + _body("motion = 'guided'\nforce = [0, 0, -5]\n" + GUIDED_PATH + "free_axis = [0, 0, 1]",
                    name="a")
            + _body("motion = 'prescribed'\n" + GUIDED_PATH, name="b")
            + _body("motion = 'fixed'", name="c") + FLOOR)
    scene = load_scene(write(tmp_path, text))
    assert [b.motion for b in scene.bodies] == ["guided", "prescribed", "fixed"]
    assert scene.bodies[0].path.free_axis == (0.0, 0.0, 1.0)


def test_scene_checks_names_and_bodies_when_built_directly():
    body = BodyConfig(name="b", shape=ShapeConfig(type="box", size=(1, 1, 1)))
    with pytest.raises(SceneError, match="body: no bodies"):
        Scene(format=1)
    with pytest.raises(SceneError, match=r"surface\[0\].name: 'b' is already the name of body\[0\]"):
        Scene(format=1, bodies=(body,), surfaces=(SurfaceConfig(name="b"),))
    with pytest.raises(SceneError, match="format"):
        Scene(format=2, bodies=(body,))


_EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("path", sorted(_EXAMPLES.rglob("*.toml")), ids=lambda p: p.stem)
def test_every_example_scene_is_valid_and_its_meshes_exist(path):
    scene = load_scene(path)
    for item in scene.bodies + scene.surfaces:
        mesh = getattr(item, "mesh", None)
        if mesh is not None:
            assert Path(mesh).is_file(), f"{path.name}: {mesh} is missing"


UNITS_SCENE = """
format = 1
[contact]
{contact}
[wear]
law = "{law}"
coefficient = {coefficient}
[[body]]
name = "b"
shape = {{ type = "box", size = [0.01, 0.01, 0.01] }}
[[surface]]
name = "s"
type = "mesh"
shape = {{ type = "box", size = [0.02, 0.02, 0.002] }}
wear = true
{surface}
"""


def _units_scene(tmp_path, law="archard", coefficient="1e-13", contact="", surface=""):
    path = tmp_path / "units.toml"
    path.write_text(UNITS_SCENE.format(law=law, coefficient=coefficient, contact=contact,
                                       surface=surface))
    return load_scene(path)


@pytest.mark.parametrize("law, text, si", [
    ("archard", '"2e-6 mm3/(N m)"', 2e-15),
    ("archard", '"2e-6 mm^3/(N*m)"', 2e-15),
    ("archard", '"2e-6 mm³/(N·m)"', 2e-15),
    ("archard", '"2e-6 mm3/Nm"', 2e-15),
    ("archard", '"3e-15 1/Pa"', 3e-15),
    ("energy_density", '"1e-5 mm3/J"', 1e-14),
    ("energy", '"4 um/J"', 4e-6),
    ("energy", "4e-6", 4e-6),
])
def test_a_wear_coefficient_may_carry_its_unit(tmp_path, law, text, si):
    scene = _units_scene(tmp_path, law, text)
    assert scene.wear.coefficient == pytest.approx(si, rel=1e-12)
    assert isinstance(scene.wear.coefficient, float)


def test_a_worn_surface_s_coefficient_with_units_follows_the_law(tmp_path):
    inherited = _units_scene(tmp_path, surface='coefficient = "5e-6 mm3/(N m)"')
    assert inherited.surfaces[0].coefficient == pytest.approx(5e-15, rel=1e-12)
    own = _units_scene(tmp_path, surface='law = "energy"\ncoefficient = "2 mm/J"')
    assert own.surfaces[0].coefficient == pytest.approx(2e-3, rel=1e-12)
    with pytest.raises(SceneError, match=r"surface\[0\]\.coefficient: 'mm/J' is a m/J unit"):
        _units_scene(tmp_path, surface='coefficient = "2 mm/J"')


@pytest.mark.parametrize("law, text, message", [
    ("archard", '"2e-6 mm/J"', "'mm/J' is a m/J unit; this law's coefficient is in 1/Pa"),
    ("energy", '"2e-6 mm3/J"', "'mm3/J' is a m³/J unit"),
    ("archard", '"2e-6 furlongs"', "unknown unit 'furlongs'"),
    ("archard", '"lots"', "expected a number or"),
    ("archard", '"-1 mm3/(N m)"', "must be >= 0"),
])
def test_bad_coefficient_units_are_refused_naming_the_key(tmp_path, law, text, message):
    with pytest.raises(SceneError, match="wear.coefficient") as err:
        _units_scene(tmp_path, law, text)
    assert message in str(err.value)


def test_a_layer_gives_the_winkler_modulus(tmp_path):
    scene = _units_scene(tmp_path, contact="layer = { youngs_modulus = 2.1e11, "
                                           "poissons_ratio = 0.3, thickness = 1e-3 }")
    E, nu, h = 2.1e11, 0.3, 1e-3
    assert scene.contact.stiffness_per_area == pytest.approx(
        E * (1 - nu) / ((1 + nu) * (1 - 2 * nu) * h), rel=1e-12)
    assert scene.contact.stiffness is None
    # Poisson's ratio 0.3 unless given
    plain = _units_scene(tmp_path, contact="layer = { youngs_modulus = 2.1e11, thickness = 1e-3 }")
    assert plain.contact.stiffness_per_area == scene.contact.stiffness_per_area


@pytest.mark.parametrize("layer, key", [
    ("layer = { youngs_modulus = 2.1e11 }", "contact.layer.thickness"),
    ("layer = { youngs_modulus = -1.0, thickness = 1e-3 }", "contact.layer.youngs_modulus"),
    ("layer = { youngs_modulus = 1e9, thickness = 1e-3, poissons_ratio = 0.5 }",
     "contact.layer.poissons_ratio"),
    ("layer = { youngs_modulus = 1e9, thickness = 1e-3, nu = 0.3 }", "contact.layer.nu"),
    ("layer = 3.0", "contact.layer"),
    ("stiffness_per_area = 1e13\nlayer = { youngs_modulus = 1e9, thickness = 1e-3 }",
     "contact.layer"),
])
def test_bad_layers_are_refused_naming_the_key(tmp_path, layer, key):
    with pytest.raises(SceneError) as err:
        _units_scene(tmp_path, contact=layer)
    assert err.value.key == key
