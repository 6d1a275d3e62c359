"""The fuzz corpus: bad and extreme inputs made by mutating the example
scenes key by key and their meshes, and the probe that puts one through
scene loading, model building, the outputs' set-up and a few steps, the
way ``meshwear run`` does (its exit path included).

Used by tests/test_fuzz.py (Hypothesis draws from it, within a minute) and
by ``make fuzz`` (``python -m tests.fuzzing``: every case, with a count of
the clean ones)::

    .venv/bin/python -m tests.fuzzing [--scenes pin_on_disc cube_toss] [--limit N]
    .venv/bin/python -m tests.fuzzing --limits     # the extreme cases of LIMIT_CASES only

:data:`LIMIT_CASES` are extreme resolutions and sizes on every kind of
surface (turning, worn, on a mechanism's body, the elastic half-space), put
through ``meshwear check`` (:func:`check_probe`): each is refused with one
line naming its key within a second, before any heavy work.
:data:`ANSWER_CASES` are extreme sizes it accepts, each answered within its
time.

A case is clean when it ends with exit 0 and nothing on stderr but
``meshwear:`` notices (a valid input), or with exit 2 or 3 and exactly one
``meshwear:`` line on stderr, within a second for a refusal; anything else (a traceback, a warning, a second line, a hang) is a
finding.
"""

import argparse
import contextlib
import io
import math
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
#: example scenes small enough to probe many times (seconds each, at most)
SCENES = ("pin_on_disc", "cube_toss", "reciprocating_block", "sphere_on_flat_fretting",
          "pin_on_worn_disc", "pin_on_turning_disc", "validation/flat_pin",
          "validation/jenkins_quasi_static", "block_on_ring")
#: steps a probe takes (the rest of a run is the same loop)
PROBE_STEPS = 20

HUGE, TINY = 1.7e308, 5e-324
#: values put in place of any key
SCALARS = (0, -1, -0.0, 1, 0.5, math.nan, math.inf, -math.inf, 1e308, -1e308, 1e-308,
           TINY, 1e-300, 1e21, 2 ** 63, -(2 ** 70), True, "", "x" * 300, "nan", "../x",
           "checkpoint.npz", [], {}, [1.0, 2.0], [[1.0]], {"a": 1})
#: values put in place of a list of numbers
VECTORS = ([0.0, 0.0, 0.0], [HUGE, HUGE, HUGE], [math.nan, 0.0, 0.0], [1e-320, 0.0, 0.0],
           [1.0, 2.0], [1.0, 0.0, 0.0, 0.0], ["a", 1.0, 2.0], [HUGE] * 4,
           [-1e308, 1e308, 0.0], [1e300, 1e300, 1e300], [0.0, 0.0, 1e-300])


def leaf_keys(data, prefix=""):
    """Every leaf key of parsed TOML ``data`` by its dotted name (the names
    ``--set`` takes: ``body[0].path.circle.radius``), with its value."""
    for key, value in data.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            yield from leaf_keys(value, name + ".")
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for i, item in enumerate(value):
                yield from leaf_keys(item, f"{name}[{i}].")
        else:
            yield name, value


def scene_cases(stems=SCENES):
    """``(scene path, key, value)`` for every key of every scene and every
    value of :data:`SCALARS` (and :data:`VECTORS` for a list of numbers)."""
    for stem in stems:
        path = EXAMPLES / f"{stem}.toml"
        data = tomllib.loads(path.read_text())
        for key, value in leaf_keys(data):
            values = SCALARS + (VECTORS if isinstance(value, list) else ())
            for bad in values:
                yield path, key, bad


