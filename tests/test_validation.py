"""The validation cases of tests/cases.py (also the rows of docs/validation.md)
at the tolerances of docs/validation.md."""

import pytest

import cases


@pytest.fixture(scope="module", params=cases.ALL, ids=lambda f: f.__name__)
def case(request):
    return request.param()


def test_validation_case_within_tolerance(case, measured):
    for row in case.rows:
        measured(f"{row.quantity}", row.measured, row.closed_form, row.tolerance)
    failed = [(r.quantity, r.measured, r.closed_form, r.error) for r in case.rows if not r.ok]
    assert not failed, failed


def test_fretting_example_sticks_inside_the_partial_slip_radius(measured):
    """examples/sphere_on_flat_fretting.toml: the points that never dissipate
    form a disc of radius c = sqrt(2 R (delta - s / mu)) (to within one ring of
    vertices), and the wear is a ring outside it."""
    import dataclasses

    import numpy as np

    from meshwear.kernels.contact import rotation_entries
    from meshwear.scene.reader import load_scene
    from meshwear.step.simulate import run_scene

    scene = load_scene(cases.EXAMPLES / "sphere_on_flat_fretting.toml")
    scene = dataclasses.replace(scene, run=dataclasses.replace(scene.run, frames=0, duration=0.15,
                                                                 history=4))
    model, state, _ = run_scene(scene)
    body, s = model.bodies[0], state.bodies[0]
    R = np.array(rotation_entries(s.pose[3:7])).reshape(3, 3)
    x = s.pose[0:3] + s.vertices @ R.T
    touching = s.contact_state[0] > 0
    radius = np.linalg.norm(x[:, 0:2] - x[touching, 0:2].mean(axis=0), axis=1)
    radius_ball = scene.bodies[0].shape.radius
    load = body.mass * 9.81 + 10.0
    delta = np.sqrt(load / (np.pi * scene.contact.stiffness_per_area * radius_ball))
    stroke, mu = scene.bodies[0].path.oscillation.amplitude, scene.contact.friction
    c = np.sqrt(2 * radius_ball * (delta - stroke / mu))
    spacing = 1.05 * radius_ball * 2 ** -6   # edge of the level-6 icosphere
    stuck = touching & (s.friction_work == 0.0)
    measured("fretting stick radius (m)", radius[stuck].max(), c, spacing / c)
    assert abs(radius[stuck].max() - c) < spacing
    assert np.all(s.wear_depth[radius < c - spacing] == 0.0)
    assert s.wear_depth[touching & (radius > c + spacing)].min() > 0.0
