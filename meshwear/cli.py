"""Command line: ``meshwear run | check | demo | sweep | export | plot | info``.

Exit codes: 0 ok, 2 bad input (one line on stderr naming the file and key),
3 numerically invalid run (every output written so far stays valid), 1 a
sweep with failed runs.
"""

import argparse
import logging
import math
import sys
import time
from pathlib import Path

EXIT_OK, EXIT_INPUT, EXIT_NUMERICAL = 0, 2, 3
#: a sweep finished with failed runs (each a row of sweep.csv with its message)
EXIT_FAILED_RUNS = 1
#: a run stopped by SIGTERM or Ctrl-C at a checkpoint (128 + the signal's number)
EXIT_TERMINATED, EXIT_INTERRUPTED = 143, 130


#: numpy's floating-point warnings (turned into errors by :func:`exit_path`)
FLOATING_POINT = r"(overflow|divide by zero|invalid value|underflow) encountered"


class InputError(Exception):
    """Bad input found by the CLI itself (one line)."""


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="meshwear", description="Wear of rigid triangle-mesh bodies, as VTK time series.")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("run", help="run a scene and write the ParaView series")
    p.add_argument("scene", help="scene file (TOML, format 1)")
    p.add_argument("-o", "--out", default=None, help="output folder (default: out/<scene name>)")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bar, no line on compiling kernels")
    p.add_argument("--resume", action="store_true",
                   help="continue the stopped run in OUT from its last checkpoint")
    _set_option(p)
    p.add_argument("--checkpoint-every", type=float, default=60.0, metavar="SECONDS",
                   help="save a checkpoint at most this often (wall clock; default 60, 0: as "
                        "often as possible)")
    p = sub.add_parser("check", help="validate a scene and estimate its cost")
    p.add_argument("scene")
    _set_option(p)
    p = sub.add_parser("demo", help="run the built-in demo scene")
    p.add_argument("-o", "--out", default="out/demo")
    p.add_argument("-q", "--quiet", action="store_true")
    p = sub.add_parser("sweep", help="run a scene over a grid or list of key values on Dask")
    p.add_argument("scene", nargs="?", default=None,
                   help="scene file (TOML; or scene = ... in the sweep file)")
    p.add_argument("--vary", action="append", default=[], metavar="KEY=[V1, V2, ...]",
                   help="a key and its values (repeatable): wear.coefficient=[1e-13, 2e-13]")
    p.add_argument("-f", "--file", default=None, metavar="SWEEP",
                   help="sweep file (TOML: scene, mode, [values] KEY = [...])")
    p.add_argument("--mode", choices=("grid", "list"), default=None,
                   help="every combination of the values (grid, default) or the i-th of each "
                        "(list)")
    p.add_argument("-o", "--out", default=None,
                   help="output folder (default: out/<scene name>_sweep)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="a running Dask scheduler (default: a LocalCluster on this machine)")
    p.add_argument("--workers", type=int, default=None,
                   help="LocalCluster processes (default: one per core; 0: one run after "
                        "another in this process)")
    p = sub.add_parser("export", help="write the worn parts of a run as STL, PLY or OBJ")
    p.add_argument("out", help="the run's output folder")
    p.add_argument("--part", action="append", default=[], metavar="NAME",
                   help="a worn body or surface (repeatable; default: all of them)")
    p.add_argument("--frame", type=int, default=-1,
                   help="frame number (0 the first, default -1 the last)")
    p.add_argument("--format", default="stl", choices=("stl", "ply", "obj"))
    p.add_argument("--units", default="m", help="units of the written files (m, mm, cm, um, in)")
    p.add_argument("-d", "--dest", default=None,
                   help="folder for the files (default: the output folder)")
    p = sub.add_parser("plot", help="draw a run's wear maps, profiles and histories as PNG")
    p.add_argument("out", help="the run's output folder")
    p.add_argument("--part", action="append", default=[], metavar="NAME",
                   help="a worn body or surface (repeatable; default: all of them)")
    p.add_argument("--profile", metavar="X0,Y0,Z0:X1,Y1,Z1", default=None,
                   help="wear profile under the line between two points (m, the part's own "
                        "frame), as PNG and CSV; write --profile=... if it starts with '-'")
    p.add_argument("--view", metavar="X,Y,Z", default=None,
                   help="direction the wear maps look from (the part's own frame; default: "
                        "onto the worn faces, or along the axis they face round, as a gear's)")
    p.add_argument("-d", "--dest", default=None,
                   help="folder for the files (default: OUT/plots)")
    p = sub.add_parser("info", help="describe a mesh file")
    p.add_argument("mesh")
    p.add_argument("--units", default="m", help="units of the mesh file (m, mm, cm, um, in)")
    args = parser.parse_args(argv)
    for stream in (sys.stdout, sys.stderr):   # µ, ³ and the like on an ASCII terminal
        if hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="replace")

    def command():
        if args.command in ("run", "demo", "check") and not getattr(args, "quiet", False):
            # a first run compiles its kernels: say so (docs/performance.md)
            from .kernels.notice import CompileNotice

            with CompileNotice() as notice:
                code = steps()
            if notice.done():
                print(notice.done(), file=sys.stderr)
            return code
        return steps()

    def steps():
        if args.command == "run":
            if not args.checkpoint_every >= 0:  # NaN too
                raise InputError(f"--checkpoint-every: must be a number >= 0, got "
                                 f"{args.checkpoint_every:g}")
            return _run(args.scene, args.out, args.quiet, args.resume, args.checkpoint_every,
                        _overrides(args.set))
        if args.command == "demo":
            from importlib.resources import files

            scene = files("meshwear") / "data" / "demo.toml"
            return _run(str(scene), args.out, args.quiet)
        if args.command == "check":
            return _check(args.scene, _overrides(args.set))
        if args.command == "export":
            return _export(args)
        if args.command == "sweep":
            return _sweep(args)
        if args.command == "plot":
            return _plot(args)
        return _info(args.mesh, args.units)

    return exit_path(command)


