"""What a scene is and what changes while it runs: the arrays a run holds
(docs/model.md, "Bodies, points and counter-surfaces").

:class:`Model` (frozen) holds everything that does not change while a run
runs: each body's :class:`BodyModel` (reference mesh, areas, mass, motion),
the counter-surfaces, the contact law and the time step. :class:`State`
holds what does: each body's :class:`BodyState` (pose, worn vertices, wear,
contact and friction state) and each worn counter-surface's
:class:`PartState`, every array allocated once, so a step allocates none.
:func:`meshwear.model.build.build_model` makes the one from a scene,
:func:`meshwear.model.build.initial_state` the other. Kernels see only
these arrays.
"""

from dataclasses import dataclass, field

import numpy as np

from ..motion.dynamics import OwnMotions
from ..kernels.nearest import face_frames

#: meshwear's own motions, the dynamics of a model without a mechanism
OWN_MOTIONS = OwnMotions()


@dataclass(frozen=True, eq=False)
class BodyModel:
    """One worn body, in its body frame (origin at the centre of mass, axes of
    the mesh file).

    Attributes
    ----------
    name : str
    faces : (m, 3) int64
    reference_vertices : (n, 3) float
        Unworn vertices, body frame (m).
    tributary_area : (n,) float
        Barycentric vertex areas of the reference mesh (m²).
    area_vectors : (n, 4) float
        Area vectors of the reference mesh and their lengths (m², body frame,
        :func:`meshwear.geometry.area_vectors`): projected on a plane they
        give each vertex's contact area there.
    wear_direction : (n, 3) or (0, 3) float
        Inward vertex normals when wear moves along them, else empty.
    reference_face_normals : (m, 3) float
    mass : float
        kg (nan for fixed or prescribed bodies whose mesh is open).
    inertia : (3, 3) float
        About the centre of mass, body frame (kg·m²).
    origin : (3,) float
        The mesh file's origin in the body frame (m): history's x, y, z.
    initial_pose : (13,) float
    motion : FreeMotion | GuidedMotion | PrescribedMotion | FixedMotion
    period : float or None
        Cycle length of the body's path (s).
    radius : float
        Largest distance of a vertex from the centre of mass (m).
    depth_limit : float
        A body moved by its dynamics (free, guided) stops the run when a
        vertex in contact is deeper than this (m):
        :data:`meshwear.model.build.IMPACT_DEPTH` of its thinnest extent; 0
        for bodies placed by their path.
    refinement : dict or None
        What ``resolution`` did (:func:`meshwear.geometry.remesh.refine_part`).
    margin : float
        Its default active-set margin (m), used where ``contact.margin`` is
        not given, and why (``margin_reason``):
        :func:`meshwear.surfaces.margin.contact_margin`.
    """

    name: str
    faces: np.ndarray
    reference_vertices: np.ndarray
    tributary_area: np.ndarray
    area_vectors: np.ndarray
    wear_direction: np.ndarray
    reference_face_normals: np.ndarray
    mass: float
    inertia: np.ndarray
    origin: np.ndarray
    initial_pose: np.ndarray
    motion: object
    period: float | None
    radius: float = 0.0
    depth_limit: float = 0.0
    refinement: dict | None = None
    margin: float = 0.0
    margin_reason: str = ""


