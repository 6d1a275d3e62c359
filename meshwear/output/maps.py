"""Wear maps of worn parts (``meshwear plot``, docs/outputs.md, "Other commands").

A part whose worn faces face one way (a pin's end, a flat, a block, a ball's
cap) is drawn in 3-D by pyvista off screen, looked at face-on from outside
those faces, framed on the worn region. A part whose worn faces face round
an axis (a gear's flanks, a bore, a shaft worn all round) has no view that
shows them all: its surface round that axis is unrolled instead, wear drawn
against the arc length round the axis and the position along it
(matplotlib); so is a part whose face-on view hides its deepest wear. Either
way the colours are not shaded, so that they read against the scale bar,
and :func:`wear_map` can give where each vertex was drawn in the picture
(the tests read the pictures back).
"""

import os

import numpy as np

from .export import ExportError, part_mesh, read_frame, series_frames

#: pixels of the 3-D wear maps
MAP_SIZE = (900, 700)
#: the worn faces (area times the least wear of their corners) face round an
#: axis when their normals lie near a plane (the smallest eigenvalue of their
#: weighted second moment under this share of the weights) and fan out in it
#: (the middle one at least :data:`FAN`): a gear's flanks, a bore, a shaft
FLAT_SPREAD = 0.1
#: (a fan of about 2 degrees; a flat face's normals have none and no axis),
#: the smallest eigenvalue at most :data:`PLANAR` of it (a ball's cap fans
#: out every way alike: no axis)
FAN, PLANAR = 1e-3, 0.25
#: worn faces round an axis are unrolled when the weighted mean of their
#: normals is under this share of the weights (a gear's flanks, a shaft worn
#: all round), when they face the axis (a bore: no view from outside sees
#: them), or when the view face-on shows less than :data:`SHOWN` of the
#: deepest wear (a single flank behind its neighbour tooth)
ONE_WAY = 0.8
#: a 3-D map frames the vertices worn at least this share of the deepest ...
FRAMED = 0.01
#: ... with this margin (times their extent), where they are smaller than the part,
MARGIN = 1.3
#: ... in this part of the part's view (shares of its width and height, from
#: its lower left): clear of the title
FREE = ((0.03, 0.97), (0.03, 0.9))
#: the share of a 3-D map's width the scale bar's column takes
BAR_COLUMN = 0.2
#: the deepest wear: the worn vertices at or above this quantile of their depths
DEEPEST = 0.9
#: a face-on view has to show at least this share of the deepest wear's vertices
SHOWN = 0.9
#: an unrolled map's faces: those whose normal is at most this far along the axis
#: (cosine; a gear's end faces, a bushing's ends left out)
ROUND = 0.5
#: an unrolled strip longer than this many times its width is cut into rows
ROW_ASPECT = 25.0
#: rows of an unrolled map at most
MAX_ROWS = 6
#: the unrolled map's width and height a row (inches), margins above and
#: below the rows (inches), and resolution (dots per inch)
UNROLLED_WIDTH, UNROLLED_ROW_HEIGHT, UNROLLED_DPI = 12.0, 1.6, 110
UNROLLED_MARGINS = (0.5, 0.6)


def pyplot():
    """matplotlib.pyplot on the Agg backend (ExportError naming the extra if it is missing)."""
    try:
        import matplotlib
    except ImportError:
        raise ExportError("meshwear plot needs matplotlib: pip install 'meshwear[plots]'") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def mesh_fields(out_dir, name, frame=-1):
    """A part's mesh in its own frame at ``frame``, its wear depth there and the frame's time."""
    vertices, faces, time = part_mesh(out_dir, name, frame)
    depth = np.asarray(read_frame(series_frames(out_dir, name)[frame][1])
                       .point_data["wear_depth"], float)
    return vertices, faces, depth, time


