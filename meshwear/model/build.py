"""The compile of a scene into its :class:`~meshwear.model.state.Model`, and
the state a run starts from (docs/model.md, "Bodies, points and
counter-surfaces").

:func:`build_model` turns a validated :class:`meshwear.scene.Scene` into plain
arrays once, in phases: the parts (meshes loaded and refined, counter-surfaces
made worn or riding on a mechanism), the contact law, the bodies settled at
the start, the time step (:mod:`.timestep`); on the way it refuses what the
engine cannot run (a body placed inside a surface, a load nothing carries),
naming the key. :func:`initial_state` allocates every per-vertex array a run
writes into, so a step allocates no state; :func:`check_time_step` refuses a
step above the stable one before a run starts (here, beside
:func:`initial_state`, whose active sets a mechanism's limit is taken on).
"""

import logging
import math
import dataclasses

import numpy as np

from .. import geometry, surfaces
from . import reach
from ..geometry import remesh
from ..surfaces.margin import contact_margin
from ..contact.elastic import HalfSpace, PatchError
from ..contact.elastic import step as elastic_step
from ..contact.winkler import body_contact
from ..kernels.contact import LAW_SLOTS, all_vertices, make_law, rotation_entries
from ..kernels.laws import code_of
from ..motion.motions import (BalancedMotion, FixedMotion, FreeMotion, GuidedMotion,
                              MechanismMotion, Path, TurningMotion, PrescribedMotion)
from ..scene.checks import SceneError
from .state import BodyModel, BodyState, Model, PartState, State
from .timestep import _even_steps, _stable_limit, _timing, auto_time_step_why, stable_time_step


def build_model(scene):
    """Build the :class:`Model` of a validated scene (meshes loaded here).

    Raises
    ------
    SceneError, geometry.MeshError
        For input the engine cannot use, naming the key.
    """
    # the step count first, from the longest step the run can take (an
    # "auto" one is shorter still): a run too long is refused before any
    # mesh is built or refined
    periods = _periods(scene)
    _timing(scene, scene.wear.period or (max(periods) if periods else None), math.inf)
    mechanism, bodies, surface_set = _build_parts(scene)
    plane_array = surface_set.planes

    run = scene.run
    law, quasi_static, elastic = _contact_law(scene, bodies)
    _settle_bodies(scene, bodies, surface_set, plane_array, law)
    _finish_surfaces(scene, bodies, surface_set, mechanism)
    period, limit, (dt, n_steps, cycle_steps) = _choose_time_step(scene, bodies, surface_set,
                                                                   plane_array, law, mechanism)
    # unbounded surfaces (a plane without a size) are drawn 4 body extents wide
    extent = 4.0 * max(float(np.ptp(b.reference_vertices, axis=0).max()) for b in bodies)
    return Model(scene=scene, bodies=bodies, planes=plane_array, law=law, extent=extent,
                 surfaces=surface_set,
                 quasi_static=quasi_static, dt=dt, n_steps=n_steps, sample_steps=_even_steps(n_steps, run.history),
                 frame_steps=_even_steps(n_steps, run.frames), period=period,
                 cycle_steps=cycle_steps, mechanism=mechanism, elastic=elastic,
                 dt_reason=("run.dt" if run.dt != "auto"
                            else "auto: " + auto_time_step_why(scene, period, limit)[1]))