def exit_path(command):
    """Run ``command()`` and return its exit code, mapping what it raises to
    the command line's codes with one line on stderr: bad input 2, a
    numerically invalid run 3, Ctrl-C 130. numpy's floating-point warnings
    are errors inside it (never printed): an overflow while the scene is read
    and the model built is the scene's fault (2), one in a run the run's (3)."""
    import warnings

    from .geometry.meshes import MeshError
    from .output.export import ExportError
    from .scene.checks import SceneError
    from .step.simulate import NumericalError

    global _notices
    outer, _notices = _notices, _Notices()
    logger = logging.getLogger("meshwear")
    logger.addHandler(_notices)
    propagate, logger.propagate = logger.propagate, False
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("error", FLOATING_POINT, RuntimeWarning)
            code = command()
        _notices.show()
        return code
    except (SceneError, MeshError, InputError, ExportError) as err:
        return _fail(f"meshwear: error: {err}", EXIT_INPUT)
    except NumericalError as err:
        return _fail(f"meshwear: run stopped: {err}", EXIT_NUMERICAL)
    except (ArithmeticError, RuntimeWarning) as err:  # overflow, division by zero
        if _notices.holding:      # the scene is still being read: a figure of it is to blame
            return _fail(f"meshwear: error: numbers out of range ({err}): a value of the scene "
                         "is too large or too small for double precision", EXIT_INPUT)
        return _fail(f"meshwear: run stopped: numbers out of range ({err}): the run left "
                     "double precision's range", EXIT_NUMERICAL)
    except MemoryError:
        return _fail("meshwear: error: out of memory; the scene asks for more than this "
                     "machine has (fewer steps, frames or faces)", EXIT_INPUT)
    except KeyboardInterrupt:
        return _fail("meshwear: interrupted; the outputs written so far are valid",
                     EXIT_INTERRUPTED)
    except BrokenPipeError:               # `meshwear info x | head`
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    finally:
        logger.removeHandler(_notices)
        logger.propagate = propagate
        _notices = outer


def _fail(line, code):
    print(line, file=sys.stderr)
    return code


