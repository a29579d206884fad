"""A convex tool against a closed, non-convex triangle mesh, compiled.

Sign rule as everywhere: negative in overlap; the normal is outward from the mesh.

* The tool is measured by its core and the core's radius subtracted (``narrowphase``): a sphere
  is the mesh's exact point query at its centre, minus its radius.
* Separation: the mesh's AABB tree is searched depth-first, nearer child first, skipping every
  node whose box is farther from the tool's own box (in the mesh's frame, from six support
  points) than the nearest triangle so far; each candidate triangle is measured by GJK against
  the tool. The nearest triangle's distance is the separation, exact to GJK's tolerance, and
  its feature's pseudonormal at the tool's witness says whether the tool is outside.
* Overlap (a triangle in contact, or the tool wholly inside): the deepest point of the tool's
  point shell (``tool``) by the mesh's exact signed distance (``bvh.mesh_distance``). The signed
  distance is 1-Lipschitz, so a shell point closer to an already measured one than that one's
  distance above the deepest so far cannot be deeper, and is skipped; the first point measured
  is the one deepest along the contact triangle's normal. When no shell point is inside (a
  feature of the mesh reaches into the tool between shell points), the answer is the contact
  itself: depth zero at GJK's contact point, with that triangle's normal.
"""

import math

from collision_engine import bvh
from collision_engine._jit import jit
from collision_engine.gjk import gjk, STATUS_NOT_CONVERGED, STATUS_OK
from collision_engine.narrowphase import core_of
from collision_engine.norms import norm3, unit3
from collision_engine.signed_volumes import closest_point_on_triangle
from collision_engine.support import POINT, support, TRIANGLE
from collision_engine.tool import FLOAT_HEADER, INT_HEADER

__all__ = ['mesh_tool_distance']


@jit
def _to_mesh(rel, x, y, z):
    """A point of the tool's frame in the mesh's frame (``rel``: the tool's pose there)."""
    return (rel[0] * x + rel[1] * y + rel[2] * z + rel[9],
            rel[3] * x + rel[4] * y + rel[5] * z + rel[10],
            rel[6] * x + rel[7] * y + rel[8] * z + rel[11])


@jit
def _extent(core, rel, axis):
    """The tool core's extent along a mesh axis: its support along -+ that axis, (lo, hi)."""
    ux, uy, uz = rel[3 * axis], rel[3 * axis + 1], rel[3 * axis + 2]  # the axis, tool frame
    sx, sy, sz, _ = support(core[0], core[1], core[2], core[3], core[4], ux, uy, uz, 0)
    tx, ty, tz, _ = support(core[0], core[1], core[2], core[3], core[4], -ux, -uy, -uz, 0)
    offset = rel[9 + axis]
    return ux * tx + uy * ty + uz * tz + offset, ux * sx + uy * sy + uz * sz + offset


@jit
def _core_box(core, rel):
    """The tool core's axis-aligned box in the mesh's frame: (lo x, y, z, hi x, y, z)."""
    lx, hx = _extent(core, rel, 0)
    ly, hy = _extent(core, rel, 1)
    lz, hz = _extent(core, rel, 2)
    return lx, ly, lz, hx, hy, hz


@jit
def _box_gap2(floats, b, lx, ly, lz, hx, hy, hz):
    """Squared distance between the node box at floats[b:b + 6] and the box (l, h)."""
    dx = max(floats[b] - hx, 0.0, lx - floats[b + 3])
    dy = max(floats[b + 1] - hy, 0.0, ly - floats[b + 4])
    dz = max(floats[b + 2] - hz, 0.0, lz - floats[b + 5])
    return dx * dx + dy * dy + dz * dz