def _build_parts(scene):
    """``(mechanism, bodies, surface_set)`` of ``scene``: its mechanism (or
    None), its bodies' :class:`BodyModel`, refined where they face the
    surfaces, and its counter-surfaces, refined where the bodies can reach
    them over the run and made worn, riding on the mechanism's bodies."""
    mechanism = None
    if scene.mechanism is not None:
        from ..mechanism.build import Mechanism

        mechanism = Mechanism(scene)
    built = []
    loaded = {}         # the mesh files read, each once
    for j, s in enumerate(scene.surfaces):
        try:
            built.append(surfaces.build_surface(s, mechanism, loaded))
        except geometry.MeshError as err:
            raise SceneError(scene.source, _part_key(f"surface[{j}]", s), str(err)) from None
    # the bodies are refined where they face the surfaces, then the mesh
    # surfaces where the bodies can reach them over the run
    if mechanism is not None:
        for j, (surface, s) in enumerate(zip(built, scene.surfaces)):
            if s.mechanism_body is not None:
                _ride(mechanism, surface, j, s.mechanism_body, 0.0)
    unrefined = surfaces.SurfaceSet(built)
    if mechanism is None:
        _refuse_before_refining(scene, built, unrefined, loaded)
    bodies = _build_bodies(scene, unrefined, mechanism, loaded=loaded)
    for j, (surface, s) in enumerate(zip(built, scene.surfaces)):
        if getattr(s, "resolution", None) is not None and isinstance(surface,
                                                                     surfaces.MeshSurface):
            try:
                built[j] = surface.refined(s, reach.surface_faces_to_refine(
                    scene, surface, bodies, _periods(scene), s.resolution))
            except geometry.MeshError as err:
                raise SceneError(scene.source, _part_key(f"surface[{j}]", s), str(err)) from None
    _make_worn(scene, built, bodies)
    if mechanism is not None:
        # refined or made worn: the riders anew
        mechanism.surfaces = []
        for j, (surface, s) in enumerate(zip(built, scene.surfaces)):
            if s.mechanism_body is not None:
                _ride(mechanism, surface, j, s.mechanism_body, 0.0)
    surface_set = surfaces.SurfaceSet(built)
    return mechanism, bodies, surface_set


def _make_worn(scene, built, bodies):
    """Make the counter-surfaces with ``wear = true`` among ``built`` worn,
    spreading a contact's wear over the area a vertex of ``bodies`` stands for."""
    for j, (surface, s) in enumerate(zip(built, scene.surfaces)):
        if getattr(s, "wear", False):
            if scene.wear.acceleration == "cycle_jump" and scene.wear.jump == "explicit":
                raise SceneError(scene.source, f"surface[{j}].wear",
                                 "a worn counter-surface is cycle-jumped by implicit jumps "
                                 "only; set wear.jump = 'implicit' (the default)")
            surface.make_worn(code_of(s.law or scene.wear.law),
                              scene.wear.coefficient if s.coefficient is None else s.coefficient)
            # a contact wears the area its body vertex stands for
            spacing = max((contact_spacing(b, sb) for b, sb in zip(bodies, scene.bodies)),
                          default=0.0)
            surface.spread_over(SPREAD * spacing, SPREAD_BELOW * spacing)


def _contact_law(scene, bodies):
    """``(law, quasi_static, elastic)``: the contact kernel's (13,) law of
    ``scene`` (no damping without inertia, a Winkler foundation standing in
    for the half-space model until its first solve), whether the run is
    quasi-static, and the half-space model's constants (or None)."""
    c = scene.contact
    (ct, ct_area), (dt_point, dt_area) = c.tangential
    law = make_law(friction=c.friction, static_friction=c.static_friction,
                   wear_law=scene.wear.law, wear_coefficient=scene.wear.coefficient, dt=0.0,
                   stiffness=c.stiffness or 0.0, stiffness_per_area=c.stiffness_per_area or 0.0,
                   damping=c.damping or 0.0, damping_per_area=c.damping_per_area or 0.0,
                   tangential_stiffness=ct or 0.0, tangential_stiffness_per_area=ct_area or 0.0,
                   tangential_damping=dt_point or 0.0,
                   tangential_damping_per_area=dt_area or 0.0)
    quasi_static = scene.run.mode == "quasi-static"
    if quasi_static:  # no inertia, so no damping either
        law[[LAW_SLOTS.index(name) for name in LAW_SLOTS if "damping" in name]] = 0.0
    elastic = None
    if c.model == "half-space":
        elastic = HalfSpace(c.youngs_modulus, c.poissons_ratio, c.friction)
        # the Winkler foundation that stands in until the first solve (the
        # start's placement): E* over a hundredth of the largest body
        size = max(float(np.ptp(b.reference_vertices, axis=0).max()) for b in bodies)
        law[LAW_SLOTS.index("stiffness")] = 0.0
        law[LAW_SLOTS.index("stiffness_per_area")] = elastic.modulus / (0.01 * size)
        law[LAW_SLOTS.index("tangential_stiffness")] = 0.0
        law[LAW_SLOTS.index("tangential_stiffness_per_area")] = law[
            LAW_SLOTS.index("stiffness_per_area")]
    return law, quasi_static, elastic


