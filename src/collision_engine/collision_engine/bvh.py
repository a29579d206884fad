"""Exact signed distance to a closed triangle mesh: an AABB tree over its triangles.

The tree is built once in numpy (median split of the triangle centroids along the longest axis,
at most ``LEAF_SIZE`` triangles a leaf) and searched in the compiled kernel depth-first, nearer
child first, skipping every box farther than the best distance found so far; the previous
answer's triangle is tried first, which tightens the bound from the start on a trajectory. On
each candidate triangle the closest point is computed exactly, in closed form
(``signed_volumes.closest_point_on_triangle``: no iteration, no GJK), which also says which
feature the nearest point lies on, unless a cheap lower bound on its distance (to its plane, to
its box: ``triangle_bound2``) is not below the best so far; the sign comes from that feature's
angle-weighted pseudonormal (``pseudonormals``). The normal returned is the face's when the
nearest point is inside a face, else the unit vector between the point and the surface (or,
within 1e-9 of the mesh's size, where that vector is mostly rounding, the feature's
pseudonormal). Vertices must be welded and the surface closed and consistently wound
(``shapes.TriangleMesh`` checks).

Packed layout (one object's blocks; ``t`` triangles, ``e`` edges, ``n`` vertices, ``b`` nodes),
triangles in tree-leaf order:

* floats: scale (bounding radius, m); corners (t, 9); face normals (t, 3); edge normals (e, 3);
  vertex normals (n, 3); node boxes (b, 6) as min xyz, max xyz; a grid of exact signed
  distances (``distance_grid``, for the probe's overlap search: ``tool_mesh``): origin (3),
  spacing (0: no grid), vertices along x, y and z (3), then the values.
* ints: t, e, n, b, tree depth; faces (t, 3); face edges (t, 3); original face index (t,);
  nodes (b, 3) as first child (-1 for a leaf), first triangle, triangle count.

The search keeps its pending nodes on a stack that the scene preallocates: a depth-first search
holds at most one pending sibling per level above the node it expands, plus that node's two
children, so a tree of depth L (edges from the root to its deepest leaf) needs L + 1 entries
(``search_stack_size``). The depth is measured when the tree is built, so that any tree, however
unbalanced, gets a stack that cannot overflow. (A median split, as here, gives
L = ceil(log2(t / LEAF_SIZE)) for any mesh, degenerate or not.)
"""

import numpy as np

from collision_engine._jit import jit
from collision_engine.norms import norm3, unit3
from collision_engine.pseudonormals import pseudonormals
from collision_engine.signed_volumes import closest_point_on_triangle

__all__ = ['FAR', 'GRID_HEADER', 'GRID_VERTICES', 'LEAF_SIZE', 'box_distance2', 'build_tree',
           'distance_grid', 'grid_at', 'grid_bounds', 'layout', 'mesh_distance',
           'nearest_triangle', 'pack_triangle_mesh', 'pseudonormal', 'search_stack_size',
           'tree_depth', 'triangle_bound2', 'triangle_distance2']

LEAF_SIZE = 4
GRID_HEADER = 7  # a distance grid's origin (3), spacing, vertices along x, y and z
GRID_VERTICES = 2 ** 17  # the grid of a scene's mesh: 1 MB; for the hand, 2 mm apart
FAR = 2.0 ** 26  # mesh radii: beyond, a query is answered from a nearer point on its ray


def build_tree(corners: np.ndarray, leaf_size: int = LEAF_SIZE):
    """Median-split AABB tree over triangles.

    Parameters
    ----------
    corners : (t, 3, 3) float, m
        The triangles' corners.

    Returns
    -------
    order : (t,) int64
        Triangle indices in leaf order: leaf triangles are contiguous.
    boxes : (b, 6) float64, m
        Each node's box (min x, y, z, max x, y, z).
    nodes : (b, 3) int64
        First child (its sibling follows it; -1 for a leaf), first triangle, triangle count.
    """
    order, boxes, nodes, count = _build_tree(np.ascontiguousarray(corners, dtype=np.float64),
                                             leaf_size)
    return order, boxes[:count].copy(), nodes[:count].copy()