def worn_faces(vertices, faces, depth):
    """Unit outward normals (k, 3) of the faces and their weights (k,),
    summing to 1: area times the least wear of their corners (a face worn
    all over; the faces at a worn edge or corner by their mean wear where
    none is)."""
    cross = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]],
                     vertices[faces[:, 2]] - vertices[faces[:, 0]])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    normals = cross / np.maximum(2.0 * area, 1e-300)[:, None]
    weights = area * depth[faces].min(axis=1)
    if not weights.sum() > 0.0:
        weights = area * depth[faces].mean(axis=1)
    if not weights.sum() > 0.0:
        weights = area
    return normals, weights / weights.sum()


def choose_map(vertices, faces, depth):
    """How a part's wear map shows its worn faces (:func:`worn_faces`):
    ``(kind, direction, axis)``. ``direction`` is the weighted mean of their
    normals; ``axis`` the axis they face round, if they do
    (:data:`FLAT_SPREAD`; their normals' smallest principal axis, from its
    positive side), else None. ``kind`` is ``"unrolled"`` where they face
    round it many ways (:data:`ONE_WAY`) or face it (a bore), else
    ``"view"``: looked at face-on from ``direction``."""
    normals, weights = worn_faces(vertices, faces, depth)
    mean = weights @ normals
    direction = mean / np.linalg.norm(mean) if np.linalg.norm(mean) > 0.0 else np.eye(3)[2]
    values, vectors = np.linalg.eigh(np.einsum("i,ij,ik->jk", weights, normals, normals))
    if values[0] > FLAT_SPREAD or values[1] < FAN or values[0] > PLANAR * values[1]:
        return "view", direction, None
    axis = vectors[:, 0] if vectors[np.argmax(np.abs(vectors[:, 0])), 0] > 0.0 else -vectors[:, 0]
    rel = vertices[faces].mean(axis=1) - vertices.mean(axis=0)
    rel -= np.outer(rel @ axis, axis)
    inward = weights @ np.einsum("ij,ij->i", normals, rel) < 0.0
    if inward or np.linalg.norm(mean) < ONE_WAY:
        return "unrolled", direction, axis
    return "view", direction, axis


def deepest(depth):
    """Indices of the vertices holding the deepest wear (:data:`DEEPEST`)."""
    worn = depth > 0.0
    if not worn.any():
        return np.zeros(0, np.int64)
    return np.flatnonzero(worn & (depth >= np.quantile(depth[worn], DEEPEST)))


def wear_map(out_dir, name, path, view=None, pixels=False):
    """The part at its last frame coloured by wear depth (µm) with a scale
    bar: seen from ``view`` (its own frame) if given; else as
    :func:`choose_map` says, unrolled round the axis its worn faces face
    round (:func:`unrolled_map`) or seen face-on from outside them
    (:func:`view_map`), unrolled after all where that view hides the
    deepest wear (:data:`SHOWN`) and they face round an axis. Returns
    ``path``, and with ``pixels`` also (n, 2) float: each vertex's (row,
    column) in the picture (NaN where it is not drawn)."""
    vertices, faces, depth, time = mesh_fields(out_dir, name)
    title = f"{name}, t = {time:.6g} s, deepest {depth.max() * 1e6:.3g} µm"
    if view is not None:
        kind, direction, axis = "view", np.asarray(view, float), None
    else:
        kind, direction, axis = choose_map(vertices, faces, depth)
    if kind == "view":
        where, seen = view_map(vertices, faces, depth, direction / np.linalg.norm(direction),
                               title, path)
        deep = deepest(depth)
        if axis is not None and len(deep) and seen[deep].mean() < SHOWN:
            kind = "unrolled"
    if kind == "unrolled":
        where = unrolled_map(vertices, faces, depth, axis, title, path)
    return (path, where) if pixels else path