def _settle_bodies(scene, bodies, surface_set, plane_array, law):
    """Refuse a body placed deep inside a surface, and settle a balanced or
    a turning body on its load at the start (refused if no contact carries it)."""
    for j, (b, config) in enumerate(zip(bodies, scene.bodies)):
        vertex_planes = surfaces.initial_planes(surface_set, b, b.initial_pose, 2.0 * b.radius)[0]
        # where it was placed, before a quasi-static body is settled on its load
        _refuse_deep_start(scene, j, b, config, surface_set, vertex_planes)
        if (isinstance(b.motion, (BalancedMotion, TurningMotion))
                and not b.motion.settle(b.initial_pose, b.reference_vertices, b.area_vectors,
                                        plane_array, vertex_planes,
                                        all_vertices(len(b.reference_vertices)), law)):
            if isinstance(b.motion, TurningMotion):
                raise SceneError(scene.source, f"body[{j}].path.rotation.torque",
                                 f"no contact can carry the torque of body {config.name!r} "
                                 f"about {list(config.path.rotation.axis)} (no surface it "
                                 "touches, turning that way, has a lever about the axis)")
            raise SceneError(scene.source, f"body[{j}].path.free_axis",
                             f"no surface can carry the load of body {config.name!r} along "
                             f"{list(config.path.free_axis)} (the load pulls it off every "
                             "surface, or no surface faces it along that axis)")


def _finish_surfaces(scene, bodies, surface_set, mechanism):
    """The counter-surfaces once the bodies are placed: which turning meshes
    are static in shape, their bounds, and the mechanism's riders in slot order."""
    # a turning mesh is static in shape if it is a surface of revolution
    # about its axis, against the smallest active-set margin
    margin = min(surfaces.margin_of(scene, b) for b in bodies)
    for surface in surface_set.meshes:
        if not getattr(surface, "rider", False):
            surface.settle_invariance(margin)
    surface_set.refresh_bounds()
    if mechanism is not None:
        # slot order: uniform planes first
        slot_of = {id(x): k for k, x in enumerate(surface_set.slots)}
        mechanism.surfaces = [(x, slot_of[id(x)], name, placement)
                              for x, _, name, placement in mechanism.surfaces]
        mechanism.finish()


def _choose_time_step(scene, bodies, surface_set, plane_array, law, mechanism):
    """``(period, limit, (dt, n_steps, cycle_steps))``: the motion's cycle
    (s, or None), the largest stable step (s) and the run's step
    (:mod:`.timestep`), written into ``law`` and the mechanism."""
    run = scene.run
    periods = _periods(scene)
    period = scene.wear.period or (max(periods) if periods else None)
    slots = plane_array.shape[0] + len(surface_set.per_vertex)
    limit = _stable_limit(bodies, law, slots)[0]
    if mechanism is not None:
        mechanism.strict = mechanism.stable_limit(bodies, law, slots)[0]
        limit = min(limit, mechanism.strict)
        limit = min(limit, mechanism.file_timestep) if scene.run.dt == "auto" else limit
    dt, n_steps, cycle_steps = _timing(scene, period, limit)
    law[LAW_SLOTS.index("dt")] = dt
    if mechanism is not None:
        mechanism.set_timestep(dt)
    for key in ("frames", "history"):
        if getattr(run, key) > n_steps + 1:
            # a short run (a trial, a --set run.duration) writes at every step
            logging.getLogger("meshwear").warning(
                "%s: run.%s: %d asked, but the run has %d step times (duration / dt + 1): "
                "writing one at each", scene.source, key, getattr(run, key), n_steps + 1)
    return period, limit, (dt, n_steps, cycle_steps)


def _part_key(prefix, config):
    """The key of a part's mesh: ``mesh``, ``shape`` or ``mechanism_geom``."""
    for key in ("mechanism_geom", "mesh"):
        if getattr(config, key, None) is not None:
            return f"{prefix}.{key}"
    return f"{prefix}.shape"


