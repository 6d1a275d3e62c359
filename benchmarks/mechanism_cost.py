"""What the coupling with MuJoCo costs: a coupled step of the slider-crank
(examples/mechanisms/slider_crank.toml) against MuJoCo's step alone plus
meshwear's contact step alone, all measured in the same run.

- coupled: steps of the example in the compiled mechanism loop (MuJoCo's
  split step, the riders placed, the contact of the pin in the bushing, the
  wrenches applied), every step resolved;
- MuJoCo alone: ``mj_step`` of the same model at the same step, called from
  a compiled loop the same way (no contact forces: the rod hangs on its
  hinge);
- contact alone: meshwear's compiled step loop of the same pin against the
  same worn bushing, replaying the poses and motions of coupled steps
  recorded before (every vertex checked, as on a mechanism): the contact
  work of the coupled step without MuJoCo and the coupling.

Prints each in µs per step and vertex-steps/s, and the ratio
coupled / (MuJoCo + contact): the target is at most 1.5.

    .venv/bin/python benchmarks/mechanism_cost.py [--steps N]
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np
from numba import njit

from meshwear.kernels import loop
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import load_scene
from meshwear.step.simulate import run
from meshwear.step import stepper
from meshwear.step.stepper import _body_arrays, _motion_arrays

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "mechanisms" / "slider_crank.toml"


@njit(cache=True)
def _mujoco_steps(step, m, d, n):
    for _ in range(n):
        step(m, d)


@njit(cache=True)
def _replay(k0, dt, poses, rows, terms, pose, row, term, body, motion, planes, surfaces,
            bounds, all_terms, report):
    """meshwear's contact steps of one body at the recorded poses and
    surface motions, one step at a time as the mechanism loop takes them."""
    for j in range(poses.shape[0]):
        pose[:] = poses[j]
        row[:] = rows[j]
        term[:] = terms[j]
        k, what = loop.advance_body(k0 + j, k0 + j + 1, dt, False, False, body, motion, planes,
                                    surfaces, bounds, all_terms, report)


def best_of(repeats, f):
    """Smallest wall time (s) of ``repeats`` calls of ``f``."""
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - start)
    return best


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=4000, help="steps per timing (default 4000)")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    settle = load_scene(SCENE, [("wear.acceleration", "none"), ("run.frames", 0),
                                ("run.history", 2), ("run.duration", 0.02)])
    model = build_model(settle)
    mech, dt, n = model.mechanism, model.dt, args.steps
    state = initial_state(model)
    run(model, state)                               # compiles, and puts the pin in contact

    # coupled: n more steps from there
    def coupled():
        stepper.advance(model, state, state.step + n)

    t_coupled = best_of(args.repeats, coupled) / n

    # MuJoCo alone: mj_step of the same model and step, from a compiled loop
    import mujoco

    step = _mj_step(mujoco)
    m_alone = mech.model
    d_alone = mujoco.MjData(m_alone)
    mujoco.mj_resetDataKeyframe(m_alone, d_alone, mech.keyframe)
    _mujoco_steps(step, m_alone._address, d_alone._address, 10)
    t_mujoco = best_of(args.repeats, lambda: _mujoco_steps(step, m_alone._address,
                                                           d_alone._address, n)) / n

    # contact alone: meshwear's loop replaying the coupled steps' motion (the
    # pin's pose and the bushing's motion at every step, recorded), without
    # MuJoCo: the same contact work, the same moving worn mesh
    surfaces = model.surfaces
    body, s = model.bodies[0], state.bodies[0]
    poses, rows, terms = np.zeros((n, 13)), np.zeros((n, 19)), np.zeros((n, 9))
    k0 = state.step
    for j in range(n):
        poses[j], rows[j], terms[j] = s.pose, mech.rows[0], mech.row_terms[0, 0]
        stepper.advance(model, state, state.step + 1)
    report = np.zeros(2, np.int64)
    args_ = (_body_arrays(model, body, s), _motion_arrays(model, body, s),
             surfaces.compiled_planes(), surfaces.compiled_list(), surfaces.bounds,
             surfaces.terms, report)

    def contact():
        _replay(k0, dt, poses, rows, terms, s.pose, mech.rows[0], mech.row_terms[0, 0], *args_)

    t_contact = best_of(args.repeats, contact) / n
    vertices = len(s.vertices)
    ratio = t_coupled / (t_mujoco + t_contact)
    rows = {"coupled_us": 1e6 * t_coupled, "mujoco_us": 1e6 * t_mujoco,
            "contact_us": 1e6 * t_contact, "ratio": ratio, "vertices": vertices,
            "coupled_vertex_steps_per_s": vertices / t_coupled,
            "contact_vertex_steps_per_s": vertices / t_contact}
    print(f"slider-crank, pin of {vertices} vertices in a bushing of "
          f"{len(surfaces.per_vertex[0].vertices)} vertices, dt {dt:.3g} s, best of "
          f"{args.repeats} x {n} steps")
    print(f"  coupled step         {1e6 * t_coupled:8.2f} µs  "
          f"({vertices / t_coupled:.3g} vertex-steps/s)")
    print(f"  MuJoCo step alone    {1e6 * t_mujoco:8.2f} µs")
    print(f"  contact step alone   {1e6 * t_contact:8.2f} µs  "
          f"({vertices / t_contact:.3g} vertex-steps/s)")
    print(f"  coupled / (MuJoCo + contact) = {ratio:.2f}   (target <= 1.5)")
    print(json.dumps(rows))


def _mj_step(mujoco):
    """MuJoCo's ``mj_step`` as a C function pointer (as the mechanism loop calls it)."""
    import ctypes
    import glob
    import os

    folder = os.path.dirname(mujoco.__file__)
    for pattern in ("libmujoco.so*", "libmujoco*.dylib", "mujoco.dll"):
        for path in sorted(glob.glob(os.path.join(folder, pattern))):
            f = ctypes.CDLL(path).mj_step
            f.argtypes, f.restype = [ctypes.c_void_p, ctypes.c_void_p], None
            return f
    raise SystemExit("MuJoCo's library not found")


if __name__ == "__main__":
    main()