@jit
def _nearest_triangle(floats, ints, corners, boxes, nodes, n_tri, core, rel, hint, size,
                      rel_tol, abs_tol, max_iter, W, stack, stack_d2):
    """Search the tree for the triangle nearest the core; stop at the first one in contact.

    The hint triangle is measured first. Returns (contact, triangle, distance, a, v, status,
    lower, iterations) with a on the triangle and v = a - b (module docstring).
    """
    lx, ly, lz, hx, hy, hz = _core_box(core, rel)
    centre = (0.5 * (lx + hx), 0.5 * (ly + hy), 0.5 * (lz + hz))
    state = (math.inf, -1, STATUS_OK, 0.0, math.inf, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, False)
    if 0 <= hint < n_tri:
        state = _measure(floats, ints, corners, hint, 1, core, rel, centre, size, rel_tol,
                         abs_tol, max_iter, W, state)
    stack[0], stack_d2[0] = 0, _box_gap2(floats, boxes, lx, ly, lz, hx, hy, hz)
    top = 1
    while top > 0 and not state[12]:
        top -= 1
        node = stack[top]
        best2 = state[0] * state[0]
        if stack_d2[top] >= best2:
            continue
        child = ints[nodes + 3 * node]
        if child < 0:
            state = _measure(floats, ints, corners, ints[nodes + 3 * node + 1],
                             ints[nodes + 3 * node + 2], core, rel, centre, size, rel_tol,
                             abs_tol, max_iter, W, state)
            continue
        near_d2 = _box_gap2(floats, boxes + 6 * child, lx, ly, lz, hx, hy, hz)
        far_d2 = _box_gap2(floats, boxes + 6 * (child + 1), lx, ly, lz, hx, hy, hz)
        near, far = child, child + 1
        if far_d2 < near_d2:
            near, far, near_d2, far_d2 = far, near, far_d2, near_d2
        if far_d2 < best2:
            stack[top], stack_d2[top] = far, far_d2
            top += 1
        if near_d2 < best2:
            stack[top], stack_d2[top] = near, near_d2
            top += 1
    best, best_t, status, lower, unsure, ax, ay, az, vx, vy, vz, total, contact = state
    if unsure < best:
        status, lower = STATUS_NOT_CONVERGED, min(lower, unsure)
    return contact, best_t, best, ax, ay, az, vx, vy, vz, status, lower, total


@jit
def _measure(floats, ints, corners, first, count, core, rel, centre, size, rel_tol, abs_tol,
             max_iter, W, state):
    """Measure triangles first..first + count by GJK and fold them into the search's state.

    ``state`` is (best distance, its triangle, status, lower bound, least lower bound of an
    unconverged triangle, a (3), v (3), GJK iterations, contact); a contact ends the search.
    """
    best, best_t, status, lower, unsure, ax, ay, az, vx, vy, vz, total, contact = state
    cx, cy, cz = centre
    for t in range(first, first + count):
        c = corners + 9 * t
        s, touch, _, ux, uy, uz, low, iterations, _, px, py, pz = gjk(
            (TRIANGLE, floats, c, ints, 0), core, rel, cx - floats[c], cy - floats[c + 1],
            cz - floats[c + 2], size, rel_tol, abs_tol, max_iter, W[:12], W[12:24])
        total += iterations
        d = 0.0 if touch else norm3(ux, uy, uz)
        if s != STATUS_OK:
            unsure = min(unsure, low)
        if d < best:
            best, best_t, status, lower = d, t, s, low
            ax, ay, az, vx, vy, vz = px, py, pz, ux, uy, uz
        if touch:
            return best, best_t, STATUS_OK, 0.0, unsure, ax, ay, az, vx, vy, vz, total, True
    return best, best_t, status, lower, unsure, ax, ay, az, vx, vy, vz, total, contact


@jit
def _outside(floats, ints, lay, t, ax, ay, az, vx, vy, vz):
    """Whether the core's witness b = a - v lies outside the mesh (a: its nearest point)."""
    (_, corners, face_normals, edge_normals, vertex_normals, _, faces, face_edges, _,
     _) = lay
    bx, by, bz = ax - vx, ay - vy, az - vz
    c = corners + 9 * t
    _, ux, uy, uz, feature, which = closest_point_on_triangle(
        floats[c] - bx, floats[c + 1] - by, floats[c + 2] - bz,
        floats[c + 3] - bx, floats[c + 4] - by, floats[c + 5] - bz,
        floats[c + 6] - bx, floats[c + 7] - by, floats[c + 8] - bz)
    px, py, pz = bvh.pseudonormal(floats, ints, face_normals, edge_normals, vertex_normals,
                                  faces, face_edges, t, feature, which)
    return ux * px + uy * py + uz * pz <= 0.0