def _ride(mechanism, surface, index, name, t):
    """Put counter-surface ``surface`` on mechanism body ``name``: its rest
    frame becomes its placement in that body's frame, its motion a steady
    turn and velocity rewritten at every step (:mod:`meshwear.mechanism`)."""
    from ..kernels.rigid import STEADY

    m = surface.motion
    if not getattr(surface, "rider", False):
        # its rest frame in the mechanism body's: rotation row by row, position
        surface.placement = np.concatenate([m.R0.ravel(), m.position])
        m.path.terms = np.zeros((1, 9))
        m.path.terms[0, 0] = STEADY
        surface.rider = True
        surface.invariant = False
        surface._compiled = None
    mechanism.surface_motion(name, surface.placement, t, m.array, m.path.terms)
    mechanism.surfaces.append((surface, index, name, surface.placement))


def _refuse_before_refining(scene, built, unrefined, loaded=None):
    """Before any part is refined, where a mesh surface is to be: a body
    placed inside a surface, and a surface's resolution too fine for this
    machine from the bodies' coarse meshes (their vertices are among the
    refined ones', and the refined ones lie near the faces their resolution
    refines: :func:`meshwear.model.reach.refuse_early`), are refused without
    the bodies' refinement first (a turning shaft's 80 000 faces take
    seconds). The deep-start check is made again once the parts are refined
    (their facets' sag)."""
    refined = [j for j, (surface, s) in enumerate(zip(built, scene.surfaces))
               if getattr(s, "resolution", None) is not None
               and isinstance(surface, surfaces.MeshSurface)]
    if not refined:
        return
    coarse = _build_bodies(scene, unrefined, coarse=True, loaded=loaded)
    for j, (b, config) in enumerate(zip(coarse, scene.bodies)):
        _refuse_deep_start(scene, j, b, config, unrefined, surfaces.initial_planes(
            unrefined, b, b.initial_pose, 2.0 * b.radius)[0])
    # (and the faces each body's resolution surely refines: near them the
    # refined vertices are, where its coarse vertices need not be)
    drawn = [reach.refined_faces(scene, config, b, unrefined)
             for b, config in zip(coarse, scene.bodies)]
    for j in refined:
        s = scene.surfaces[j]
        try:
            reach.refuse_early(scene, built[j], coarse, _periods(scene), s.resolution, drawn)
        except geometry.MeshError as err:
            raise SceneError(scene.source, _part_key(f"surface[{j}]", s), str(err)) from None


def _build_bodies(scene, surface_set, mechanism=None, coarse=False, loaded=None):
    """The :class:`BodyModel` of every body; with ``coarse``, their meshes
    as given (no ``resolution``: no mechanism either); ``loaded``: the mesh
    files read so far (:func:`meshwear.geometry.load_part`)."""
    bodies = []
    for j, b in enumerate(scene.bodies):
        if coarse:
            b = dataclasses.replace(b, resolution=None, resolution_reach=None)
        try:
            bodies.append(_build_body(scene, j, b, surface_set, mechanism, loaded))
        except geometry.MeshError as err:
            # the mesh loader names the mesh file; add the scene file and the key
            raise SceneError(scene.source, _part_key(f"body[{j}]", b), str(err)) from None
    return tuple(bodies)


def _periods(scene):
    """Cycle lengths (s) of the bodies' and mesh surfaces' periodic motions."""
    out = [Path(x.path).period for x in scene.bodies + scene.surfaces
           if getattr(x, "path", None) is not None]
    turns = ([s.rotation for s in scene.surfaces]
             + [b.path.rotation for b in scene.bodies if b.path is not None])
    out += [2.0 * np.pi / abs(r.rate) for r in turns if r is not None and r.rate != 0.0]
    return [p for p in out if p is not None]