@jit
def _build_tree(corners, leaf_size):
    """Compiled body of ``build_tree`` (in numpy it took 0.4 s for the hand's 11k triangles).

    Returns order, boxes and nodes with room for 2 t nodes, and the count used.
    """
    t = len(corners)
    centroids = (corners[:, 0] + corners[:, 1] + corners[:, 2]) / 3.0
    lows = np.minimum(np.minimum(corners[:, 0], corners[:, 1]), corners[:, 2])
    highs = np.maximum(np.maximum(corners[:, 0], corners[:, 1]), corners[:, 2])
    order = np.arange(t)
    capacity = max(1, 2 * t)
    boxes = np.empty((capacity, 6))
    nodes = np.empty((capacity, 3), dtype=np.int64)
    pending = np.empty((capacity, 3), dtype=np.int64)  # (start, stop, node) still to split
    pending[0, 0], pending[0, 1], pending[0, 2] = 0, t, 0
    top, count = 1, 1
    while top > 0:
        top -= 1
        start, stop, node = pending[top, 0], pending[top, 1], pending[top, 2]
        members = order[start:stop]
        spread = np.empty(3)
        for axis in range(3):
            boxes[node, axis] = lows[members, axis].min()
            boxes[node, 3 + axis] = highs[members, axis].max()
            spread[axis] = centroids[members, axis].max() - centroids[members, axis].min()
        if stop - start <= leaf_size:
            nodes[node, 0], nodes[node, 1], nodes[node, 2] = -1, start, stop - start
            continue
        axis = np.argmax(spread)
        middle = (stop - start) // 2
        order[start:stop] = members[np.argsort(centroids[members, axis])]
        child = count
        count += 2
        nodes[node, 0], nodes[node, 1], nodes[node, 2] = child, start, stop - start
        pending[top, 0], pending[top, 1], pending[top, 2] = start + middle, stop, child + 1
        pending[top + 1, 0], pending[top + 1, 1] = start, start + middle
        pending[top + 1, 2] = child
        top += 2
    return order, boxes, nodes, count


def tree_depth(nodes: np.ndarray) -> int:
    """Edges from the root to the deepest leaf of a tree as ``build_tree`` returns it.

    Parameters
    ----------
    nodes : (b, 3) int
        First child (its sibling follows it; -1 for a leaf), first triangle, triangle count.
    """
    depth = np.zeros(len(nodes), dtype=np.int64)
    for node in range(len(nodes)):  # children always come after their parent
        child = nodes[node, 0]
        if child >= 0:
            depth[child] = depth[child + 1] = depth[node] + 1
    return int(depth.max())


def search_stack_size(ints: np.ndarray) -> int:
    """Stack entries the search of one packed mesh (its ``ints`` block) can fill: depth + 1."""
    return int(ints[4]) + 1