def mesh_cases():
    """``(name, bytes)`` of broken and extreme mesh files:
    terms: truncated, garbage, bad indices, extreme coordinates."""
    good = (ROOT / "meshes" / "cube_20mm.stl").read_bytes()
    tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
    return [
        ("empty.stl", b""),
        ("truncated.stl", good[: len(good) // 2]),
        ("garbage.stl", bytes(range(256)) * 8),
        ("garbage.obj", b"\x00\xff" * 500),
        ("zero_index.obj", (tri + "f 0 1 2\nf 1 2 3\n").encode()),
        ("far_index.obj", (tri + "f 1 2 99\n").encode()),
        ("negative_index.obj", (tri + "f -9 1 2\n").encode()),
        ("huge.obj", ("v 1e308 0 0\nv -1e308 0 0\nv 0 1e308 0\nv 0 0 1e308\n"
                      "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n").encode()),
        ("nan.obj", ("v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                     "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n").encode()),
        ("flat.obj", (tri.replace("v 0 0 1", "v 1 1 0") + "f 1 2 3\nf 1 3 4\n").encode()),
        ("one_face.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ("no_faces.obj", tri.encode()),
        ("text.ply", b"ply\nformat ascii 1.0\nelement vertex 99\nend_header\n1 2 3\n"),
    ]


#: extreme resolutions and sizes on every kind of surface: ``(kind, scene,
#: overrides[, key named])``, each refused by ``meshwear check`` (exit 2, one
#: line naming the key, by default the part of the first one) within a second (docs/outputs.md, "Limits checked before
#: any work"). "turning": a mesh surface turning under a body; "worn": a
#: worn mesh surface, refined where the bodies reach it; "mechanism": parts
#: on MuJoCo bodies; "half-space": the elastic half-space contact
LIMIT_CASES = (
    ("turning", "pin_on_turning_disc", (("surface[0].resolution", 1e-5),)),
    ("turning", "pin_on_turning_disc", (("surface[0].resolution", 1e-9),)),
    ("turning", "pin_on_turning_disc", (("surface[0].resolution", TINY),)),
    ("turning", "pin_on_turning_disc", (("body[0].resolution", 1e-9),)),
    ("turning", "pin_on_turning_disc", (("body[0].shape.radius", 1.0),)),
    ("turning", "pin_on_turning_disc", (("run.dt", 1e-300),)),
    ("turning", "gear_pair", (("surface[0].resolution", 1e-7),)),
    ("turning", "gear_pair", (("run.duration", 1e300),)),
    ("worn", "pin_on_worn_disc", (("surface[0].resolution", 1e-6),)),
    ("worn", "pin_on_worn_disc", (("surface[0].resolution", 1e-300),)),
    ("worn", "pin_on_worn_disc", (("surface[0].shape.height", 1e6),), "body[0].position"),
    ("worn", "pin_on_worn_disc", (("run.dt", 1e-300),)),
    ("worn", "cylinder_on_worn_flat", (("surface[0].resolution", 1e-7),)),
    ("worn", "cylinder_on_worn_flat", (("body[0].shape.height", 10.0),)),
    ("worn", "shaft_in_worn_bushing", (("surface[0].resolution", 1e-6),)),
    ("worn", "shaft_in_worn_bushing", (("surface[0].resolution", 1e-6),
                                       ("body[0].resolution", 1e-4))),
    ("worn", "shaft_in_worn_bushing", (("body[0].shape.sections", 100_000),)),
    ("mechanism", "mechanisms/pendulum_in_bushing", (("surface[0].resolution", 1e-5),)),
    ("mechanism", "mechanisms/pendulum_in_bushing", (("body[0].resolution", 1e-9),)),
    ("mechanism", "mechanisms/pin_on_disc", (("surface[0].resolution", 1e-6),)),
    ("mechanism", "mechanisms/pin_on_disc", (("body[0].shape.radius", 10.0),)),
    ("mechanism", "mechanisms/gear_pair_torque", (("body[0].resolution", 1e-7),)),
    ("mechanism", "mechanisms/slider_crank", (("run.dt", 1e-300),)),
    ("half-space", "validation/hertz_ball", (("body[0].resolution", 1e-7),)),
    ("half-space", "validation/hertz_ball", (("body[0].resolution", 1e-6),
                                             ("body[0].resolution_reach", 1.0))),
    ("half-space", "validation/hertz_ball", (("body[0].shape.radius", 10.0),)),
    ("half-space", "validation/hertz_ball", (("run.duration", 1e300),)),
    ("half-space", "sphere_on_flat_fretting_elastic", (("body[0].resolution", 1e-7),)),
    ("half-space", "sphere_on_flat_fretting_elastic", (("body[0].shape.radius", 10.0),)),
    ("half-space", "validation/hertz_ball", (("body[0].shape.radius", 1e-6),), "contact.model"),
    ("half-space", "sphere_on_flat_fretting_elastic", (("body[0].shape.radius", 1e-9),),
     "contact.model"),
)

#: extreme sizes ``meshwear check`` accepts: ``(kind, scene, overrides,
#: seconds)``, each answered with exit 0 (notices only) within its seconds
#: (docs/outputs.md, "Limits checked before any work"): a turning disc of
#: 100 000 sections (400 000 faces, its caps fans of slivers) gave no answer
#: in ten minutes
ANSWER_CASES = (
    ("turning", "pin_on_turning_disc", (("surface[0].shape.sections", 100_000),), 30.0),
)


class Outcome:
    """What a probe did: ``code`` (0, 2, 3, or None for an escaped
    exception), ``stderr``, ``seconds``, ``error`` (the escaped exception)."""

    def __init__(self, code, stderr, seconds, error=None):
        self.code, self.stderr, self.seconds, self.error = code, stderr, seconds, error

    @property
    def clean(self):
        lines = self.stderr.splitlines()
        if self.error is not None:
            return False
        if self.code == 0:        # a valid input: its notices only
            return all(line.startswith("meshwear: ") and "Warning" not in line
                       for line in lines)
        return self.code in (2, 3) and len(lines) == 1 and lines[0].startswith("meshwear: ")

    def __repr__(self):
        what = (f"{type(self.error).__name__}: {self.error}" if self.error is not None
                else self.stderr.strip()[:300])
        return f"exit {self.code} in {self.seconds:.2f} s: {what}"


def probe(scene_path, overrides=(), steps=PROBE_STEPS):
    """One input through what ``meshwear run`` does first, in this process:
    load, build, the dt check, the outputs' set-up and first frame, and
    ``steps`` steps, inside the command line's exit path."""
    from meshwear import cli

    def work():
        from meshwear.step import stepper
        from meshwear.model.build import initial_state
        from meshwear.output.recorder import RunRecorder

        scene, model, _ = cli._prepare(scene_path, overrides)
        state = initial_state(model)
        with tempfile.TemporaryDirectory() as out:
            recorder = RunRecorder(Path(out) / "run", model)
            recorder.on_frame(model, state)
            stepper.advance(model, state, min(model.n_steps, steps))
            from meshwear.step.simulate import check
            check(model, state, [b.reference_face_normals for b in model.bodies])
            recorder.finish()
        return 0

    stderr = io.StringIO()
    start = time.perf_counter()
    try:
        with contextlib.redirect_stderr(stderr):
            code = cli.exit_path(work)
    except BaseException as err:  # noqa: BLE001 - a finding, reported
        return Outcome(None, stderr.getvalue(), time.perf_counter() - start, err)
    return Outcome(code, stderr.getvalue(), time.perf_counter() - start)


def check_probe(scene_path, overrides=()):
    """One input through ``meshwear check`` in this process (its exit path
    included, its report dropped), timed: an :class:`Outcome`."""
    from meshwear import cli

    stderr = io.StringIO()
    start = time.perf_counter()
    try:
        with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
            code = cli.exit_path(lambda: cli._check(str(scene_path), tuple(overrides)))
    except BaseException as err:  # noqa: BLE001 - a finding, reported
        return Outcome(None, stderr.getvalue(), time.perf_counter() - start, err)
    return Outcome(code, stderr.getvalue(), time.perf_counter() - start)


def limit_refused(outcome, case, seconds=1.0):
    """Whether a case of :data:`LIMIT_CASES` ended as it must: exit 2 with
    one line naming its key, within ``seconds``."""
    named = case[3] if len(case) > 3 else case[2][0][0].split(".")[0]
    return (outcome.code == 2 and outcome.clean and named in outcome.stderr
            and outcome.seconds <= seconds)


def check_limits(cases=LIMIT_CASES, seconds=1.0, answers=ANSWER_CASES):
    """Every case of :data:`LIMIT_CASES` and :data:`ANSWER_CASES` through
    :func:`check_probe` twice (the first loads or compiles the kernels its
    path calls: the second is timed); ``[(kind, scene, overrides, outcome,
    as it must)]``."""
    out = []
    for case in tuple(cases) + tuple(answers):
        kind, stem, overrides = case[:3]
        path = EXAMPLES / f"{stem}.toml"
        check_probe(path, overrides)
        outcome = check_probe(path, overrides)
        ok = (limit_refused(outcome, case, seconds) if case in cases else
              outcome.code == 0 and outcome.clean and outcome.seconds <= case[3])
        out.append((kind, stem, overrides, outcome, ok))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description="run the fuzz corpus, count clean cases")
    parser.add_argument("--scenes", nargs="*", default=list(SCENES))
    parser.add_argument("--start", type=int, default=0, help="first case (0-based)")
    parser.add_argument("--limit", type=int, default=None, help="cases at most")
    parser.add_argument("-v", "--verbose", action="store_true", help="name each case first")
    parser.add_argument("--slow", type=float, default=1.0,
                        help="seconds beyond which a refused case counts as slow")
    parser.add_argument("--limits", action="store_true",
                        help="the extreme cases of LIMIT_CASES only")
    args = parser.parse_args(argv)
    limits = check_limits(seconds=args.slow)
    for kind, stem, overrides, outcome, ok in limits:
        print(f"{'ok  ' if ok else 'FAIL'} {kind} {stem} {dict(overrides)}: {outcome!r}"[:300])
    print(f"{sum(ok for *_, ok in limits)} of {len(limits)} extreme cases refused by check "
          f"within {args.slow:g} s, or answered within their time")
    if args.limits:
        return 0 if all(ok for *_, ok in limits) else 1
    cases = list(scene_cases(args.scenes))[args.start:][: args.limit]
    clean = slow = 0
    findings = {}
    start = time.perf_counter()
    for n, (path, key, value) in enumerate(cases, 1):
        if args.verbose:
            print(f"{n - 1 + args.start}: {path.stem} {key} = {value!r}"[:200], file=sys.stderr,
                  flush=True)
        outcome = probe(path, ((key, value),))
        ok = outcome.clean
        if ok and outcome.code != 0 and outcome.seconds > args.slow:
            slow += 1
            ok = False
        clean += ok
        if not ok:
            kind = (type(outcome.error).__name__ if outcome.error is not None
                    else f"exit {outcome.code}, {len(outcome.stderr.splitlines())} lines")
            findings.setdefault(kind, []).append((path.stem, key, value, outcome))
        if n % 100 == 0:
            print(f"  {n} of {len(cases)}: {clean} clean", file=sys.stderr, flush=True)
    with tempfile.TemporaryDirectory() as folder:
        for name, content in mesh_cases():
            mesh = Path(folder) / name
            mesh.write_bytes(content)
            outcome = probe(EXAMPLES / "cube_toss.toml", (("body[0].mesh", str(mesh)),))
            cases.append(mesh)
            if outcome.clean:
                clean += 1
            else:
                findings.setdefault("mesh", []).append(("cube_toss", "mesh", name, outcome))
    for kind, items in sorted(findings.items()):
        print(f"{kind}: {len(items)}")
        for stem, key, value, outcome in items[:60]:
            shown = repr(value)[:40]
            print(f"  {stem} {key} = {shown}: {outcome!r}"[:400])
    print(f"{clean} of {len(cases)} cases clean ({slow} slow refusals) in "
          f"{time.perf_counter() - start:.0f} s")
    return 0 if clean == len(cases) and all(ok for *_, ok in limits) else 1


if __name__ == "__main__":
    sys.exit(main())