def _build_body(scene, index, body, surface_set, mechanism=None, loaded=None):
    key = f"body[{index}]"
    vertices, faces = geometry.load_part(body, mechanism, loaded)
    refinement = None
    if body.resolution is not None:
        vertices, faces, refinement = remesh.refine_part(
            body, vertices, faces,
            reach.faces_to_refine(scene, body, vertices, faces, surface_set))
    needs_inertia = body.motion in ("free", "guided", "mechanism")
    area = geometry.tributary_areas(vertices, faces)
    riding = body.motion == "mechanism"
    try:
        mass, com, inertia = geometry.mass_properties(
            vertices, faces, density=body.density, mass=body.mass,
            source=(str(body.mesh) if body.mesh is not None
                    else _part_key(key, body)))
        if riding:
            # MuJoCo's mass, the mesh's distribution of it (the stability limit)
            scale = mechanism.mass(body.mechanism_body) / mass
            mass, inertia = mass * scale, inertia * scale
    except geometry.MeshError:
        if needs_inertia:
            raise
        # an open mesh that is only moved: its area centroid stands in for the centre of mass
        mass, com, inertia = float("nan"), area @ vertices / area.sum(), np.full((3, 3), np.nan)
    body_vertices = np.ascontiguousarray(vertices - com)

    if scene.wear.direction == "vertex_normal":
        wear_direction = np.ascontiguousarray(-geometry.vertex_normals(body_vertices, faces))
    else:
        wear_direction = np.zeros((0, 3))

    q = np.asarray(body.orientation, float)
    R = np.array(rotation_entries(q)).reshape(3, 3)
    pose = np.zeros(13)
    pose[0:3] = np.asarray(body.position, float) + R @ com
    pose[3:7] = q
    pose[7:10] = body.velocity
    pose[10:13] = body.angular_velocity
    gravity = np.asarray(scene.run.gravity, float)
    with np.errstate(over="ignore"):
        acceleration = gravity + np.asarray(body.force, float) / mass if needs_inertia else gravity
    if not np.all(np.isfinite(acceleration)):
        raise SceneError(scene.source, f"{key}.force",
                         f"{list(body.force)} N on {mass:.3g} kg overflows the acceleration")
    path = Path(body.path)
    if body.motion == "free":
        motion = FreeMotion(mass, inertia, acceleration)
    elif body.path is not None and body.path.rotation is not None \
            and body.path.rotation.torque is not None:
        # a guided body under a torque (the scene allows nothing else)
        if scene.run.mode != "quasi-static":
            raise SceneError(scene.source, f"{key}.path.rotation.torque",
                             "applies in run.mode = \"quasi-static\" only (a dynamic run "
                             "would integrate the turn: give the body a mass and use a "
                             "[mechanism])")
        if scene.contact.model == "half-space":
            raise SceneError(scene.source, f"{key}.path.rotation.torque",
                             "not supported with contact.model = \"half-space\" (its patch "
                             "balances a load along the normal only)")
        motion = TurningMotion(pose[0:3].copy(), path, body.path.rotation.torque)
    elif body.motion == "guided" and scene.run.mode == "quasi-static":
        motion = BalancedMotion(pose[0:3].copy(), path, body.path.free_axis,
                                mass * acceleration @ np.asarray(body.path.free_axis, float))
    elif body.motion == "guided":
        motion = GuidedMotion(pose[0:3].copy(), path, body.path.free_axis, mass, acceleration)
    elif body.motion == "prescribed":
        motion = PrescribedMotion(pose[0:3].copy(), path)
    elif riding:
        motion = MechanismMotion(mass, inertia)
        mechanism.bodies.append((None, index, body.mechanism_body, pose.copy()))
        mechanism.body_pose(body.mechanism_body, pose.copy(), pose)
    else:
        motion = FixedMotion()
    turning = body.path is not None and body.path.rotation is not None
    if turning:
        r = body.path.rotation
        motion.set_turn(q, r.axis, r.rate, r.center)
    motion.place(pose, 0.0)
    if not np.all(np.isfinite(pose)):
        raise SceneError(scene.source, key, "initial pose is not finite")
    vectors = geometry.area_vectors(body_vertices, faces)
    margin, why = (scene.contact.margin, "contact.margin") if scene.contact.margin else \
        contact_margin(scene, body, body_vertices, vectors, pose, motion, surface_set)
    return BodyModel(
        name=body.name, faces=faces, reference_vertices=body_vertices, tributary_area=area,
        area_vectors=vectors, wear_direction=wear_direction,
        reference_face_normals=geometry.face_normals(body_vertices, faces),
        mass=float(mass), inertia=inertia, origin=-com, initial_pose=pose, motion=motion,
        period=path.period, radius=float(np.linalg.norm(body_vertices, axis=1).max()),
        depth_limit=(IMPACT_DEPTH * _thinnest(body_vertices)
                     if motion.dynamic_axes is not None and not riding else 0.0),
        refinement=refinement, margin=float(margin), margin_reason=why)


