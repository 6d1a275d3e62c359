"""The elastic half-space contact model in a run (docs/model.md, "Elastic half-space").

With ``[contact] model = "half-space"`` a quasi-static body's contact
forces come from the elastic solve of :mod:`meshwear.contact.halfspace` instead of
a spring per vertex. At each step, for each body and its counter-surface:

1. Gaps. The body is placed on its path; each vertex facing the surface
   gets its gap ``h_i`` along the contact normal (negative: the rigid
   bodies overlap), as the Winkler kernel measures it.
2. The patch. The vertices within a band of gaps above the smallest span a
   regular grid in the tangent plane (cells of about one vertex's
   contact area, axes fixed to the body, the first along its path's
   stroke). The vertices' Delaunay triangles interpolate the gaps onto the
   cells, linearly. Back on the vertices (:mod:`meshwear.contact.cellfields`),
   the grid's fields are read at each vertex's point, bilinearly between
   the four cell centres around it: its pressure; its force is that
   pressure times its contact area, all scaled alike so that the vertices
   carry exactly the solved load (the same for the shear and the friction
   energy).
3. Normal. A guided body's load gives the load-controlled solve, its
   approach the body's move along its free axis (the load balance); a
   prescribed or fixed body's overlap gives the displacement-controlled
   one. The solve starts from the last pressure. It is skipped while the
   gaps have changed by less than :data:`RESOLVE` of the elastic approach
   since it was last taken (the body's rigid moves excepted): a body
   sliding on a plane changes its gaps only by its wear.
4. Tangential. A translation along the grid's first axis, the same at
   every point (a fretting stroke, a straight slide), is Cattaneo-Mindlin
   partial slip with Mindlin and Deresiewicz's reversals, solved at the
   stroke's displacement (:func:`meshwear.contact.halfspace.shear_at_shift`) on the
   window of pressed cells (merged f x f where wider than
   :data:`meshwear.contact.elastic_patch.SHEAR_CELLS`): stick and slip
   per cell, each cell's slip and friction energy from its shear and the
   relative displacement of the surfaces. Any other relative motion (a
   turning disc, a circle) slides: Coulomb at every vertex, ``mu N_i``
   against its slip velocity.
5. Wear. Each vertex's energy (the cells' energy density at its point
   times its area, scaled to the cells' total), load and slip go through
   the wear law (:mod:`meshwear.kernels.laws`)
   and the vertex moves as in the Winkler kernel.

The state of the solve (:class:`Patch`) is a cache: a run resumed from a
checkpoint solves it again (a fretting cycle then restarts its
Mindlin-Deresiewicz branch from the shear the wear left).

This module owns the step (the normal solve and its band, the load
balance, the wear) and what the rest of a run reads from a patch (check's
lines, the pressure written out, the penetrations of a cycle jump, what a
worn counter wears by). The patch and its grid (steps 1 and 2, the fields
at the vertices) are :mod:`meshwear.contact.elastic_patch`'s; the
tangential problem (step 4) is :mod:`meshwear.contact.elastic_friction`'s.
"""

from dataclasses import dataclass

import numpy as np

from . import halfspace
from .elastic_friction import _tangential
from .elastic_patch import (Patch, PatchError, _build_patch, _drop_grid, _locate, _new_pressure,
                            _spread, _stroke, pair_geometry)
from ..kernels.contact import FORCE as FORCE_SLOT
from ..kernels.contact import NO_CONTACT, SLIP
from ..kernels.laws import LAWS, name_of
from ..motion.motions import BalancedMotion, _perpendicular
from ..surfaces.base import quaternion_matrix