def view_map(vertices, faces, depth, view, title, path):
    """The part seen from ``view`` (unit, its own frame) without perspective,
    drawn by pyvista off screen to ``path``. Returns each vertex's (row,
    column) there (n, 2), and whether it is in sight (n,) bool: not behind
    another face (the depth buffer)."""
    if "DISPLAY" not in os.environ and "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ:
        # no X server: render through EGL (VTK's default would try X first
        # and print a warning)
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"
    import pyvista

    mesh = pyvista.PolyData(vertices, np.hstack([np.full((len(faces), 1), 3), faces]).ravel())
    mesh.point_data["wear depth (µm)"] = depth * 1e6
    up = np.cross(view, [0.0, 0.0, 1.0] if abs(view[2]) < 0.9 else [1.0, 0.0, 0.0])
    up = np.cross(up, view)
    try:
        # the part on the left, the scale bar in a column of its own
        plotter = pyvista.Plotter(off_screen=True, window_size=MAP_SIZE, shape=(1, 2),
                                  col_weights=[1.0 - BAR_COLUMN, BAR_COLUMN], border=False)
    except Exception as err:  # no OpenGL at all (a bare container)
        raise ExportError(f"meshwear plot: cannot render off screen ({err}); install EGL or "
                          "OSMesa, or run with a display") from None
    plotter.set_background("white")
    plotter.subplot(0, 0)
    # (unshaded: a colour is the depth the scale bar gives it, whatever the
    # face's slope to the light)
    actor = plotter.add_mesh(mesh, scalars="wear depth (µm)", cmap="viridis", show_edges=False,
                             lighting=False, clim=[0.0, max(depth.max() * 1e6, 1e-30)],
                             show_scalar_bar=False)
    text = plotter.add_text(title, font_size=10, color="black")
    text.prop.background_color, text.prop.background_opacity = "white", 1.0
    plotter.enable_parallel_projection()
    center = np.asarray(mesh.center)
    distance = 3.0 * max(mesh.length, 1e-12)
    plotter.camera_position = [tuple(center + distance * view), tuple(center), tuple(up)]
    plotter.reset_camera()
    _frame_the_wear(plotter.camera, vertices, depth, view, up)
    renderer = plotter.renderer
    plotter.subplot(0, 1)
    plotter.add_scalar_bar("wear depth\n(µm)\n", mapper=actor.mapper, color="black",
                           vertical=True, fmt="%.3g", position_x=0.1, position_y=0.1,
                           width=0.25, height=0.75, title_font_size=14, label_font_size=12)
    image = plotter.screenshot(str(path), return_img=True)
    where, seen = _display_points(plotter.render_window, renderer, vertices, image.shape[:2])
    plotter.close()
    return where, seen


def _frame_the_wear(camera, vertices, depth, view, up):
    """Point the (parallel) ``camera`` so that the worn region (the vertices
    worn at least :data:`FRAMED` of the deepest), with a margin, fills the
    part of the picture left of the scale bar and under the title; the whole
    part where it is no larger (a fretting scar tens of µm wide on a ball of
    some mm would be a few pixels)."""
    right = np.cross(up, view)
    right /= np.linalg.norm(right)
    up = up / np.linalg.norm(up)
    aspect = (1.0 - BAR_COLUMN) * MAP_SIZE[0] / MAP_SIZE[1]
    (x0, x1), (y0, y1) = FREE

    def fit(points):
        x, y = points @ right, points @ up
        half = 0.5 * MARGIN * max(np.ptp(y) / (y1 - y0), np.ptp(x) / ((x1 - x0) * aspect), 1e-12)
        return half, 0.5 * (x.max() + x.min()), 0.5 * (y.max() + y.min())

    worn = depth >= FRAMED * depth.max() if depth.max() > 0.0 else np.ones(len(depth), bool)
    half, x, y = fit(vertices[worn])
    whole = fit(vertices)
    if half >= whole[0]:
        half, x, y = whole
    # the region's middle where the free part of the picture has its middle
    x -= (0.5 * (x0 + x1) - 0.5) * 2.0 * half * aspect
    y -= (0.5 * (y0 + y1) - 0.5) * 2.0 * half
    middle = x * right + y * up + (np.asarray(camera.focal_point) @ view) * view
    camera.position = tuple(middle + (np.asarray(camera.position) - np.asarray(camera.focal_point)))
    camera.focal_point = tuple(middle)
    camera.parallel_scale = half