#: a worn counter-part spreads a contact's wear as far as this many times
#: the spacing of the bodies' vertices that meet it, across the direction
#: it slid in (docs/model.md, "Worn counter-surfaces")
SPREAD = 3.5

#: a worn counter's vertices spread a contact's wear where their edges are
#: on average shorter than this many times the bodies' spacing
SPREAD_BELOW = 2.0


def contact_spacing(body, scene_body):
    """The spacing (m) of the vertices of ``body`` (a :class:`BodyModel`)
    where it meets counter-parts: the median of their shortest edges, over
    the vertices its ``resolution`` refined (those whose shortest edge is
    within it) if it has one, else over all."""
    faces, vertices = body.faces, body.reference_vertices
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    lengths = np.linalg.norm(vertices[edges[:, 0]] - vertices[edges[:, 1]], axis=1)
    shortest = np.full(len(vertices), np.inf)
    np.minimum.at(shortest, edges.ravel(), np.repeat(lengths, 2))
    shortest = shortest[np.isfinite(shortest)]
    resolution = getattr(scene_body, "resolution", None)
    if resolution is not None and (shortest <= resolution).any():
        shortest = shortest[shortest <= resolution]
    return float(np.median(shortest)) if len(shortest) else 0.0


#: a vertex in contact deeper than this fraction of its body's thinnest
#: extent means an impact the contact could not stop (docs/model.md, "Impacts")
IMPACT_DEPTH = 0.25


def _thinnest(vertices):
    """The smallest extent of a body's bounding box (m)."""
    return float(np.ptp(vertices, axis=0).min())


#: an initial penetration deeper than this fraction of the body's smallest
#: extent is taken for a placing mistake (a static sink is microns at most)
START_PENETRATION = 0.01


def _refuse_deep_start(scene, index, body, config, surface_set, vertex_planes):
    """A body placed deep inside a surface would be shot out by its first steps."""
    R = np.array(rotation_entries(body.initial_pose[3:7])).reshape(3, 3)
    x = body.initial_pose[0:3] + body.reference_vertices @ R.T
    allowed = START_PENETRATION * _thinnest(body.reference_vertices)
    depths = [(p, -float(((x - row[0]) @ row[1]).min()))
              for p, row in zip(surface_set.uniform, surface_set.planes)]
    # vertices with no plane under them (zero normal) are not inside
    depths += [(m, -float(np.einsum("ij,ij->i", x - vp[:, 0], vp[:, 1]).min()))
               for m, vp in zip(surface_set.per_vertex, vertex_planes)]
    for p, depth in depths:
        if depth > allowed:
            raise SceneError(scene.source, f"body[{index}].position",
                             f"body {config.name!r} starts {depth:.3g} m inside surface "
                             f"{p.name!r}; place it on or above the surface (a plane's normal, "
                             "and a mesh's face normals, point out of the solid side)")