#: the normal problem is solved again when the gaps changed (rigid moves
#: aside) by more than this fraction of the elastic approach
RESOLVE = 1e-3
#: the relative tolerance of the normal conjugate-gradient solve (the
#: traction's change in an iteration), taken seldom (the tangential one's:
#: :data:`meshwear.contact.elastic_friction.SHEAR_TOLERANCE`)
TOLERANCE = 1e-8
#: the band of gaps the first patch spans, in vertices of smallest gap
FIRST_BAND_VERTICES = 64
#: the band of gaps a patch spans is the elastic approach over this (the
#: contact lies where the gap is below the approach; the rest is margin) ...
BAND_USE = 0.7
#: ... and a patch is built again when the approach passes this fraction of
#: its band, or falls below the next
GROW_BAND, SHRINK_BAND = 0.9, 0.3
#: contact normals of a patch spreading wider than this (rad) are not a
#: half-space contact: check warns ...
WARN_SPREAD = 0.1
#: ... and the run refuses beyond this
REFUSE_SPREAD = 0.5


@dataclass(frozen=True)
class HalfSpace:
    """The model's elastic constants: Young's moduli (Pa) and Poisson's
    ratios of the worn bodies and of the counter-surfaces, and the friction
    coefficient."""

    youngs: tuple
    poisson: tuple
    friction: float

    @property
    def modulus(self):
        """The contact modulus E* (Pa)."""
        return halfspace.contact_modulus(self.youngs, self.poisson)


def step(model, body, s, t, before, at_rest=False):
    """One quasi-static step of ``body`` (state ``s``) at ``t`` with the
    elastic half-space, after :func:`meshwear.step.simulate._quasi_static_step`
    placed it on its path (``before``: its position at the step's start)
    and updated its surfaces: normal and tangential tractions, the load
    balance, wear. Fills the same state arrays as the Winkler kernel. ``at_rest``:
    a step of no duration (the t = 0 state): nothing slips or wears."""
    elastic = model.elastic
    motion = body.motion
    active = s.active
    gap, n, area, r, velocity = pair_geometry(model, body, s, active)
    if at_rest:
        velocity[:] = 0.0
    patch = s.elastic
    if patch is not None and patch.written is not None:
        # the last step's contacts: this step writes its own
        w = patch.written
        s.normal_force[0, w] = 0.0
        s.tangential[0, w, FORCE_SLOT] = 0.0
        s.contact_state[0, w] = NO_CONTACT
        patch.written = None
    s.wrench[:] = 0.0
    balanced = isinstance(motion, BalancedMotion)
    hmin = float(gap.min()) if len(gap) else np.inf
    if not np.isfinite(hmin):
        if balanced:
            raise PatchError(f"body {body.name!r}: no contact carries its load at t = {t:.6g} s")
        return
    if patch is None:
        normal = n[np.argmin(gap)].copy()
        stroke = _stroke(motion)
        e1 = _perpendicular(normal, stroke)
        patch = s.elastic = Patch(e1=e1, e2=np.cross(normal, e1), normal=normal)
        patch.extra.update(youngs=elastic.youngs, poisson=elastic.poisson)
    beta = float(motion.axis @ patch.normal) if balanced else 1.0
    if balanced and beta <= 0.1:
        raise PatchError(f"body {body.name!r}: its free axis is "
                         f"{np.degrees(np.arccos(max(beta, -1.0))):.0f}° from the contact normal; "
                         "the half-space model balances the load along the normal (give "
                         "free_axis along it)")
    load = motion.carried / beta if balanced else None
    take, heights, shift_move = _solve_normal(body, s, t, patch, active, gap, n, area, r, hmin,
                                              balanced, load)
    # from here on, the vertices that carry load only
    on = patch.loaded
    idx = patch.index[on]
    F = patch.forces[on]
    at = take[on]
    approach = patch.approach + shift_move
    velocity = velocity[at]
    if balanced:
        # the load balance: the body approaches by the solve's approach
        z = -approach / beta
        s.pose[0:3] += z * motion.axis
        if not at_rest:
            s.pose[7:10] = (s.pose[0:3] - before) / model.dt
            velocity += (z / model.dt) * motion.axis
    k_area = area[at]
    normal_world = n[at]
    slip_v = velocity - np.einsum("ij,ij->i", velocity, normal_world)[:, None] * normal_world
    energy, friction, state = _tangential(model, patch, F, slip_v, elastic.friction, at_rest)
    _wear(model, body, s, patch, idx, F, energy, slip_v, k_area, normal_world)
    _record(s, patch, idx, F, friction, state, normal_world, r, at)
    _foundation(model, patch, approach, heights, on, k_area, F)


