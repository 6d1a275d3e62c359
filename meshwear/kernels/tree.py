"""A bounding-volume tree over the faces of a counter mesh (docs/model.md, "How
the faces are found").

The faces are sorted along a Morton curve through their box centres and split
where the curve crosses from one octree cell to the next, recursively, down to
leaves of :data:`LEAF` faces; each node keeps
the box of its faces (grown by a rounding, and for a worn mesh by a slack on
the side its vertices sink to). A query for the faces within some
distance of a point walks down the nodes whose boxes come within it, nearer
child first, so it visits O(log F) nodes and the faces near the point,
whatever the mesh's size and however far it looks (a uniform grid whose cells
list the faces within the reach costs (reach / face size)² a lookup).

Arrays:

boxes : (N, 6) float64
    Each node's box, low corner then high corner.
nodes : (N, 2) int64
    A leaf: the first of its faces in ``order`` and their count (> 0). An
    inner node: its first child (the second follows it) and 0. The root is
    node 0; children come after their parent.
order : (F,) int64
    The faces in leaf order.

A worn mesh moves each vertex along its inward normal by its wear since the
boxes were fitted; while that is under the slack, the boxes still hold its
faces. :func:`refit` fits them anew in O(F) on the same topology.
"""

import numpy as np

from .jit import njit

def morton_codes(points):
    """(n,) uint64 Morton codes of ``points`` (n, 3): 20 bits an axis, one
    scale for the three (so that the curve keeps distances)."""
    if len(points) == 0:
        return np.zeros(0, np.uint64)
    low = points.min(axis=0)
    span = float((points.max(axis=0) - low).max())
    q = np.floor((points - low) / (span if span > 0.0 else 1.0) * 1048575.0).astype(np.uint64)
    return _spread(q[:, 0]) | (_spread(q[:, 1]) << np.uint64(1)) | (_spread(q[:, 2]) << np.uint64(2))


def _spread(x):
    """The 20 low bits of each uint64 spread to every third bit."""
    x = x & np.uint64(0xFFFFF)
    x = (x | (x << np.uint64(32))) & np.uint64(0x001F00000000FFFF)
    x = (x | (x << np.uint64(16))) & np.uint64(0x001F0000FF0000FF)
    x = (x | (x << np.uint64(8))) & np.uint64(0x100F00F00F00F00F)
    x = (x | (x << np.uint64(4))) & np.uint64(0x10C30C30C30C30C3)
    x = (x | (x << np.uint64(2))) & np.uint64(0x1249249249249249)
    return x


#: faces of a leaf at most
LEAF = 4

#: deepest tree built (a split per bit of the 60-bit codes, then halving
#: where codes are equal: 60 + log2(F) levels at most); a query's stack holds
#: at most one entry per level and one more
STACK = 128


def build(vertices, faces, rounding, slack=0.0, sink=None):
    """The tree (boxes, nodes, order) of a mesh's faces, boxes grown as
    :func:`refit` grows them."""
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    n = len(faces)
    if n == 0:
        return np.zeros((0, 6)), np.zeros((0, 2), np.int64), np.zeros(0, np.int64)
    tri = vertices[faces]
    code = morton_codes(0.5 * (tri.min(axis=1) + tri.max(axis=1)))
    order = np.argsort(code, kind="stable").astype(np.int64)
    nodes = _topology(code[order], LEAF)
    boxes = np.zeros((len(nodes), 6))
    refit(vertices, faces, nodes, order, float(rounding), float(slack),
          np.zeros((0, 3)) if sink is None else sink, boxes)
    return boxes, nodes, order


