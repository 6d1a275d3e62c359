"""A whole :class:`Scene`, and reading one from a TOML file (format 1).

The TOML tables map one to one onto the dataclasses of :mod:`.settings` and
:mod:`.parts` (docs/scene-format.md). Every value is checked in the
dataclass's ``__post_init__``, so ``dataclasses.replace`` makes a checked
variant for sweeps; the parser (:func:`load_scene`, :func:`parse_scene`) only
checks the key names, resolves mesh paths and builds nested tables, and
:class:`Scene` checks that its tables go together. Bad input raises
:class:`SceneError`, one line naming the file, the key and what is wrong::

    scene.toml: contact.stifness: unknown key (did you mean 'stiffness'?)

Keys of bodies and surfaces are written by index: ``body[0].density``,
``surface[1].normal`` (0-based, in file order); :func:`set_key` and
:func:`parse_override` set them over a file's (``--set``,
docs/scene-format.md, "Setting keys from the command line").
"""

import copy
import dataclasses
import numbers
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from ..kernels.laws import LAWS
from .checks import SceneError, _choice, _coefficient, _did_you_mean, _instance, _set, _show
from .parts import (SHAPE_KEYS, SURFACE_KEYS, SURFACE_TYPES, BodyConfig, Circle, MechanismConfig,
                    Oscillation, PathConfig, RotationConfig, ShapeConfig, SurfaceConfig)
from .settings import ContactConfig, RunConfig, WearConfig

FORMAT = 1
#: largest scene file read (bytes)
MAX_SCENE_BYTES = 16 * 2**20
#: files of a run's output folder that no part's outputs may take
RESERVED_NAMES = ("history.csv", "summary.json", "checkpoint.npz")