def _solve_normal(body, s, t, patch, active, gap, n, area, r, hmin, balanced, load):
    """Step 3 of :func:`step`: the normal problem on a patch that fits it.
    The patch's grid is kept while the vertices' tangent coordinates hold
    (else built again over the band of gaps ``gap`` above ``hmin``); the
    solve is skipped while the gaps moved rigidly (within :data:`RESOLVE`),
    else taken (``load`` for a guided body, ``balanced``; the overlap for
    the others) and the band grown or shrunk, the grid built again, until
    the contact lies inside it. Returns the patch's vertices' positions in
    ``active``, their gaps, and the rigid move along the normal the
    approach follows (m; 0 after a solve)."""
    shift_move = 0.0
    for _ in range(8):
        take = None if patch.grid is None else _locate(patch, active, r)
        if take is None:
            if patch.grid is not None:
                _drop_grid(patch)
            if patch.band == 0.0:
                finite = gap[np.isfinite(gap)] - hmin
                k = min(FIRST_BAND_VERTICES, len(finite))
                patch.band = 2.0 * float(np.partition(finite, k - 1)[k - 1]) + 1e-30
            take = _build_patch(patch, active, gap, r, area, hmin)
        heights = gap[take]
        if not np.all(np.isfinite(heights)):
            _drop_grid(patch)
            continue
        outside = float(gap[patch.outside].min(initial=np.inf))
        if patch.pressure is not None:
            change = heights - patch.heights
            # a guided body's rigid move along the normal is balanced away
            common = float(np.median(change[patch.loaded])) if balanced else 0.0
            if (np.abs(change - common).max()
                    <= RESOLVE * max(patch.approach - patch.heights.min(), 0.0)
                    and outside > patch.approach + common):
                # the same contact moved rigidly: the approach follows
                shift_move = common
                break
        cell_gap = (patch.weights @ heights).reshape(patch.allowed.shape)
        cell_gap = np.where(patch.allowed, cell_gap, 0.0)
        solution = halfspace.solve(patch.grid, cell_gap, load, mask=patch.allowed,
                                   start=patch.pressure, tol=TOLERANCE,
                                   approach=None if balanced else 0.0)
        patch.solves += 1
        patch.iterations += solution.iterations
        used = solution.approach - hmin
        pressed = solution.traction > 0.0
        if used > GROW_BAND * patch.band or outside <= solution.approach:
            patch.band = used / BAND_USE
            _drop_grid(patch)
            continue
        if pressed.any() and (pressed[0].any() or pressed[-1].any() or pressed[:, 0].any()
                              or pressed[:, -1].any()):
            patch.band *= 2.0
            _drop_grid(patch)
            continue
        if 0.0 < used < SHRINK_BAND * patch.band and patch.solves > 1:
            # the contact shrank well inside its patch: a smaller grid
            patch.band = used / BAND_USE
            _drop_grid(patch)
            continue
        _new_pressure(patch, solution, heights, area[take])
        patch.spread = _spread(body, s, patch, n[take])
        if patch.spread > REFUSE_SPREAD:
            raise PatchError(
                f"body {body.name!r}: its contact spans {np.degrees(patch.spread):.0f}° of "
                f"surface normal at t = {t:.6g} s: a conforming contact (a shaft in a "
                "bushing), not a half-space one; use contact.model = 'winkler'")
        break
    else:
        raise PatchError(f"body {body.name!r}: the half-space patch did not settle at "
                         f"t = {t:.6g} s")
    return take, heights, shift_move