class _Notices(logging.Handler):
    """meshwear's log records (a mesh cleaned, outputs fewer than asked),
    held until the input is known good (:meth:`show`, once the model is
    built) and then printed as ``meshwear: ...`` lines on stderr; dropped
    when the command fails on its input, so that a refusal is one line."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.held, self.holding = [], True

    def emit(self, record):
        if self.holding:
            self.held.append(record)
        else:
            print(f"meshwear: {record.getMessage()}", file=sys.stderr)

    def show(self):
        self.holding = False
        for record in self.held:
            self.emit(record)
        self.held = []


#: the notices of the command running (:func:`exit_path`)
_notices = _Notices()


def _set_option(parser):
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="set a scene key over the file's, by its dotted name "
                             "(wear.coefficient=1e-13, body[0].force=[0,0,-20]); repeatable")


def _overrides(texts):
    from .scene.reader import parse_override

    return tuple(parse_override(text) for text in texts)


def _prepare(scene_path, overrides=()):
    from .model.build import build_model, check_time_step
    from .scene.reader import load_scene

    scene = load_scene(scene_path, overrides)
    model = build_model(scene)
    limit = check_time_step(model)
    _notices.show()
    return scene, model, limit


def _run(scene_path, out, quiet, resume=False, checkpoint_every=60.0, overrides=()):
    from .longrun import checkpoint
    from .model.build import initial_state
    from .output.folder import FolderBusy
    from .output.recorder import RunRecorder, summary
    from .step.simulate import NumericalError, run

    scene, model, _ = _prepare(scene_path, overrides)
    out_dir = Path(out) if out else Path("out") / Path(scene_path).stem
    state = initial_state(model)
    wall_before = 0.0
    if resume:
        wall_before = checkpoint.load(out_dir / checkpoint.FILE_NAME, model, state)
    saver = checkpoint.Checkpointer(out_dir, checkpoint_every, wall_before)
    try:
        recorder = RunRecorder(out_dir, model, resume_until=state.time if resume else None,
                               state=state)
    except FolderBusy as err:
        raise InputError(str(err)) from None
    except OSError as err:  # e.g. -o names an existing file, or a folder we may not write
        raise InputError(f"{err.filename or out_dir}: output folder: cannot write there "
                         f"({err.strerror or err})") from None
    except ValueError as err:  # resuming into files that are not this run's, or damaged
        raise InputError(f"{out_dir}: cannot resume: {err}") from None
    if not resume:
        saver.remove()   # a checkpoint of an earlier run in OUT no longer applies
    if resume and not quiet:
        print(f"resuming at t = {state.time:.6g} s (step {state.step} of {model.n_steps})")
    progress = (None if quiet else _ProgressBar(model) if sys.stderr.isatty()
                else _ProgressLines(model, state))
    stopping = _StopRequests(saver)
    try:
        with stopping:
            run(model, state, observers=[recorder], progress=progress, checkpoint=stopping)
    except _Stopped as stop:
        if progress:
            progress.finish()
        status, code = ("terminated", EXIT_TERMINATED) if stop.terminated else ("interrupted",
                                                                               EXIT_INTERRUPTED)
        recorder.close(summary(model, state, saver.wall_time, status,
                               f"{status} at t = {state.time:.6g} s"))
        print(f"meshwear: {status} at t = {state.time:.6g} s (step {state.step} of "
              f"{model.n_steps}); checkpoint saved: continue with "
              f"meshwear run {scene_path} -o {out_dir} --resume", file=sys.stderr)
        return code
    except KeyboardInterrupt:
        if progress:
            progress.finish()
        recorder.close(summary(model, state, saver.wall_time, "interrupted",
                               f"interrupted at t = {state.time:.6g} s"))
        raise
    except OSError as err:  # the disk filled up, or the folder went away, mid-run
        if progress:
            progress.finish()
        message = (f"{err.filename or out_dir}: cannot write the outputs "
                   f"({err.strerror or err}); those written before t = {state.time:.6g} s "
                   "are kept")
        try:  # summary.json says so, where it still can be written
            recorder.close(summary(model, state, saver.wall_time, "write_error", message))
        except OSError:
            pass
        raise InputError(message) from None
    except NumericalError as err:
        if progress:
            progress.finish()
        recorder.close(summary(model, state, saver.wall_time, "numerical_error", str(err)))
        print(f"meshwear: run stopped: {err}; the outputs up to t = {state.time:.6g} s are in "
              f"{out_dir}", file=sys.stderr)
        return EXIT_NUMERICAL
    if progress:
        progress.finish()
    elapsed = saver.wall_time
    recorder.close(summary(model, state, elapsed))
    saver.remove()
    if not quiet:
        print(f"done in {elapsed:.1f} s: {model.n_steps} steps, "
              f"{len(model.frame_steps)} frames")
        suffix = "." + scene.run.series
        for body in model.bodies:
            print(f"  ParaView series: {out_dir / (body.name + suffix)}")
        for surface in model.surfaces.slots:
            print(f"  surface: {out_dir / (surface.name + suffix)}")
        print(f"  history: {out_dir / 'history.csv'}, summary: {out_dir / 'summary.json'}")
    return EXIT_OK


def _check(scene_path, overrides=()):
    import numpy as np

    from .geometry.remesh import describe_refinement

    started = time.perf_counter()        # the estimate's trial answers within 30 s of this
    scene, model, limit = _prepare(scene_path, overrides)
    print(f"scene {scene.source}: ok (format 1, mode {scene.run.mode})")
    for key, value in overrides:
        print(f"  set {key} = {value!r}")
    for b, config in zip(model.bodies, scene.bodies):
        mass = f"{b.mass:.6g} kg" if np.isfinite(b.mass) else "n/a (open mesh, not integrated)"
        print(f"  body {b.name!r}: {len(b.tributary_area)} contact points, {len(b.faces)} faces, "
              f"mass {mass}, motion {config.motion}")
        turn = config.path.rotation if config.path is not None else None
        if turn is not None and turn.torque is not None:
            print(f"    turning at {turn.rate:g} rad/s about {list(turn.axis)} through "
                  f"{list(turn.center)}, in balance under {turn.torque:g} N·m (settled at the "
                  f"start by {1e3 * b.motion.settled:.4g} mrad)")
        if b.refinement:
            print(f"    {describe_refinement(b.refinement)}")
        print(f"    active-set margin {b.margin:.3g} m: {b.margin_reason}")
    for surface, config in zip(model.surfaces.slots, _slot_configs(scene, model)):
        print(f"  {_surface_summary(surface, config)}, {surface.describe()}")
        if getattr(surface, "refinement", None):
            print(f"    {describe_refinement(surface.refinement)}")
    stable = (f"largest stable dt {limit:.3g} s" if np.isfinite(limit)
              else "no stability limit (quasi-static)" if model.quasi_static
              else "no stability limit (nothing integrated in time)")
    if model.dt_reason != "run.dt":
        stable += f"; {model.dt_reason}"
    print(f"  dt {model.dt:.3g} s, {stable}, {model.n_steps} steps, "
          f"{len(model.frame_steps)} frames, {len(model.sample_steps)} history rows")
    from .model.build import initial_state

    state = initial_state(model)        # describe reads it, the estimate steps it
    for line in model.dynamics.describe(model, state):
        print(f"  {line}")
    if model.elastic is not None:
        from .contact.elastic import describe

        lines, warnings = describe(model, state)
        for line in lines:
            print(f"  {line}")
        for line in warnings:
            logging.getLogger("meshwear").warning("%s: %s", scene.source, line)
    if model.cycle_steps:
        cycles = model.n_steps / model.cycle_steps
        print(f"  cycle jumping: {model.cycle_steps} steps per cycle, {cycles:.6g} cycles, "
              f"{scene.wear.jump} jumps, tolerance {scene.wear.tolerance:g}; outputs inside "
              "jumps are filled from them")
    from .geometry.remesh import spacing_notices

    for line in spacing_notices(model, state):
        print(f"  notice: {line}")
    from .step.estimate import estimate_run

    e = estimate_run(model, state, started)
    full = "" if not model.cycle_steps else (
        "with cycle jumping " if e.trial_covered >= model.n_steps else
        f"with cycle jumps growing as in a {e.trial_time:.2g} s trial " if e.trial_jumps else
        f"with cycle jumps (none yet in a {e.trial_time:.2g} s trial of "
        f"{e.trial_covered / model.cycle_steps:.2g} cycles: a rough guess) ")
    print(f"  estimated run time {full}{e.total:.3g} s: stepping {e.stepping:.3g} s "
          f"({e.per_step * 1e6:.3g} µs per step, {e.points / e.per_step:.3g} vertex-steps/s; "
          f"{e.active} of {e.vertices} vertices within reach of a surface), "
          f"writing {e.writing:.3g} s ({len(model.frame_steps)} frames, "
          f"{len(model.sample_steps)} history rows)")
    if e.cycles:
        (low, high), (cycles, few, many) = e.range, e.cycles
        print(f"  run time range with cycle jumping {low:.3g}–{high:.3g} s ({high / low:.2g}x), "
              f"{few:.4g}–{many:.4g} of {model.n_steps / model.cycle_steps:.6g} cycles resolved "
              f"(estimate {cycles:.4g}): the jumps after the trial from the fastest to the "
              "slowest trend its bounded jumps allow")
    return EXIT_OK


def _slot_configs(scene, model):
    """The scene's ``[[surface]]`` tables in the model's contact-slot order."""
    by_name = {s.name: s for s in scene.surfaces}
    return [by_name[s.name] for s in model.surfaces.slots]


def _surface_summary(surface, config):
    """``plane 'floor': point [..], normal [..]`` and the like."""
    kind = config.type
    if kind == "plane":
        return (f"plane {surface.name!r}: point {list(config.point)}, "
                f"normal {list(config.normal)}")
    if kind == "mesh":
        return (f"mesh surface {surface.name!r}: {len(surface.vertices)} vertices, "
                f"{len(surface.faces)} faces")
    if kind == "cylinder":
        length = f"length {config.length:g} m" if config.length else "infinite"
        return (f"cylinder {surface.name!r} ({config.side}): radius {config.radius:g} m, axis "
                f"{list(config.axis)} through {list(config.point)}, {length}")
    return (f"sphere {surface.name!r} ({config.side}): radius {config.radius:g} m, "
            f"centre {list(config.center)}")


def _sweep(args):
    from .sweep import from_arguments, run_sweep

    if args.workers is not None and args.workers < 0:
        raise InputError(f"--workers: must be >= 0, got {args.workers}")
    sweep = from_arguments(args.scene, args.vary, args.file, args.mode)
    if not sweep.scene.is_file():
        raise InputError(f"{sweep.scene}: scene file not found")
    out = Path(args.out) if args.out else Path("out") / f"{sweep.scene.stem}_sweep"
    runs = sweep.runs()
    print(f"sweep of {sweep.scene}: {len(runs)} runs ({sweep.mode} of "
          f"{', '.join(sweep.keys)}) into {out}")
    start = time.perf_counter()
    rows = run_sweep(sweep, out, args.scheduler, args.workers,
                     report=lambda line: print(f"  {line}", flush=True))
    failed = sum(row["status"] != "ok" for row in rows)
    print(f"done in {time.perf_counter() - start:.1f} s: {len(rows) - failed} ok, {failed} "
          f"failed; table: {out / 'sweep.csv'}")
    return EXIT_OK if not failed else EXIT_FAILED_RUNS


def _export(args):
    from .output.export import export

    for path in export(args.out, args.part, args.frame, args.format, args.units, args.dest):
        print(path)
    return EXIT_OK


def _plot(args):
    from .output.plots import plot

    line = None
    if args.profile is not None:
        bad = InputError(f"--profile {args.profile}: expected two points x0,y0,z0:x1,y1,z1 (m)")
        try:
            line = [[float(v) for v in point.split(",")] for point in args.profile.split(":")]
        except ValueError:
            raise bad from None
        if len(line) != 2 or any(len(point) != 3 for point in line):
            raise bad
    view = None
    if args.view is not None:
        bad = InputError(f"--view {args.view}: expected a direction x,y,z, not zero")
        try:
            view = [float(v) for v in args.view.split(",")]
        except ValueError:
            raise bad from None
        if len(view) != 3 or not all(math.isfinite(v) for v in view) or not any(view):
            raise bad
    for path in plot(args.out, args.part, args.dest, line, view):
        print(path)
    return EXIT_OK


def _info(mesh_path, units):
    from .geometry.properties import mesh_info

    info = mesh_info(mesh_path, units)
    for key, value in info.items():
        print(f"{key}: {value}")
    return EXIT_OK


class _Stopped(Exception):
    """The run stopped at a checkpoint on SIGTERM or Ctrl-C."""

    def __init__(self, terminated):
        super().__init__("terminated" if terminated else "interrupted")
        self.terminated = terminated


class _StopRequests:
    """SIGTERM (what batch schedulers send) and Ctrl-C ask the run to stop at
    its next consistent state (where it may save a checkpoint): there a
    checkpoint is saved and :class:`_Stopped` raised. A second Ctrl-C stops
    at once (the outputs written so far stay valid, without a checkpoint).
    Used as the run's ``checkpoint`` hook, wrapping the :class:`Checkpointer`."""

    def __init__(self, saver):
        self.saver, self.requested, self.terminated = saver, False, False
        self._previous = {}

    def __enter__(self):
        import signal

        for number in (signal.SIGTERM, signal.SIGINT):
            try:
                self._previous[number] = signal.signal(number, self._handle)
            except ValueError:                # not the main thread: leave them be
                pass
        return self

    def __exit__(self, *exc):
        import signal

        for number, handler in self._previous.items():
            signal.signal(number, handler)

    def _handle(self, number, frame):
        import signal

        if self.requested and number == signal.SIGINT:
            raise KeyboardInterrupt
        self.requested = True
        self.terminated = self.terminated or number == signal.SIGTERM

    def __call__(self, model, state):
        if self.requested:
            from .longrun.checkpoint import save

            save(self.saver.path, model, state, self.saver.wall_time)
            raise _Stopped(self.terminated)
        self.saver(model, state)


