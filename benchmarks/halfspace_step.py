"""What a resolved step of the half-space contact model costs against the Winkler step.

A polymer ball (R = 10 mm, E = 3 GPa) pressed by 10 N on a steel flat: a
Hertz contact 0.28 mm in radius, its mesh refined to 5 µm there, so that
about 10⁴ vertices carry load. Three motions, each run with
``[contact] model = "half-space"`` and, in the same run, with the Winkler
foundation whose contact has the same radius (K = P / (pi R delta²),
delta = a² / 2R; the compiled step loop):

- sliding: a steady slide (gross slip; the normal solve is kept while the
  gaps change by less than its tolerance),
- fretting: +-0.5 of the gross-slip stroke, 40 steps a cycle, partial
  slip (a shear solve every step of the first cycle),
- fretting with wear: the same, worn (the normal solve taken again as the
  scar grows);
- fretting, repeated: the unworn fretting's steps in its third cycle (a
  periodic stroke on an unchanged pressure reuses its tangential solves
  once its turning points repeat: the first loading's turning point is a
  loop's to 1.5e-3 of mu p, so from the third cycle on).

Prints, per motion, the steps' median time for both models, their ratio
and vertex-steps/s (vertices in contact per second), then one JSON line.

    .venv/bin/python benchmarks/halfspace_step.py [--steps 40]
"""

import argparse
import json
import time

import numpy as np

from meshwear.step import stepper
from meshwear.contact.halfspace import contact_modulus
from meshwear.model.build import build_model, initial_state
from meshwear.scene.reader import parse_scene

E_BALL, E_FLAT, NU, R, LOAD, MU = 3e9, 210e9, 0.35, 0.01, 10.0, 0.4


def scene(model, path, wear=0.0):
    e_star = contact_modulus((E_BALL, E_FLAT), (NU, 0.3))
    a = (3.0 * LOAD * R / (4.0 * e_star)) ** (1.0 / 3.0)
    if model == "half-space":
        contact = {"model": "half-space", "youngs_modulus": [E_BALL, E_FLAT],
                   "poissons_ratio": [NU, 0.3]}
    else:
        delta = a * a / (2.0 * R)
        contact = {"stiffness_per_area": LOAD / (np.pi * R * delta * delta)}
    contact.update(friction=MU, margin=2e-5)
    data = {
        "format": 1,
        "run": {"mode": "quasi-static", "duration": 1.0, "dt": 1e-3, "frames": 0,
                "history": 2, "gravity": [0.0, 0.0, 0.0]},
        "contact": contact,
        "wear": {"law": "energy_density", "coefficient": wear},
        "body": [{"name": "ball", "shape": {"type": "sphere", "radius": R, "subdivisions": 5},
                  "resolution": 5e-6, "resolution_reach": 1.2e-5, "mass": 0.01,
                  "position": [0.0, 0.0, R], "force": [0.0, 0.0, -LOAD], "motion": "guided",
                  "path": dict(path, free_axis=[0.0, 0.0, 1.0])}],
        "surface": [{"name": "flat", "type": "plane", "size": 0.004}],
    }
    return parse_scene(data), a


def timed(scene_, steps, skip=5):
    """Median time (s) of ``steps`` steps after the first ``skip`` (the
    kernels compiled or loaded, the first solves), the vertices in contact,
    the model and the state."""
    model = build_model(scene_)
    state = initial_state(model)
    stepper.advance(model, state, skip)
    times = []
    for k in range(steps):
        start = time.perf_counter()
        stepper.advance(model, state, skip + 1 + k)
        times.append(time.perf_counter() - start)
    pressed = int((state.bodies[0].normal_force > 0.0).sum())
    return float(np.median(times)), pressed, model, state


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=40)
    args = parser.parse_args()
    e_star = contact_modulus((E_BALL, E_FLAT), (NU, 0.3))
    a = (3.0 * LOAD * R / (4.0 * e_star)) ** (1.0 / 3.0)
    g_term = 2.0 * (1.0 + NU) * (2.0 - NU) / E_BALL + 2.0 * 1.3 * 1.7 / E_FLAT
    gross = 3.0 * MU * LOAD * g_term / (16.0 * a)
    motions = {
        "sliding": ({"velocity": [0.01, 0.0, 0.0]}, 0.0),
        "fretting": ({"oscillation": {"axis": [1.0, 0.0, 0.0], "amplitude": 0.5 * gross,
                                      "frequency": 25.0}}, 0.0),
        "fretting, worn": ({"oscillation": {"axis": [1.0, 0.0, 0.0], "amplitude": 0.5 * gross,
                                            "frequency": 25.0}}, 1e-12),
    }
    #: steps before the timed ones: a repeated cycle of an unworn fretting
    #: contact reuses its tangential solves (docs/model.md, "In a run")
    skips = {"fretting, repeated": 95}
    motions["fretting, repeated"] = motions["fretting"]
    print(f"Hertz radius {a * 1e3:.3f} mm, gross-slip stroke {gross * 1e6:.3f} µm")
    print(f"{'motion':>19}{'vertices':>10}{'half-space (ms)':>17}{'Winkler (ms)':>14}"
          f"{'ratio':>8}{'half-space v-steps/s':>22}")
    rows = []
    for name, (path, wear) in motions.items():
        skip = skips.get(name, 5)
        elastic, pressed, model, state = timed(scene("half-space", path, wear)[0], args.steps,
                                               skip)
        winkler, pressed_w, _, _ = timed(scene("winkler", path, wear)[0], args.steps, skip)
        patch = state.bodies[0].elastic
        row = {"motion": name, "vertices": pressed, "winkler_vertices": pressed_w,
               "half_space_ms": 1e3 * elastic, "winkler_ms": 1e3 * winkler,
               "ratio": elastic / winkler, "vertex_steps_per_s": pressed / elastic,
               "grid": list(patch.grid.shape), "normal_solves": patch.solves}
        rows.append(row)
        print(f"{name:>19}{pressed:>10}{row['half_space_ms']:>17.2f}{row['winkler_ms']:>14.2f}"
              f"{row['ratio']:>8.2f}{row['vertex_steps_per_s']:>22.3g}")
    print(json.dumps({"benchmark": "halfspace_step", "rows": rows}))


if __name__ == "__main__":
    main()