def _wear(model, body, s, patch, idx, F, energy, slip_v, k_area, normal_world):
    """Step 5 of :func:`step`: the loaded vertices ``idx`` (forces ``F``,
    friction ``energy``, slip velocities ``slip_v``, contact areas
    ``k_area``, contact normals ``normal_world``) wear by the wear law and
    add up their friction work; and what a worn counter wears by
    (``patch.counter``)."""
    # wear: the law on each vertex's energy, load and slip
    mu = model.elastic.friction
    law = LAWS[name_of(int(model.law[2]))]
    slip_distance = energy / (mu * F) if mu > 0.0 else np.zeros(len(F))
    dw, dv = law.twin(model.law[3], energy, F, slip_distance, np.where(k_area > 0.0, k_area, 1.0))
    worn = dw > 0.0
    if worn.any():
        R = quaternion_matrix(s.pose[3:7])
        if body.wear_direction.shape[0]:
            direction = body.wear_direction[idx[worn]]
        else:
            direction = normal_world[worn] @ R
        s.vertices[idx[worn]] += dw[worn, None] * direction
        s.wear_depth[idx[worn]] += dw[worn]
        s.wear_volume[idx[worn]] += dv[worn]
    s.friction_work[idx] += energy
    # what a worn counter wears by: each vertex's energy as a slip at its
    # speed (the counter's kernel dissipates f N |v| dt in slip)
    speed = np.linalg.norm(slip_v, axis=1)
    moving = (energy > 0.0) & (speed > 0.0) & (mu > 0.0)
    patch.counter = (idx[moving], energy[moving] / (mu * speed[moving] * model.dt))


def _record(s, patch, idx, F, friction, state, normal_world, r, at):
    """The step's contacts written into the state ``s`` as the Winkler
    kernel writes them: each loaded vertex's normal force, friction and
    contact state, the body's wrench (``r[at]``: their offsets from the
    body's origin), the load history."""
    s.normal_force[0, idx] = F
    s.tangential[0, idx, FORCE_SLOT] = friction
    s.contact_state[0, idx] = state
    patch.written = idx
    forces = F[:, None] * normal_world + friction
    s.wrench[0:3] = forces.sum(axis=0)
    s.wrench[3:6] = np.cross(r[at], forces).sum(axis=0)
    if s.load.shape[1]:
        s.load[0, idx] += F
        s.load[1, idx] += F * F
        if len(s.load) > 2:
            s.load[2:5, idx] += (F[:, None] * normal_world).T


def _foundation(model, patch, approach, heights, on, k_area, F):
    """Once, at the first contact with an overlap: the stiffness per area
    of the Winkler foundation equivalent to it (``model.law``), from the
    loaded vertices' (``on``, of the patch's) overlaps ``approach -
    heights``."""
    if not patch.extra.get("foundation"):
        # the Winkler foundation equivalent to the first contact, for what
        # reasons with one (a cycle jump's re-balance, its wear per unit of
        # penetration): its load over its overlaps; kept for the run, so
        # that the jumps' measurements compare from cycle to cycle
        overlap = np.maximum(approach - heights[on], 0.0)
        stiff = float(overlap @ (k_area * overlap))
        if len(F) and stiff > 0.0:
            model.law[6] = float(F @ overlap) / stiff
            model.law[5] = 0.0
            patch.extra["foundation"] = True


def vertex_pressure(s):
    """(n,) the pressure (Pa) at the points of the vertices that carry load
    in the last step of a half-space body (state ``s``): the solved
    pressure read bilinearly between the cell centres around each
    (docs/outputs.md, ``pressure``); zero elsewhere. Its force is this
    pressure times its contact area, scaled alike at every vertex by
    ``P / sum(p_j A_j)``: the two differ by the quadrature's error only."""
    out = np.zeros(len(s.wear_depth))
    patch = s.elastic
    if patch is not None and patch.written is not None and patch.point_pressure is not None:
        on = patch.loaded
        # (a contact narrower than a cell, which no vertex's point reads,
        # is carried by the gap weights: its force over its area there)
        out[patch.written] = np.where(patch.point_pressure[on] > 0.0, patch.point_pressure[on],
                                      patch.forces[on] / patch.areas[on])
    return out