@dataclass(frozen=True, kw_only=True)
class Scene:
    """A whole scene: ``format`` (must be 1), where it came from, and its tables.

    ``source`` names the file in error messages; ``base_dir`` is the folder
    mesh paths were resolved against.
    """

    format: int
    source: str = "<scene>"
    base_dir: Path = Path(".")
    run: RunConfig = field(default_factory=RunConfig)
    contact: ContactConfig = field(default_factory=ContactConfig)
    wear: WearConfig = field(default_factory=WearConfig)
    bodies: tuple = ()
    surfaces: tuple = ()
    #: the MuJoCo model the parts with a ``mechanism_body`` ride on
    mechanism: MechanismConfig | None = None
    #: (key, value) pairs set over the file's (``--set``), part of its identity
    overrides: tuple = ()
    #: the parsed TOML it was built from (None if built in code): :meth:`set` edits a copy
    data: dict | None = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        def fail(key, message):
            raise SceneError(self.source, key, message)

        try:
            _check_format(self.format)
            _set(self, "run", _instance, RunConfig)
            _set(self, "contact", _instance, ContactConfig)
            _set(self, "wear", _instance, WearConfig)
        except SceneError as err:
            fail(err.key, err.message)
        object.__setattr__(self, "base_dir", Path(self.base_dir))
        object.__setattr__(self, "bodies", tuple(self.bodies))
        object.__setattr__(self, "surfaces", tuple(self.surfaces))
        # a worn surface's coefficient with units and [wear]'s law
        surfaces = list(self.surfaces)
        for j, s in enumerate(surfaces):
            if isinstance(s, SurfaceConfig) and isinstance(s.coefficient, str):
                try:
                    value = _coefficient("coefficient", s.coefficient, LAWS[self.wear.law].unit)
                except SceneError as err:
                    fail(f"surface[{j}].{err.key}", err.message)
                surfaces[j] = dataclasses.replace(s, coefficient=value)
        object.__setattr__(self, "surfaces", tuple(surfaces))
        if not self.bodies:
            fail("body", "no bodies; add at least one [[body]] table")
        items = ([(f"body[{i}]", b, BodyConfig) for i, b in enumerate(self.bodies)]
                 + [(f"surface[{j}]", s, SurfaceConfig) for j, s in enumerate(self.surfaces)])
        # each name owns the output paths <name>.pvd, <name>.vtkhdf and <name>/; no two may
        # clash, nor with history.csv / summary.json, ignoring case (as
        # Windows and macOS file systems do)
        taken = {name: name for name in RESERVED_NAMES}
        names = {}
        for key, item, cls in items:
            if not isinstance(item, cls):
                fail(key, f"expected a {cls.__name__}, got {_show(item)}")
            if item.name in names:
                fail(key + ".name", f"{item.name!r} is already the name of {names[item.name]}")
            names[item.name] = key
            paths = (item.name.casefold(), item.name.casefold() + ".pvd",
                     item.name.casefold() + ".vtkhdf")
            for path in paths:
                if path in taken:
                    fail(key + ".name", f"{item.name!r}: its output files would clash with "
                         f"{taken[path]} (case is ignored); choose another name")
            for path in paths:
                taken[path] = f"those of {key}"
        if self.run.mode == "quasi-static":
            for i, b in enumerate(self.bodies):
                if b.motion == "free":
                    fail(f"body[{i}].motion", "'free' is not allowed with run.mode = "
                         "'quasi-static'; use guided, prescribed or fixed")
        if self.contact.model == "half-space":
            if self.run.mode != "quasi-static":
                fail("contact.model", "'half-space' solves quasi-static contacts; set "
                     "run.mode = 'quasi-static'")
            if len(self.surfaces) != 1:
                fail("contact.model", f"'half-space' takes one counter-surface, the scene has "
                     f"{len(self.surfaces)}")
        riders = [(f"{kind}[{i}]", x) for kind, group in (("body", self.bodies),
                                                          ("surface", self.surfaces))
                  for i, x in enumerate(group) if x.mechanism_body is not None]
        if riders and self.mechanism is None:
            fail(riders[0][0] + ".mechanism_body", "there is no [mechanism] table; add one "
                 'with model = "file.xml" (a MuJoCo model)')
        if self.mechanism is not None:
            if not riders:
                fail("mechanism", "no part rides on it; give a body or surface a "
                     "mechanism_body")
            if self.run.mode == "quasi-static":
                fail("run.mode", "'quasi-static' does not apply to a scene with a "
                     "[mechanism]: MuJoCo integrates it in time; use 'dynamic'")
            if self.wear.acceleration == "cycle_jump" and self.wear.period is None:
                fail("wear.period", "missing; 'cycle_jump' with a [mechanism] needs its "
                     "cycle length (a driven crank's turn: 2 pi / speed)")
        if self.wear.acceleration == "cycle_jump" and self.wear.period is None and not any(
                (x.path is not None and x.path.periodic)
                or (getattr(x, "rotation", None) is not None and x.rotation.rate != 0.0)
                for x in self.bodies + self.surfaces):
            fail("wear.period", "missing; 'cycle_jump' needs a cycle length: set wear.period "
                 "or give a path with an oscillation or a circle")


    def set(self, key, value=None):
        """A copy with keys set by their dotted names, checked like a file's.

        ``scene.set("wear.coefficient", 1e-13)`` or ``scene.set({"wear.coefficient":
        1e-13, "body[0].force": [0, 0, -20]})`` (or a sequence of pairs): the names the errors print and
        ``--set`` takes (:func:`set_key`). Values are TOML-like: numbers,
        strings, booleans, lists (numpy arrays and scalars are converted),
        tables as dicts. The settings join :attr:`overrides`.

        Raises
        ------
        SceneError
            Naming the key, for a bad key or value; for a scene built in code
            (``data`` is None: use :func:`dataclasses.replace`).
        """
        values = ([(key, value)] if isinstance(key, str)
                  else list(key.items()) if isinstance(key, dict) else list(key))
        if self.data is None:
            raise SceneError(self.source, values[0][0] if values else "",
                             "this scene was not read from TOML; use dataclasses.replace")
        values = [(k, _plain(v)) for k, v in values]
        data = copy.deepcopy(self.data)
        for k, v in values:
            set_key(data, k, v, self.source)
        scene = parse_scene(data, self.source, self.base_dir)
        object.__setattr__(scene, "overrides", tuple(self.overrides) + tuple(values))
        return scene