@dataclass(frozen=True, eq=False)
class Model:
    """Everything about a run that does not change while it runs.

    ``surfaces`` (:class:`meshwear.surfaces.SurfaceSet`) holds the
    counter-surfaces in contact-slot order: the uniform planes, whose rows
    form ``planes``, the (P, 4, 3) array the contact kernel takes (point,
    normal, velocity, angular velocity; moving planes are updated in place),
    then the per-vertex ones (slots ``P + j``). ``law`` is the kernel's (13,)
    contact and wear law; ``cull`` says whether bodies keep an active set;
    ``extent`` (m) is the largest body's size, which unbounded surfaces are
    drawn at.
    """

    scene: object
    bodies: tuple
    planes: np.ndarray
    law: np.ndarray
    quasi_static: bool
    dt: float
    n_steps: int
    sample_steps: np.ndarray
    frame_steps: np.ndarray
    period: float | None
    #: steps per cycle when cycles are jumped over, else 0
    cycle_steps: int = 0
    surfaces: object = None
    cull: bool = True
    extent: float = 1.0
    #: the MuJoCo mechanism the riders move with (:mod:`meshwear.mechanism`), or None
    mechanism: object = None
    #: the half-space contact's constants (:class:`meshwear.contact.elastic.HalfSpace`),
    #: or None: the Winkler foundation of ``law``
    elastic: object = None
    #: what set ``dt``: "run.dt", or the limit of ``"auto"`` that did
    #: (:func:`meshwear.model.timestep.auto_time_step_why`)
    dt_reason: str = "run.dt"

    @property
    def dynamics(self):
        """What moves the parts (:mod:`meshwear.motion.dynamics`): the mechanism, or
        meshwear's own motions."""
        return self.mechanism if self.mechanism is not None else OWN_MOTIONS

    def __post_init__(self):
        steps = np.union1d(np.union1d(self.sample_steps, self.frame_steps), [self.n_steps])
        object.__setattr__(self, "output_steps", steps.astype(np.int64))
        object.__setattr__(self, "output_steps_set", set(steps.tolist()))
        object.__setattr__(self, "sample_set", set(self.sample_steps.tolist()))
        object.__setattr__(self, "frame_set", set(self.frame_steps.tolist()))

    @property
    def duration(self):
        return self.n_steps * self.dt

    @property
    def worn_counters(self):
        """Some counter-surface wears."""
        return bool(self.surfaces) and any(m.worn for m in self.surfaces.per_vertex)

    @property
    def slots(self):
        """Number of counter-surfaces: planes, then the per-vertex ones."""
        return self.planes.shape[0] + (len(self.surfaces.per_vertex) if self.surfaces else 0)


@dataclass(eq=False)
class BodyState:
    """What changes for one body; every array is allocated once.

    Attributes
    ----------
    pose : (13,) float
        Centre of mass, quaternion, velocity, angular velocity (world).
    vertices : (n, 3) float
        Worn vertices in the body frame (m).
    wear_depth, friction_work, wear_volume : (n,) float
        ``w`` (m), ``E`` (J) and worn volume (m³) per vertex.
    contact_state : (S, n) int8
        Per counter-surface (planes, then meshes).
    tangential : (S, n, 4, 3) float
        Stick anchor, stick-start force, friction force, last slip velocity.
    normal_force : (S, n) float
    wrench : (6,) float
        Contact force and torque about the centre of mass in the last step.
    vertex_planes : (M, n, 3, 3) float
        Per per-vertex surface (analytic or mesh), the plane under each
        active vertex.
    hint : (M, n) int64
        Per mesh surface, the face under each vertex at the last query (-1: none).
    active : (k,) int64
        The vertices within reach of a surface (:mod:`meshwear.surfaces`).
    active_wear : (k,) float
        Their wear depth when the active set was last refreshed.
    cull : (9,) float
        Margin, time and pose of the last active-set refresh.
    """

    pose: np.ndarray
    vertices: np.ndarray
    wear_depth: np.ndarray
    friction_work: np.ndarray
    wear_volume: np.ndarray
    contact_state: np.ndarray
    tangential: np.ndarray
    normal_force: np.ndarray
    wrench: np.ndarray = field(default_factory=lambda: np.zeros(6))
    vertex_planes: np.ndarray = None
    hint: np.ndarray = None
    active: np.ndarray = None
    active_wear: np.ndarray = None
    cull: np.ndarray = None
    cull_scratch: object = None
    #: (5, n) each vertex's total normal force (N), total squared normal
    #: force (N²) and total force vector along the normals (N, world) added
    #: up over the steps since they were last zeroed, kept while cycles are
    #: jumped over (:data:`meshwear.longrun.jumps.LOAD_ROWS`); else (2, 0)
    load: np.ndarray = field(default_factory=lambda: np.zeros((2, 0)))
    #: (1,) how much nearer (m) the body may come to a surface before its
    #: deepest vertex in contact has to be measured again against its
    #: ``depth_limit`` (docs/model.md, "Impacts"); 0: at the next step
    impact_room: np.ndarray = field(default_factory=lambda: np.zeros(1))
    #: the pairs' shares of the worn counter-surfaces' vertices, logged
    #: over a measured cycle for implicit jumps (:func:`meshwear.longrun.jumps.pair_log`):
    #: rows (surface, vertex, counter vertex) and the pair's normal force on
    #: the counter vertex (N), the rows used and whether to log (0 rows: not kept)
    log_index: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int64))
    log_value: np.ndarray = field(default_factory=lambda: np.zeros(0))
    log_count: np.ndarray = field(default_factory=lambda: np.zeros(2, np.int64))
    #: the step from which the log holds every pair (-1: none)
    log_from: int = -1
    #: the half-space solve kept from step to step (:class:`meshwear.contact.elastic.Patch`;
    #: a cache, not saved in checkpoints), or None
    elastic: object = None