@jit
def _deepest_shell_point(floats, fo, ints, io, tool_floats, tool_ints, rel, nx, ny, nz, ax, ay,
                         az, hint, stack, stack_d2):
    """The shell point of least signed distance, if any is inside (module docstring).

    (nx, ny, nz) is the contact's outward normal and a a point on the surface there, which
    order the shell. Returns (found, distance, x, y, z, normal x, y, z, shell point x, y, z,
    leaf triangle, original triangle, triangles tested).
    """
    n_shell = tool_ints[1]
    shell = int(tool_floats[6])
    work = int(tool_floats[7]) + 12
    first, deepest = 0, -math.inf
    for i in range(n_shell):
        px, py, pz = _to_mesh(rel, tool_floats[shell + 3 * i], tool_floats[shell + 3 * i + 1],
                              tool_floats[shell + 3 * i + 2])
        depth = nx * (ax - px) + ny * (ay - py) + nz * (az - pz)
        if depth > deepest:
            first, deepest = i, depth
    best = 0.0
    found = False
    measured = tested = 0
    x = y = z = mx = my = mz = sx = sy = sz = 0.0
    leaf_t = triangle = -1
    for step in range(n_shell):
        i = first if step == 0 else (step - 1 if step - 1 < first else step)
        px, py, pz = _to_mesh(rel, tool_floats[shell + 3 * i], tool_floats[shell + 3 * i + 1],
                              tool_floats[shell + 3 * i + 2])
        bound = -math.inf
        for j in range(measured):
            w = work + 4 * j
            bound = max(bound, tool_floats[w + 3] - norm3(px - tool_floats[w],
                                                          py - tool_floats[w + 1],
                                                          pz - tool_floats[w + 2]))
        if bound >= best:
            continue
        d, qx, qy, qz, ux, uy, uz, t, original, count = bvh.mesh_distance(
            floats, fo, ints, io, px, py, pz, hint, stack, stack_d2)
        hint = t
        tested += count
        w = work + 4 * measured
        tool_floats[w], tool_floats[w + 1], tool_floats[w + 2], tool_floats[w + 3] = (
            px, py, pz, d)
        measured += 1
        if d < best:
            best, found = d, True
            x, y, z, mx, my, mz, sx, sy, sz = qx, qy, qz, ux, uy, uz, px, py, pz
            leaf_t, triangle = t, original
    return found, best, x, y, z, mx, my, mz, sx, sy, sz, leaf_t, triangle, tested


@jit
def mesh_tool_distance(floats, fo, ints, io, tool_floats, tool_ints, tool_kind, rel, hint,
                       size, rel_tol, abs_tol, max_iter, W, stack, stack_d2):
    """Signed distance from a packed triangle mesh to the tool, in the mesh's frame.

    ``rel`` (12,) is the tool's pose in the mesh's frame; ``hint`` a triangle (leaf order) to
    try first; W GJK's scratch (24 used), ``stack`` and ``stack_d2`` the tree search's.
    Returns (status, distance, lower bound, x, y, z, nx, ny, nz, iterations, triangle, leaf
    triangle): x on the mesh, n outward from it; the tool's witness is x + distance n.
    """
    tool = (tool_kind, tool_floats, FLOAT_HEADER, tool_ints, INT_HEADER)
    radius = tool_floats[0]
    core = core_of(tool)
    lay = bvh.layout(floats, fo, ints, io)
    if core[0] == POINT:
        d, x, y, z, nx, ny, nz, t, original, tested = bvh.mesh_distance(
            floats, fo, ints, io, rel[9], rel[10], rel[11], hint, stack, stack_d2)
        return STATUS_OK, d - radius, d - radius, x, y, z, nx, ny, nz, tested, original, t
    n_tri, corners, face_normals, _, _, boxes, _, _, original, nodes = lay
    contact, t, d, ax, ay, az, vx, vy, vz, status, lower, tested = _nearest_triangle(
        floats, ints, corners, boxes, nodes, n_tri, core, rel, hint, size, rel_tol, abs_tol,
        max_iter, W, stack, stack_d2)
    if not contact and _outside(floats, ints, lay, t, ax, ay, az, vx, vy, vz):
        nx, ny, nz = unit3(-vx, -vy, -vz)
        return (status, d - radius, lower - radius, ax, ay, az, nx, ny, nz, tested,
                ints[original + t], t)
    f = face_normals + 3 * t
    fx, fy, fz = floats[f], floats[f + 1], floats[f + 2]
    found, depth, x, y, z, nx, ny, nz, _, _, _, leaf_t, triangle, more = _deepest_shell_point(
        floats, fo, ints, io, tool_floats, tool_ints, rel, fx, fy, fz, ax, ay, az, t, stack,
        stack_d2)
    if not found:
        return (STATUS_OK, -radius, -radius, ax, ay, az, fx, fy, fz, tested + more,
                ints[original + t], t)
    return (STATUS_OK, depth - radius, depth - radius, x, y, z, nx, ny, nz, tested + more,
            triangle, leaf_t)