def counter_pairs(s):
    """Per slot, the (contact state, normal force) a worn counter-surface
    wears by after a half-space step (:func:`meshwear.step.counters.wear_counters`):
    the vertices that dissipated energy slip, each with the force whose
    Coulomb slip at its speed dissipates that energy; the others nothing."""
    patch = s.elastic
    if patch is None:
        return list(zip(np.zeros_like(s.contact_state), np.zeros_like(s.normal_force)))
    # allocated once, the last step's entries cleared (not the whole arrays)
    if "counter_pairs" not in patch.extra:
        patch.extra["counter_pairs"] = (np.zeros_like(s.contact_state),
                                        np.zeros_like(s.normal_force), np.zeros(0, np.int64))
    state, force, last = patch.extra["counter_pairs"]
    state[0, last], force[0, last] = NO_CONTACT, 0.0
    idx, f = patch.counter if patch.counter is not None else (last[:0], 0.0)
    state[0, idx], force[0, idx] = SLIP, f
    patch.extra["counter_pairs"] = (state, force, idx)
    return list(zip(state, force))


def describe(model, state):
    """``meshwear check``'s lines on each body's half-space contact at the
    start: the patch and its grid, and how far its contact normals spread
    (the half-space assumption: within :data:`WARN_SPREAD`; a warning
    beyond it)."""
    lines, warnings = [], []
    surface = model.surfaces.slots[0].name
    for body, s in zip(model.bodies, state.bodies):
        patch = s.elastic
        if patch is None or patch.pressure is None:
            lines.append(f"half-space contact of {body.name!r} on {surface!r}: none at the start")
            continue
        h = patch.grid.spacing[0]
        pressed = patch.pressure > 0.0
        radius = np.sqrt(pressed.sum() * h * h / np.pi)
        lines.append(
            f"half-space contact of {body.name!r} on {surface!r}: E* {model.elastic.modulus:.3g} "
            f"Pa, patch of radius {radius:.3g} m ({int((patch.forces > 0.0).sum())} vertices) on "
            f"a {patch.grid.shape[0]} x {patch.grid.shape[1]} grid of {h:.3g} m cells, peak "
            f"pressure {patch.pressure.max():.3g} Pa, contact normals within "
            f"{np.degrees(patch.spread):.2g}°")
        if patch.spread > WARN_SPREAD:
            warnings.append(
                f"body {body.name!r} on {surface!r}: the contact normals spread "
                f"{np.degrees(patch.spread):.2g}°, more than {np.degrees(WARN_SPREAD):.2g}°: "
                "the patch is not small against the radii of curvature (the half-space "
                "assumption); model = 'winkler' may suit a conforming contact better")
    return lines, warnings


def equivalent_depth(model, body, s, index, depth, area):
    """The penetrations a cycle jump reasons with (:func:`meshwear.longrun.jumps.contact_geometry`)
    for a half-space contact: a loaded vertex's force over its stiffness on
    the equivalent Winkler foundation, ``N_i / (K A_i)``; an unloaded one in
    the patch, minus its gap after the surfaces deformed (the rigid overlap
    of a vertex just outside an elastic contact, out to sqrt(2) a on a
    ball, carries nothing: taken as a penetration it would carry load and
    wear in the jump); the others' rigid ``depth`` as given."""
    patch = s.elastic
    if patch is None or patch.pressure is None or patch.index is None:
        return depth
    pos = np.minimum(np.searchsorted(patch.index, index), len(patch.index) - 1)
    ours = patch.index[pos] == index
    # the surfaces' displacement at each vertex: its nearest cell's
    u = patch.grid.convolve(patch.pressure)
    cell = np.rint((patch.coords[pos[ours]] - patch.origin) / patch.grid.spacing[0]).astype(int)
    cell = np.clip(cell, 0, np.array(u.shape) - 1)
    displacement = np.zeros(len(index))
    displacement[ours] = u[cell[:, 0], cell[:, 1]]
    force = s.normal_force[0, index]
    stiffness = model.law[5] + model.law[6] * area
    out = depth.copy()
    loaded = ours & (force > 0.0) & (stiffness > 0.0)
    out[loaded] = force[loaded] / stiffness[loaded]
    free = ours & ~loaded & np.isfinite(depth)
    out[free] = np.minimum(depth[free] - displacement[free], 0.0)
    return out