class _ProgressLines:
    """Plain progress lines on stderr when it is not a terminal (nohup, batch
    jobs, notebooks): one every :data:`LINE_SECONDS` of wall time."""

    #: seconds between two lines
    LINE_SECONDS = 30.0

    def __init__(self, model, state=None):
        self.model, self.state, self.start = model, state, time.perf_counter()
        self.written = self.start

    def __call__(self, step, n_steps):
        now = time.perf_counter()
        if now - self.written < self.LINE_SECONDS or step >= n_steps:
            return
        self.written = now
        done = step / max(n_steps, 1)
        elapsed = now - self.start
        eta = f"{elapsed / done - elapsed:.0f} s" if done > 0 else "--"
        # with cycle jumping, the last jump and what bounded it: a long run
        # whose jumps stay short says why
        js = getattr(self.state, "jump", None)
        jumps = ("" if js is None else
                 f", last jump {js.last_jump} cycles ({js.last_limit or 'none yet'})")
        print(f"meshwear: {100 * done:.1f} % t = {step * self.model.dt:.6g} s "
              f"(step {step} of {n_steps}), {elapsed:.0f} s elapsed, eta {eta}{jumps}",
              file=sys.stderr, flush=True)

    def finish(self):
        pass


class _ProgressBar:
    """One line on stderr, redrawn at most four times a second."""

    def __init__(self, model, width=30):
        self.model, self.width, self.start = model, width, time.perf_counter()
        self.drawn = -1.0

    def __call__(self, step, n_steps):
        now = time.perf_counter()
        if now - self.drawn < 0.25 and step < n_steps:
            return
        self.drawn = now
        done = step / max(n_steps, 1)
        elapsed = now - self.start
        eta = f"{elapsed / done - elapsed:5.0f} s" if done > 0 else "   -- s"
        bar = "#" * int(done * self.width)
        sys.stderr.write(f"\r[{bar:<{self.width}}] {100 * done:5.1f}%  "
                         f"t = {step * self.model.dt:.4g} s  eta {eta} ")
        sys.stderr.flush()

    def finish(self):
        sys.stderr.write("\n")


if __name__ == "__main__":
    sys.exit(main())