@njit(cache=True)
def _topology(codes, leaf):
    """``nodes`` of a tree over faces sorted by their Morton ``codes``: each
    range is split where its highest differing bit of the code changes (so a
    node's faces fill one cell of an octree, not two far apart), in the
    middle where the codes are equal, down to ``leaf`` faces."""
    n = codes.shape[0]
    nodes = np.zeros((2 * n, 2), np.int64)
    first = np.zeros(2 * n, np.int64)
    last = np.zeros(2 * n, np.int64)
    first[0], last[0] = 0, n
    stack = np.zeros(STACK, np.int64)
    top = 1
    used = 1
    while top > 0:
        top -= 1
        k = stack[top]
        a, b = first[k], last[k]
        if b - a <= leaf:
            nodes[k, 0], nodes[k, 1] = a, b - a
            continue
        differ = codes[a] ^ codes[b - 1]
        if differ == 0:
            m = (a + b) // 2
        else:
            bit = np.uint64(1)
            while differ > np.uint64(1):
                differ = differ >> np.uint64(1)
                bit = bit << np.uint64(1)
            # the first code of the range with that bit set
            lo, hi = a, b - 1
            while lo < hi:
                mid = (lo + hi) // 2
                if codes[mid] & bit:
                    hi = mid
                else:
                    lo = mid + 1
            m = lo
        c = used
        used += 2
        nodes[k, 0], nodes[k, 1] = c, 0
        first[c], last[c] = a, m
        first[c + 1], last[c + 1] = m, b
        stack[top] = c + 1
        stack[top + 1] = c
        top += 2
    return nodes[:used].copy()


@njit(cache=True)
def refit(vertices, faces, nodes, order, rounding, slack, sink, boxes):
    """Fit ``boxes`` to the faces where ``vertices`` put them, grown by
    ``rounding`` (m) all round and, where ``sink`` (V, 3) gives each
    vertex's outward normal, by ``slack`` (m) along minus that normal: a
    worn vertex sinks that way, so the boxes hold its faces until it has
    sunk ``slack`` farther, and stay tight on the side the bodies come from
    (``sink`` empty: no slack)."""
    worn = sink.shape[0] > 0
    for k in range(nodes.shape[0] - 1, -1, -1):
        a, count = nodes[k, 0], nodes[k, 1]
        if count > 0:
            for j in range(3):
                boxes[k, j] = np.inf
                boxes[k, 3 + j] = -np.inf
            for e in range(a, a + count):
                f = order[e]
                for c in range(3):
                    v = faces[f, c]
                    for j in range(3):
                        x = vertices[v, j]
                        lo = hi = x
                        if worn:
                            y = x - slack * sink[v, j]
                            lo, hi = min(x, y), max(x, y)
                        if lo < boxes[k, j]:
                            boxes[k, j] = lo
                        if hi > boxes[k, 3 + j]:
                            boxes[k, 3 + j] = hi
            for j in range(3):
                boxes[k, j] -= rounding
                boxes[k, 3 + j] += rounding
        else:
            for j in range(3):
                boxes[k, j] = min(boxes[a, j], boxes[a + 1, j])
                boxes[k, 3 + j] = max(boxes[a, 3 + j], boxes[a + 1, 3 + j])


@njit(cache=True)
def box_distance2(boxes, k, x, y, z):
    """Squared distance from (x, y, z) to node ``k``'s box (0 inside it)."""
    d = 0.0
    g = boxes[k, 0] - x
    if g > 0.0:
        d += g * g
    else:
        g = x - boxes[k, 3]
        if g > 0.0:
            d += g * g
    g = boxes[k, 1] - y
    if g > 0.0:
        d += g * g
    else:
        g = y - boxes[k, 4]
        if g > 0.0:
            d += g * g
    g = boxes[k, 2] - z
    if g > 0.0:
        d += g * g
    else:
        g = z - boxes[k, 5]
        if g > 0.0:
            d += g * g
    return d


def face_neighbours(faces):
    """(F, 3) int64: the face across each edge of each face (edge ``k`` from
    corner ``k`` to corner ``k + 1``, as the edge lines of
    :func:`meshwear.kernels.nearest.face_frames`), -1 at a border or where
    more than two faces share the edge."""
    faces = np.asarray(faces, dtype=np.int64)
    n = len(faces)
    out = np.full((n, 3), -1, np.int64)
    if n == 0:
        return out
    a = faces.ravel()
    b = np.roll(faces, -1, axis=1).ravel()
    key = np.minimum(a, b) * (int(faces.max()) + 1) + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    start = np.flatnonzero(np.r_[True, sorted_key[1:] != sorted_key[:-1]])
    count = np.diff(np.r_[start, len(key)])
    pairs = start[count == 2]
    e1, e2 = order[pairs], order[pairs + 1]
    out.ravel()[e1] = e2 // 3
    out.ravel()[e2] = e1 // 3
    return out