def _plain(value):
    """``value`` with numpy arrays and scalars turned into Python lists and numbers."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _check_format(value):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise SceneError("", "format", f"expected the integer {FORMAT}, got {_show(value)}")
    if value != FORMAT:
        raise SceneError("", "format", f"version {value} is not supported; "
                                       f"this meshwear reads format = {FORMAT}")


# ------------------------------------------------------------------ parser

def load_scene(path, overrides=()) -> Scene:
    """Read and validate a scene file.

    Parameters
    ----------
    path : str or os.PathLike
        TOML file; mesh paths in it are relative to its folder.
    overrides : sequence of (key, value)
        Keys to set before validation, by their dotted names (the names the
        errors print: ``wear.coefficient``, ``body[0].force``,
        ``surface[1].path.oscillation.amplitude``); values as parsed TOML
        values (:func:`parse_override` turns ``KEY=VALUE`` text into one).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        Missing or unreadable file, TOML syntax error (key = its line and
        column), or any invalid key or value.
    """
    path = Path(path)
    source = str(path)
    try:
        with open(path, "rb") as file:
            raw = file.read(MAX_SCENE_BYTES + 1)
        if len(raw) > MAX_SCENE_BYTES:
            raise SceneError(source, "", f"larger than {MAX_SCENE_BYTES // 2**20} MiB; a scene "
                                         "file names its meshes, it does not hold them")
        text = raw.decode("utf-8-sig")
    except FileNotFoundError:
        raise SceneError(source, "", "file not found") from None
    except IsADirectoryError:
        raise SceneError(source, "", "is a folder, not a scene file") from None
    except OSError as err:
        raise SceneError(source, "", f"cannot read: {err.strerror or err}") from None
    except UnicodeDecodeError:
        raise SceneError(source, "", "not a UTF-8 text file") from None
    try:
        data = tomllib.loads(text)
    except RecursionError:
        raise SceneError(source, "", "TOML syntax error: tables or lists nested too "
                                     "deeply") from None
    except tomllib.TOMLDecodeError as err:
        message = str(err)
        where = re.search(r"\s*\(at (line \d+, column \d+|end of document)\)$", message)
        location = where.group(1) if where else ""
        message = message[:where.start()] if where else message
        raise SceneError(source, location, f"TOML syntax error: {message}") from None
    for key, value in overrides:
        set_key(data, key, value, source)
    scene = parse_scene(data, source, path.resolve().parent)
    object.__setattr__(scene, "overrides", tuple(overrides))
    return scene


_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?$")


def parse_override(text):
    """``KEY=VALUE`` (the command line's ``--set``) as ``(key, value)``: the
    value is read as a TOML value (``1e-13``, ``[0, 0, -10]``, ``true``,
    ``"archard"``, ``{ axis = [0, 0, 1], rate = 10 }``), or else taken as a
    bare string (``quasi-static``).

    Raises
    ------
    SceneError
        For text without ``=`` or an empty key.
    """
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise SceneError("--set", text, "expected KEY=VALUE, e.g. wear.coefficient=1e-13")
    try:
        parsed = tomllib.loads(f"v = {value.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        parsed = value.strip()
    return key, parsed


def set_key(data, key, value, source="<scene>"):
    """Set ``key`` (dotted, with ``[i]`` for the i-th body or surface) in the
    parsed TOML ``data`` to ``value``, creating the tables on the way.

    Raises
    ------
    SceneError
        Naming the key: an index past the bodies or surfaces there are, or a
        part of the path that is not a table.
    """
    node = data
    parts = key.split(".")
    for n, part in enumerate(parts):
        match = _PART.match(part)
        if not match:
            raise SceneError(source, key, f"--set: {part!r} is not a key name or name[index]")
        name, index = match.group(1), match.group(2)
        last = n == len(parts) - 1
        where = ".".join(parts[:n + 1])
        if not isinstance(node, dict):
            raise SceneError(source, key, f"--set: {'.'.join(parts[:n])} is not a table")
        if index is not None:
            items = node.get(name)
            if not isinstance(items, list) or int(index) >= len(items):
                count = len(items) if isinstance(items, list) else 0
                raise SceneError(source, key, f"--set: there is no {name}[{index}]; the scene "
                                              f"has {count} [[{name}]] table(s)")
            if last:
                items[int(index)] = value
                return
            node = items[int(index)]
        elif last:
            node[name] = value
        else:
            if name not in node:
                node[name] = {}
            node = node[name]
            if not isinstance(node, dict):
                raise SceneError(source, key, f"--set: {where} is not a table")


def parse_scene(data: dict, source: str = "<scene>", base_dir: Path = Path(".")) -> Scene:
    """Validate parsed TOML (a dict of tables) and build the :class:`Scene`.

    Parameters
    ----------
    data : dict
        As returned by ``tomllib``.
    source : str
        Name of the scene in error messages.
    base_dir : path
        Folder that relative mesh paths are resolved against.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
    """
    base_dir = Path(base_dir)
    if not isinstance(data, dict):
        raise SceneError(source, "", f"expected a table of keys, got {_show(data)}")
    if "format" not in data:
        raise SceneError(source, "format", f"missing; a scene file starts with format = {FORMAT}")
    try:
        _check_format(data["format"])
    except SceneError as err:
        raise SceneError(source, err.key, err.message) from None
    _check_keys(source, data, "",
                ("format", "run", "contact", "wear", "body", "surface", "mechanism"))
    tables = {name: _simple(cls, data.get(name, {}), name, source)
              for name, cls in (("run", RunConfig), ("contact", ContactConfig), ("wear", WearConfig))}
    bodies = _array(source, data.get("body", []), "body")
    if not bodies:
        raise SceneError(source, "body", "no bodies; add at least one [[body]] table")
    bodies = [_body(source, base_dir, raw, f"body[{i}]") for i, raw in enumerate(bodies)]
    surfaces = [_surface(source, base_dir, raw, f"surface[{j}]")
                for j, raw in enumerate(_array(source, data.get("surface", []), "surface"))]
    mechanism = None
    if "mechanism" in data:
        table = _table(source, data["mechanism"], "mechanism", MechanismConfig)
        if isinstance(table.get("model"), str):
            table["model"] = base_dir / table["model"]
        mechanism = _build(MechanismConfig, source, "mechanism", table)
    return Scene(format=data["format"], source=source, base_dir=base_dir, bodies=tuple(bodies),
                 surfaces=tuple(surfaces), mechanism=mechanism, data=copy.deepcopy(data),
                 **tables)


def _array(source, value, key):
    """An array of tables; a single table ``[body]`` counts as one."""
    if isinstance(value, dict):
        return [value]
    if not isinstance(value, list):
        raise SceneError(source, key, f"expected [[{key}]] tables, got {_show(value)}")
    return value


def _check_keys(source, table, prefix, allowed, foreign=(), kind=""):
    """Every key of ``table`` must be in ``allowed``; keys in ``foreign`` belong
    to another ``type`` and get a message saying so."""
    for key in table:
        if key in allowed:
            continue
        full = f"{prefix}.{key}" if prefix else key
        if key in foreign:
            raise SceneError(source, full, f"does not apply to {kind}")
        hint = _did_you_mean(key, allowed) or f"; valid keys: {', '.join(allowed)}"
        raise SceneError(source, full, "unknown key" + hint)


def _table(source, value, prefix, cls, allowed=None, foreign=(), kind=""):
    """Check that ``value`` is a table with known keys and the required ones."""
    if not isinstance(value, dict):
        raise SceneError(source, prefix, f"expected a table, got {_show(value)}")
    names = [f.name for f in dataclasses.fields(cls)]
    _check_keys(source, value, prefix, allowed or names, foreign, kind)
    for f in dataclasses.fields(cls):
        if (f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
                and f.name not in value):
            raise SceneError(source, f"{prefix}.{f.name}", "missing (required)")
    return dict(value)


def _build(cls, source, prefix, kwargs):
    """``cls(**kwargs)``, with the error's key prefixed and the file named."""
    try:
        return cls(**kwargs)
    except SceneError as err:
        if err.source:  # raised by a nested table, already complete
            raise
        raise SceneError(source, f"{prefix}.{err.key}", err.message) from None


def _simple(cls, value, prefix, source):
    return _build(cls, source, prefix, _table(source, value, prefix, cls))


def _typed(source, value, prefix, options, default=None):
    """The ``type`` of a table, checked before its other keys."""
    if not isinstance(value, dict):
        raise SceneError(source, prefix, f"expected a table, got {_show(value)}")
    if "type" not in value and default is None:
        raise SceneError(source, f"{prefix}.type", "missing; one of "
                         + ", ".join(repr(o) for o in options))
    try:
        return _choice("type", value.get("type", default), options)
    except SceneError as err:
        raise SceneError(source, f"{prefix}.type", err.message) from None


def _shape(source, value, prefix):
    kind = _typed(source, value, prefix, tuple(SHAPE_KEYS))
    others = {k for keys in SHAPE_KEYS.values() for k in keys} - set(SHAPE_KEYS[kind])
    table = _table(source, value, prefix, ShapeConfig, ("type",) + SHAPE_KEYS[kind], others,
                   f"a {kind} (its keys: {', '.join(SHAPE_KEYS[kind])})")
    return _build(ShapeConfig, source, prefix, table)


def _path(source, value, prefix):
    table = _table(source, value, prefix, PathConfig)
    for key, cls in (("oscillation", Oscillation), ("circle", Circle),
                     ("rotation", RotationConfig)):
        if key in table:
            table[key] = _simple(cls, table[key], f"{prefix}.{key}", source)
    return _build(PathConfig, source, prefix, table)


def _geometry(source, base_dir, table, prefix):
    """Resolve the mesh path and build the shape and path of a body or surface."""
    if isinstance(table.get("mesh"), str):
        table["mesh"] = base_dir / table["mesh"]
    if "shape" in table:
        table["shape"] = _shape(source, table["shape"], f"{prefix}.shape")
    if "path" in table:
        table["path"] = _path(source, table["path"], f"{prefix}.path")
    return table


def _body(source, base_dir, value, prefix):
    table = _geometry(source, base_dir, _table(source, value, prefix, BodyConfig), prefix)
    if isinstance(value, dict) and "mechanism_body" in value:
        for key in ("motion", "density", "mass"):
            if key in value:
                why = ("MuJoCo moves it" if key == "motion"
                       else "its mass is the MuJoCo body's")
                raise SceneError(source, f"{prefix}.{key}", "does not apply to a part on "
                                 f"mechanism body {value['mechanism_body']!r}: {why}")
    return _build(BodyConfig, source, prefix, table)


def _surface(source, base_dir, value, prefix):
    kind = _typed(source, value, prefix, SURFACE_TYPES, default="plane")
    own = SURFACE_KEYS[kind]
    other = {k for keys in SURFACE_KEYS.values() for k in keys} - set(own)
    table = _table(source, value, prefix, SurfaceConfig, ("name", "type") + own, other,
                   f'a type = "{kind}" surface (its keys: {", ".join(own)})')
    table = _geometry(source, base_dir, table, prefix)
    if "rotation" in table:
        table["rotation"] = _simple(RotationConfig, table["rotation"], f"{prefix}.rotation", source)
    return _build(SurfaceConfig, source, prefix, table)