def pack_triangle_mesh(vertices: np.ndarray, faces: np.ndarray, *,
                       grid_vertices: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Build the tree and pseudonormals of a mesh and pack them in the layout above.

    Parameters
    ----------
    vertices : (n, 3) float, m, local frame
    faces : (t, 3) int, closed and consistently wound
    grid_vertices : int
        The most vertices of its grid of exact signed distances (``distance_grid``; 0: none).

    Returns
    -------
    floats : (k,) float64
    ints : (j,) int64
    """
    normals = pseudonormals(vertices, faces)
    order, boxes, nodes = build_tree(vertices[faces])
    faces_sorted = faces[order]
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    scale = float(np.linalg.norm(vertices - centre, axis=1).max())
    floats = np.concatenate((
        [scale], vertices[faces_sorted].ravel(), normals.face[order].ravel(),
        normals.edge.ravel(), normals.vertex.ravel(), boxes.ravel()))
    ints = np.concatenate((
        [len(faces), len(normals.edge), len(vertices), len(nodes), tree_depth(nodes)],
        faces_sorted.ravel(),
        normals.face_edges[order].ravel(), order, nodes.ravel()))
    floats, ints = floats.astype(np.float64), ints.astype(np.int64)
    return np.concatenate((floats, distance_grid(floats, ints, vertices, grid_vertices))), ints


def distance_grid(floats: np.ndarray, ints: np.ndarray, vertices: np.ndarray,
                  count: int) -> np.ndarray:
    """Return the grid block of a packed mesh: exact signed distances at a grid's vertices.

    The grid spans the mesh's box widened by one spacing on every side, its spacing the least
    that keeps it to ``count`` vertices. Each value bounds the signed distance d near its
    vertex v, which is 1-Lipschitz: |d(p) - d(v)| <= |p - v|; and a point beyond the grid is
    outside the mesh. Returns [origin (3), spacing, vertices along x, y, z, values (x-major)],
    or that header with a zero spacing when ``count`` is 0.
    """
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    extent = high - low
    if count <= 0 or extent.max() <= 0.0:
        return np.zeros(GRID_HEADER)

    def shape(spacing):
        return np.ceil(extent / spacing).astype(np.int64) + 3

    spacing = extent.max() / 4.0
    while np.prod(shape(spacing / 1.25)) <= count:
        spacing /= 1.25
    origin = low - spacing
    stack = np.zeros(search_stack_size(ints), dtype=np.int64)
    values = _grid_values(floats, ints, origin, spacing, shape(spacing), stack,
                          np.zeros(len(stack)))
    return np.concatenate((origin, [spacing], shape(spacing), values))


@jit
def _grid_values(floats, ints, origin, spacing, shape, stack, stack_d2):
    """Exact signed distance at every grid vertex, x-major (each search hinted by the last)."""
    values = np.empty(shape[0] * shape[1] * shape[2])
    hint, n = -1, 0
    for i in range(shape[0]):
        for j in range(shape[1]):
            for k in range(shape[2]):
                d, _, _, _, _, _, _, hint, _, _ = mesh_distance(
                    floats, 0, ints, 0, origin[0] + i * spacing, origin[1] + j * spacing,
                    origin[2] + k * spacing, hint, stack, stack_d2, -1.0)
                values[n] = d
                n += 1
    return values


@jit
def grid_bounds(floats, grid, qx, qy, qz):
    """Bounds (lower, upper) on the signed distance at q from the grid at floats[grid:].

    From the nearest grid vertex; (-inf, inf) without a grid, and (inf, inf) beyond it, where
    q is outside the mesh.
    """
    spacing = floats[grid + 3]
    if spacing == 0.0:
        return -np.inf, np.inf
    i = round((qx - floats[grid]) / spacing)
    j = round((qy - floats[grid + 1]) / spacing)
    k = round((qz - floats[grid + 2]) / spacing)
    nx, ny, nz = floats[grid + 4], floats[grid + 5], floats[grid + 6]
    if not (0 <= i < nx and 0 <= j < ny and 0 <= k < nz):
        return np.inf, np.inf
    value = floats[grid + GRID_HEADER + int((i * ny + j) * nz + k)]
    reach = norm3(qx - (floats[grid] + i * spacing), qy - (floats[grid + 1] + j * spacing),
                  qz - (floats[grid + 2] + k * spacing))
    return value - reach, value + reach


@jit
def layout(floats, fo, ints, io):
    """Offsets of one packed mesh's blocks (module docstring), and its triangle count.

    Returns (triangles, corners, face normals, edge normals, vertex normals, boxes; faces,
    face edges, original index, nodes): the first six index ``floats``, the last four ``ints``.
    """
    n_tri, n_edge, n_vert = ints[io], ints[io + 1], ints[io + 2]
    corners = fo + 1
    face_normals = corners + 9 * n_tri
    edge_normals = face_normals + 3 * n_tri
    vertex_normals = edge_normals + 3 * n_edge
    boxes = vertex_normals + 3 * n_vert
    faces = io + 5
    face_edges = faces + 3 * n_tri
    original = face_edges + 3 * n_tri
    return (n_tri, corners, face_normals, edge_normals, vertex_normals, boxes, faces, face_edges,
            original, original + n_tri)


@jit
def grid_at(floats, fo, ints, io):
    """Offset in ``floats`` of one packed mesh's distance grid: the block after its node boxes."""
    return layout(floats, fo, ints, io)[5] + 6 * ints[io + 3]


@jit
def pseudonormal(floats, ints, face_normals, edge_normals, vertex_normals, faces, face_edges,
                 t, feature, which):
    """Return the angle-weighted pseudonormal of a feature of triangle t (leaf order).

    It signs the distance of every point whose nearest surface point lies on that feature.
    ``feature`` and ``which`` are ``closest_point_on_triangle``'s: 3 face, 2 edge (opposite
    vertex ``which``), 1 vertex ``which``.
    """
    if feature == 3:
        p = face_normals + 3 * t
    elif feature == 2:
        p = edge_normals + 3 * ints[face_edges + 3 * t + which]
    else:
        p = vertex_normals + 3 * ints[faces + 3 * t + which]
    return floats[p], floats[p + 1], floats[p + 2]


@jit
def box_distance2(floats, b, qx, qy, qz):
    """Squared distance from q to the box at floats[b:b + 6] (0 inside)."""
    dx = max(floats[b] - qx, 0.0, qx - floats[b + 3])
    dy = max(floats[b + 1] - qy, 0.0, qy - floats[b + 4])
    dz = max(floats[b + 2] - qz, 0.0, qz - floats[b + 5])
    return dx * dx + dy * dy + dz * dz


@jit
def _gap(q, a, b, c):
    """Distance from the coordinate q to the interval spanned by a, b and c (0 within it)."""
    return max(min(a, b, c) - q, 0.0, q - max(a, b, c))


@jit
def triangle_bound2(floats, corners, n_tri, t, qx, qy, qz):
    """Lower bound on the squared distance from q to triangle t (leaf order).

    The larger of the distances to the triangle's plane and to its box: a few products, where
    its closest point takes some hundred operations, so the search skips most of those.
    """
    c, f = corners + 9 * t, corners + 9 * n_tri + 3 * t
    h = (floats[f] * (qx - floats[c]) + floats[f + 1] * (qy - floats[c + 1])
         + floats[f + 2] * (qz - floats[c + 2]))
    gx = _gap(qx, floats[c], floats[c + 3], floats[c + 6])
    gy = _gap(qy, floats[c + 1], floats[c + 4], floats[c + 7])
    gz = _gap(qz, floats[c + 2], floats[c + 5], floats[c + 8])
    return max(h * h, gx * gx + gy * gy + gz * gz)


@jit
def triangle_distance2(floats, corners, t, qx, qy, qz):
    """Closest point of triangle t (leaf order) to q: ``closest_point_on_triangle``'s tuple."""
    c = corners + 9 * t
    return closest_point_on_triangle(
        floats[c] - qx, floats[c + 1] - qy, floats[c + 2] - qz,
        floats[c + 3] - qx, floats[c + 4] - qy, floats[c + 5] - qz,
        floats[c + 6] - qx, floats[c + 7] - qy, floats[c + 8] - qz)


@jit
def mesh_distance(floats, fo, ints, io, qx, qy, qz, hint, stack, stack_d2, enough2):
    """Signed distance from q to a packed triangle mesh, local frame.

    ``hint`` is a triangle (leaf order) to try first, or -1. ``stack`` (int) and ``stack_d2``
    (float) are scratch, each at least ``search_stack_size`` long (module docstring). The search
    stops at the first triangle whose squared distance is at most ``enough2`` (-1: none), and
    answers from it: then only the distance's magnitude means anything, as an upper bound.

    A point farther than ``FAR`` mesh radii R from the mesh's centre is outside, and is searched
    from the point moved toward the mesh to ``FAR`` radii on the same ray: far off, the rounding
    of q - corner (eps |q|) would exceed the triangles and garble their features, and beyond
    1e154 m the squares overflow. The nearest point found is farther from q than q's own nearest
    point by at most R^2 / (2 FAR R) (second order in R / distance), under half an ulp of the
    distance; the distance and the normal are then measured from q itself.

    Returns (distance, closest x, y, z, outward normal x, y, z, triangle in leaf order,
    original triangle index, triangles tested), m; the distance is negative inside.
    """
    scale = floats[fo]
    (n_tri, corners, face_normals, edge_normals, vertex_normals, boxes, faces, face_edges,
     original, nodes) = layout(floats, fo, ints, io)

    cx, cy, cz = (0.5 * (floats[boxes] + floats[boxes + 3]),
                  0.5 * (floats[boxes + 1] + floats[boxes + 4]),
                  0.5 * (floats[boxes + 2] + floats[boxes + 5]))
    reach = max(abs(qx - cx), abs(qy - cy), abs(qz - cz))
    sx, sy, sz = qx, qy, qz
    if reach > FAR * scale:
        pull = FAR * scale / reach
        sx, sy, sz = cx + (qx - cx) * pull, cy + (qy - cy) * pull, cz + (qz - cz) * pull
    best_d2, best_t, feature, which, vx, vy, vz, tested = nearest_triangle(
        floats, corners, boxes, ints, nodes, n_tri, sx, sy, sz, hint, stack, stack_d2, enough2)
    if reach > FAR * scale:
        x, y, z = sx + vx, sy + vy, sz + vz
        nx, ny, nz = unit3(qx - x, qy - y, qz - z)
        return (norm3(qx - x, qy - y, qz - z), x, y, z, nx, ny, nz, best_t,
                ints[original + best_t], tested)

    px, py, pz = pseudonormal(floats, ints, face_normals, edge_normals, vertex_normals, faces,
                              face_edges, best_t, feature, which)
    distance = norm3(vx, vy, vz)
    inside = vx * px + vy * py + vz * pz > 0.0
    sign = -1.0 if inside else 1.0
    nx, ny, nz = px, py, pz
    if feature != 3 and distance > 1e-9 * scale:
        ux, uy, uz = unit3(vx, vy, vz)
        nx, ny, nz = -sign * ux, -sign * uy, -sign * uz
    return (sign * distance, qx + vx, qy + vy, qz + vz, nx, ny, nz,
            best_t, ints[original + best_t], tested)


@jit
def nearest_triangle(floats, corners, boxes, ints, nodes, n_tri, qx, qy, qz, hint, stack,
                     stack_d2, enough2):
    """Depth-first search of the tree for the triangle nearest q (see ``mesh_distance``).

    It stops early at a triangle within ``enough2`` (squared; -1 for none).

    Returns (squared distance, triangle in leaf order, feature, which, vx, vy, vz, triangles
    tested) with v from q to the nearest point and the feature as
    ``closest_point_on_triangle``'s.
    """
    best_d2 = np.inf
    best_t, feature, which = -1, 0, 0
    vx = vy = vz = 0.0
    tested = 0
    if 0 <= hint < n_tri:
        d2, ux, uy, uz, f, w = triangle_distance2(floats, corners, hint, qx, qy, qz)
        tested = 1
        if d2 < best_d2:
            best_d2, vx, vy, vz, feature, which, best_t = d2, ux, uy, uz, f, w, hint
    stack[0] = 0
    stack_d2[0] = box_distance2(floats, boxes, qx, qy, qz)
    top = 1
    while top > 0 and best_d2 > enough2:
        top -= 1
        node = stack[top]
        if stack_d2[top] >= best_d2:
            continue
        child = ints[nodes + 3 * node]
        if child < 0:
            first = ints[nodes + 3 * node + 1]
            tested += ints[nodes + 3 * node + 2]
            for t in range(first, first + ints[nodes + 3 * node + 2]):
                if triangle_bound2(floats, corners, n_tri, t, qx, qy, qz) >= best_d2:
                    continue
                d2, ux, uy, uz, f, w = triangle_distance2(floats, corners, t, qx, qy, qz)
                if d2 < best_d2:
                    best_d2, vx, vy, vz, feature, which, best_t = d2, ux, uy, uz, f, w, t
            continue
        near_d2 = box_distance2(floats, boxes + 6 * child, qx, qy, qz)
        far_d2 = box_distance2(floats, boxes + 6 * (child + 1), qx, qy, qz)
        near, far = child, child + 1
        if far_d2 < near_d2:
            near, far, near_d2, far_d2 = far, near, far_d2, near_d2
        if far_d2 < best_d2:
            stack[top] = far
            stack_d2[top] = far_d2
            top += 1
        if near_d2 < best_d2:
            stack[top] = near
            stack_d2[top] = near_d2
            top += 1
    return best_d2, best_t, feature, which, vx, vy, vz, tested