def initial_state(model):
    """Allocate the :class:`State` of ``model`` at t = 0, with each body's
    active set."""
    S, M = model.slots, len(model.surfaces.per_vertex)
    bodies = []
    for b in model.bodies:
        n = len(b.tributary_area)
        bodies.append(BodyState(
            pose=b.initial_pose.copy(), vertices=b.reference_vertices.copy(),
            wear_depth=np.zeros(n), friction_work=np.zeros(n), wear_volume=np.zeros(n),
            contact_state=np.zeros((S, n), dtype=np.int8),
            tangential=np.zeros((S, n, 4, 3)), normal_force=np.zeros((S, n)),
            vertex_planes=np.zeros((M, n, 3, 3)), hint=np.full((M, n), -1, dtype=np.int64),
            active=all_vertices(n), active_wear=np.zeros(n), cull=np.zeros(surfaces.CULL_SIZE),
            cull_scratch=surfaces.Cull(np.zeros(n), np.zeros((n, 3, 3)) if M else None,
                                       np.full(n, -1, dtype=np.int64))))
    # (implicit cycle jumps relieve each counter vertex by its own stiffness)
    stiffness = bool(model.cycle_steps) and model.scene.wear.jump == "implicit"
    parts = [PartState.unworn(m, stiffness) if m.worn else None
             for m in model.surfaces.per_vertex]
    for m, part in zip(model.surfaces.per_vertex, parts):
        if part is not None:
            m.attach(part)
    state = State(time=0.0, step=0, bodies=bodies, parts=parts)
    model.dynamics.reset(model, state)
    for body, s in zip(model.bodies, state.bodies):
        surfaces.update(model, body, s, 0.0)
    if model.quasi_static:
        # the bodies already sit in balance at t = 0: evaluate their contacts
        # there (at rest, so nothing slips or wears: a step of no duration,
        # even where a surface turns under them), for the t = 0 outputs and
        # the stick anchors the first step starts from
        at_rest = model.law.copy()
        at_rest[LAW_SLOTS.index("dt")] = 0.0
        for body, s in zip(model.bodies, state.bodies):
            s.pose[7:13] = 0.0
            if model.elastic is not None:
                try:
                    elastic_step(model, body, s, 0.0, s.pose[0:3].copy(), at_rest=True)
                except PatchError as err:
                    raise SceneError(model.scene.source, "contact.model", str(err)) from None
                s.pose[7:13] = 0.0
            else:
                body_contact(model, body, s, at_rest)
    return state


def check_time_step(model):
    """Refuse a ``run.dt`` above :func:`~.timestep.stable_time_step`, or one in which a
    dynamic body's starting speed carries it deeper than its ``depth_limit``;
    return the limit.

    Raises
    ------
    SceneError
        Naming ``run.dt`` and the largest stable dt, or ``body[i].velocity``.
    """
    for index, b in enumerate(model.bodies):
        # a step must not carry a body deeper than its contact can stand for
        # before the contact has even seen it (docs/model.md, "Impacts")
        speed = (float(np.linalg.norm(b.initial_pose[7:10]))
                 + float(np.linalg.norm(b.initial_pose[10:13])) * b.radius)
        if b.depth_limit > 0.0 and speed * model.dt > b.depth_limit:
            raise SceneError(model.scene.source, f"body[{index}].velocity",
                             f"body {b.name!r} moves {speed * model.dt:.3g} m in one step of "
                             f"{model.dt:.3g} s, more than {IMPACT_DEPTH:.0%} of its thinnest "
                             f"extent ({b.depth_limit / IMPACT_DEPTH:.3g} m): no contact can "
                             "stop it within the body; lower the speed or run.dt")
    limit, who = stable_time_step(model)
    if model.dt <= limit:
        return limit
    asked = model.scene.run.dt
    rounded = ("" if asked == "auto" or np.isclose(asked, model.dt, rtol=1e-12, atol=0.0)
               else f" (rounded to {model.dt:.6g} s for whole steps per cycle)")
    own = _stable_limit(model.bodies, model.law, model.slots)[0]
    if model.dt <= own:
        # a mechanism's riders: a step above the bound of every vertex
        # pressing at once holds while the vertices within reach of a
        # surface allow it (checked again at every active-set refresh)
        reach, near = model.dynamics.watched_limit(model, initial_state(model))
        if model.dt <= reach:
            logging.getLogger("meshwear").warning(
                "%s: run.dt: %r s%s is above the stability limit of every vertex of the "
                "riders pressing at once (%.6g s) and within that of the vertices within reach "
                "of a surface at the start (%.6g s, body %r): the run checks it at every "
                "active-set refresh and stops (exit 3) if the contact outgrows it",
                model.scene.source, asked, rounded, limit, reach, near)
            return reach
        raise SceneError(model.scene.source, "run.dt",
                         f"{asked!r} s{rounded} is above the stability limit of the contact "
                         f"on body {near!r}; the largest stable dt is {limit:.6g} s with every "
                         f"vertex pressing at once, {reach:.6g} s with the vertices within "
                         "reach of a surface at the start")
    raise SceneError(model.scene.source, "run.dt",
                     f"{asked!r} s{rounded} is above the stability limit of the contact "
                     f"on body {who!r}; the largest stable dt is {limit:.6g} s")