def _display_points(window, renderer, points, shape):
    """(row, column) (k, 2) of world ``points`` (k, 3) in the picture
    ``window`` just rendered (``shape`` its rows and columns) by
    ``renderer``, and whether each is in sight: no farther than the
    farthest of the depth buffer's values round it (its own faces drawn
    there) by more than a little."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkFloatArray

    rows, columns = shape
    buffer = vtkFloatArray()
    window.GetZbufferData(0, 0, columns - 1, rows - 1, buffer)
    zbuffer = vtk_to_numpy(buffer).reshape(rows, columns)       # bottom row first
    display = np.empty((len(points), 3))
    for k, p in enumerate(points):
        renderer.SetWorldPoint(p[0], p[1], p[2], 1.0)
        renderer.WorldToDisplay()
        display[k] = renderer.GetDisplayPoint()
    x, y = np.rint(display[:, 0]).astype(int), np.rint(display[:, 1]).astype(int)
    seen = np.zeros(len(points), bool)
    inside = (x >= 0) & (x < columns) & (y >= 0) & (y < rows)
    far = np.full(len(points), -np.inf)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            far[inside] = np.maximum(far[inside], zbuffer[np.clip(y[inside] + dy, 0, rows - 1),
                                                          np.clip(x[inside] + dx, 0,
                                                                  columns - 1)])
    seen[inside] = display[inside, 2] <= far[inside] + 1e-3
    # (display y runs up from the bottom row)
    return np.column_stack([rows - 1 - display[:, 1], display[:, 0]]), seen


def unroll(vertices, faces, depth, axis):
    """The part's surface round ``axis`` (unit) laid flat: the faces whose
    normal is within :data:`ROUND` of square to the axis, on the side the
    wear is (a bore's, not its tube's outside); each of their vertices at
    its arc length round the axis along the surface's outline (m, from a
    seam where the part wears least) and its position along the axis.

    Returns
    -------
    flat : (n, 2) float
        (arc length, position along the axis) of every vertex (NaN off the
        unrolled faces).
    kept : (k, 3) int
        The unrolled faces (those across the seam left out).
    length : float
        The outline's length (m).
    """
    centre = vertices.mean(axis=0)
    e1 = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    rel = vertices - centre
    plane = np.column_stack([rel @ e1, rel @ e2])
    along = rel @ axis
    normals, weights = worn_faces(vertices, faces, depth)
    middle = plane[faces].mean(axis=1)
    radial = middle / np.maximum(np.linalg.norm(middle, axis=1), 1e-300)[:, None]
    outward = (normals @ e1) * radial[:, 0] + (normals @ e2) * radial[:, 1]
    # the side the wear is on: outward (a gear, a shaft) or inward (a bore)
    side = 1.0 if weights @ outward >= 0.0 else -1.0
    kept = faces[(np.abs(normals @ axis) <= ROUND) & (side * outward > -ROUND)]
    on = np.zeros(len(vertices), bool)
    on[kept.ravel()] = True
    angle = np.arctan2(plane[:, 1], plane[:, 0])
    # the seam where the part wears least (the middle of the emptiest of
    # 360 sectors, by wear)
    sector = ((angle + np.pi) / (2.0 * np.pi) * 360).astype(int) % 360
    worn = np.bincount(sector[on], depth[on], minlength=360)
    seam = (_middle_of_longest_run(worn <= 0.01 * worn.max()) + 0.5) / 360 * 2.0 * np.pi - np.pi
    angle = np.mod(angle - seam, 2.0 * np.pi)
    # arc length along the outline: the vertices in order round the axis,
    # each step the distance between neighbours (the rows across the width
    # of an extruded outline fall on each other and add nothing)
    index = np.flatnonzero(on)
    order = index[np.argsort(angle[index], kind="stable")]
    steps = np.linalg.norm(np.diff(plane[order], axis=0), axis=1)
    arc = np.full(len(vertices), np.nan)
    arc[order] = np.concatenate([[0.0], np.cumsum(steps)])
    length = float(arc[order[-1]]) if len(order) else 0.0
    # a face across the seam would span the whole strip
    spread = np.ptp(angle[kept], axis=1) if len(kept) else np.zeros(0)
    kept = kept[spread < np.pi]
    flat = np.column_stack([arc, np.where(on, along, np.nan)])
    return flat, kept, length


def _middle_of_longest_run(mask):
    """Index of the middle of the longest run of True in the circular ``mask``."""
    n = len(mask)
    if mask.all():
        return 0
    start = int(np.argmin(mask))            # a False: runs do not wrap past it
    rolled = np.roll(mask, -start)
    best, best_at, run = 0, 0, 0
    for k, value in enumerate(rolled):
        run = run + 1 if value else 0
        if run > best:
            best, best_at = run, k
    return (start + best_at - best // 2) % n


def rasterize(points, triangles, values, x_range, y_range, shape):
    """``values`` (n,) at ``points`` (n, 2) interpolated linearly over
    ``triangles`` (k, 3) at the centres of a grid of ``shape`` (rows,
    columns) cells over ``x_range`` and ``y_range`` (rows from the bottom);
    NaN off the triangles. (The scalar, not its colour, is interpolated, so
    every cell has a colour of the scale.)"""
    rows, columns = shape
    (x0, x1), (y0, y1) = x_range, y_range
    out = np.full(shape, np.nan)
    px = (points[:, 0] - x0) / (x1 - x0) * columns - 0.5
    py = (points[:, 1] - y0) / (y1 - y0) * rows - 0.5
    xs, ys, vs = px[triangles], py[triangles], values[triangles]
    i0 = np.maximum(np.ceil(xs.min(axis=1)), 0).astype(int)
    i1 = np.minimum(np.floor(xs.max(axis=1)), columns - 1).astype(int)
    j0 = np.maximum(np.ceil(ys.min(axis=1)), 0).astype(int)
    j1 = np.minimum(np.floor(ys.max(axis=1)), rows - 1).astype(int)
    det = ((ys[:, 1] - ys[:, 2]) * (xs[:, 0] - xs[:, 2])
           + (xs[:, 2] - xs[:, 1]) * (ys[:, 0] - ys[:, 2]))
    live = (i1 >= i0) & (j1 >= j0) & (det != 0.0)
    # the triangles in groups of about the same box (cells), each group at once
    width = np.where(live, i1 - i0 + 1, 0)
    height = np.where(live, j1 - j0 + 1, 0)
    group = (np.ceil(np.log2(np.maximum(width, 1))).astype(int) * 64
             + np.ceil(np.log2(np.maximum(height, 1))).astype(int))
    for g in np.unique(group[live]):
        k = np.flatnonzero(live & (group == g))
        bw, bh = int(width[k].max()), int(height[k].max())
        ii = i0[k, None, None] + np.arange(bw)[None, None, :]
        jj = j0[k, None, None] + np.arange(bh)[None, :, None]
        X, Y, D = xs[k, :, None, None], ys[k, :, None, None], det[k, None, None]
        l0 = ((Y[:, 1] - Y[:, 2]) * (ii - X[:, 2]) + (X[:, 2] - X[:, 1]) * (jj - Y[:, 2])) / D
        l1 = ((Y[:, 2] - Y[:, 0]) * (ii - X[:, 2]) + (X[:, 0] - X[:, 2]) * (jj - Y[:, 2])) / D
        l2 = 1.0 - l0 - l1
        inside = ((l0 >= -1e-9) & (l1 >= -1e-9) & (l2 >= -1e-9)
                  & (ii <= i1[k, None, None]) & (jj <= j1[k, None, None]))
        value = (l0 * vs[k, 0, None, None] + l1 * vs[k, 1, None, None]
                 + l2 * vs[k, 2, None, None])
        jj, ii = np.broadcast_arrays(jj, ii)
        out[jj[inside], ii[inside]] = value[inside]
    return out


def unrolled_map(vertices, faces, depth, axis, title, path):
    """The part's surface round ``axis`` unrolled (:func:`unroll`) and drawn
    by matplotlib to ``path``, wear depth (µm) against the arc length round
    the axis and the position along it (mm), in rows when the strip is long
    (:data:`ROW_ASPECT`); returns each vertex's (row, column) there."""
    plt = pyplot()
    import matplotlib
    import matplotlib.image

    flat, kept, length = unroll(vertices, faces, depth, axis)
    if not len(kept):
        raise ExportError(f"{title.split(',')[0]}: no faces round the axis to unroll; "
                          "give --view")
    s, z = flat[:, 0] * 1e3, flat[:, 1] * 1e3
    used = np.unique(kept)
    width = float(np.ptp(z[used])) or 1.0
    rows = int(np.clip(np.ceil(length * 1e3 / (ROW_ASPECT * width)), 1, MAX_ROWS))
    inches = (UNROLLED_WIDTH, UNROLLED_MARGINS[0] + UNROLLED_MARGINS[1]
              + UNROLLED_ROW_HEIGHT * rows)
    fig, axes = plt.subplots(rows, 1, squeeze=False, dpi=UNROLLED_DPI, figsize=inches)
    # (fixed margins: a layout engine takes seconds over the pictures)
    fig.subplots_adjust(left=0.07, right=0.9, top=1.0 - UNROLLED_MARGINS[0] / inches[1],
                        bottom=UNROLLED_MARGINS[1] / inches[1], hspace=0.55)
    axes = axes[:, 0]
    top = max(depth.max() * 1e6, 1e-30)
    span = length * 1e3 / rows
    pad = 0.08 * width
    y_range = (z[used].min() - pad, z[used].max() + pad)
    # each row's picture at about the pixels it is drawn on
    shape = (int(UNROLLED_ROW_HEIGHT * UNROLLED_DPI), int(UNROLLED_WIDTH * UNROLLED_DPI))
    image = rasterize(np.column_stack([np.nan_to_num(s), np.nan_to_num(z)]), kept, depth * 1e6,
                      (0.0, rows * span), y_range, (shape[0], rows * shape[1]))
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="white")
    for r, ax in enumerate(axes):
        shade = ax.imshow(image[:, r * shape[1]:(r + 1) * shape[1]], origin="lower",
                          extent=(r * span, (r + 1) * span, *y_range), aspect="auto",
                          interpolation="nearest", cmap=cmap, vmin=0.0, vmax=top)
        ax.set_ylabel("along (mm)", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[-1].set_xlabel("round the axis: arc length along the outline (mm)", fontsize=9)
    a = ", ".join(f"{c:.3g}" for c in np.round(axis, 3) + 0.0)
    axes[0].set_title(f"{title}; unrolled round the axis ({a})", fontsize=10)
    low, high = axes[-1].get_position(), axes[0].get_position()
    bar = fig.add_axes((0.92, low.y0, 0.015, high.y1 - low.y0))
    fig.colorbar(shade, cax=bar, label="wear depth (µm)", format="%.3g")
    fig.canvas.draw()
    height = fig.canvas.get_width_height()[1]
    where = np.full((len(vertices), 2), np.nan)
    for r, ax in enumerate(axes):
        mine = np.flatnonzero(np.isfinite(s) & (s >= r * span) & (s <= (r + 1) * span))
        xy = ax.transData.transform(np.column_stack([s[mine], z[mine]]))
        # (display y runs up from the bottom; a pixel's centre is half a pixel in)
        where[mine] = np.column_stack([height - xy[:, 1] - 0.5, xy[:, 0] - 0.5])
    # the picture drawn, as it is (no second drawing)
    matplotlib.image.imsave(path, np.asarray(fig.canvas.buffer_rgba()))
    plt.close(fig)
    return where