@dataclass(eq=False)
class PartState:
    """What wear changes on a worn mesh counter-surface (its own frame).

    Attributes
    ----------
    vertices : (V, 3) float
        Worn vertices (m).
    frames : (F, 4, 4) float
        Their faces' frames (:func:`meshwear.kernels.nearest.face_frames`).
    depth, volume, work : (V,) float
        Wear depth (m), worn volume (m³) and friction work (J) per vertex.
    added, touched, limit, due, count : (V,) float, (V,) int64, (V,) float, (V,) int64, (1,) int64
        Each vertex's lag (the depth it took since it last moved), the
        lagging vertices (``count`` of them), the lag at which each moves and
        scratch (:func:`meshwear.kernels.counter_wear.wear_counter`); none lag
        between two stretches of steps
        (:func:`meshwear.step.counters.settle_counters`).
    stiffness : (V,) or (0,) float
        How much each vertex's wear falls per unit of its own depth, summed
        over the steps since it was zeroed (kept for implicit cycle jumps;
        (0,): not kept).
    place : (V,) int64
        Where each lagging vertex is in ``touched``, -1 for the others.
    pending, pending_list, pending_place, pending_count : (9, F) float, (F,) int64, (F,) int64, (1,) int64
        What waits on each face to be spread over the vertices around it
        (volume, energy, penetration, direction of sliding and contact point
        times volume), the faces with some, each one's place
        among them and their count (a spreading part:
        :func:`meshwear.kernels.counter_wear.wear_counter`); nothing waits
        between two stretches of steps.
    """

    vertices: np.ndarray
    frames: np.ndarray
    depth: np.ndarray
    volume: np.ndarray
    work: np.ndarray
    added: np.ndarray
    touched: np.ndarray
    limit: np.ndarray
    due: np.ndarray
    count: np.ndarray
    stiffness: np.ndarray = field(default_factory=lambda: np.zeros(0))
    place: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    pending: np.ndarray = field(default_factory=lambda: np.zeros((9, 0)))
    pending_list: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    pending_place: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    pending_count: np.ndarray = field(default_factory=lambda: np.zeros(1, np.int64))

    @classmethod
    def unworn(cls, surface, stiffness=False):
        """The unworn state of ``surface``; ``stiffness``: keep each vertex's."""
        n = len(surface.reference_vertices)
        return cls(vertices=surface.reference_vertices.copy(),
                   frames=face_frames(surface.reference_vertices, surface.faces),
                   depth=np.zeros(n), volume=np.zeros(n), work=np.zeros(n), added=np.zeros(n),
                   touched=np.zeros(n, np.int64), limit=np.full(n, np.inf),
                   due=np.zeros(n, np.int64), count=np.zeros(1, np.int64),
                   stiffness=np.zeros(n if stiffness else 0), place=np.full(n, -1, np.int64),
                   pending=np.zeros((9, len(surface.faces))),
                   pending_list=np.zeros(len(surface.faces), np.int64),
                   pending_place=np.full(len(surface.faces), -1, np.int64),
                   pending_count=np.zeros(1, np.int64))


@dataclass(eq=False)
class State:
    """Where a run is: ``step`` steps of ``dt`` represented (``time``), the
    bodies' state, the last step whose outputs are written, the cycle
    jumping's bookkeeping (:class:`meshwear.longrun.wear.JumpState`, or None) and
    whether the state was reached by steps (``resolved``) or by a jump."""

    time: float
    step: int
    bodies: list
    written: int = -1
    jump: object = None
    #: False from a cycle jump until the next step: the state is extrapolated
    resolved: bool = True
    #: per per-vertex surface, its :class:`PartState` if it wears, else None
    parts: list = field(default_factory=list)
