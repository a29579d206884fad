"""A convex tool against a closed, non-convex triangle mesh, compiled.

Sign rule as everywhere: negative in overlap; the normal is outward from the mesh.

* The tool is measured by its core and the core's radius subtracted (``narrowphase``): a sphere
  is the mesh's exact point query at its centre, minus its radius.
* Separation: the mesh's AABB tree is searched depth-first, nearer child first, skipping every
  node, and every triangle, whose lower bound is not below the nearest triangle so far; each
  other triangle is measured by GJK against the tool, starting toward the tool's centre (so a
  triangle's answer, to its last bit, does not depend on the order of the search). The bound
  is the largest of these separating-axis bounds, along the mesh's axes (against the tool's box
  there, from six support points) and along the tool's own axes (against its extents along
  them): the distance is at least the root sum of squares of the gaps along any three
  orthogonal axes; and, once a triangle is measured, the gap along the direction from it to the
  tool, which prunes the surface that curves away from the nearest point. Of two children as
  near (both at zero, often, under a tool that reaches into the surface) the one whose box
  centre is nearer the tool's goes first: there the search meets a triangle in contact sooner.
  The last query's triangle is measured first when it lies within the tool's diagonal, else in
  its turn: a stale hint is a GJK call for a bound that prunes nothing. (For the probe near the
  hand, 3 GJK calls a query in overlap and 10 apart, where the children's own order and every
  hint took 8 and 16.) The nearest triangle's distance is the separation, exact to GJK's
  tolerance, and its feature's pseudonormal at the tool's witness says whether the tool is
  outside.
* Overlap (a triangle in contact, or the tool wholly inside): the deepest point of the tool's
  point shell (``tool``) by the mesh's exact signed distance (``bvh.mesh_distance``). Only a
  point deeper than the deepest so far matters, and bounds rule most points out unsearched:
  a scene's mesh carries a grid of exact signed distances (``bvh.distance_grid``), and as the
  signed distance is 1-Lipschitz a point's lies within its distance to the nearest grid vertex
  of that vertex's value (beyond the grid it is outside); a measured point q bounds p's from
  below by q's minus |p - q| (every measured point's distance, outside ones included, serves
  that test); and it is at least minus the distance to any surface point, so a shell point
  within the deepest depth of a surface point found is no deeper. For the same reason a search
  stops at the first triangle within the deepest depth (its distance is then kept as the
  bound), and it starts from the triangle of the surface point found nearest the shell point.
  The points are taken by least upper bound from the grid, the likely deepest first, among
  those whose lower bound is below the deepest so far; for the probe near the hand that is 6
  searches a query, where the tests between shell points alone left 19. When no shell point
  is inside (a feature of the mesh reaches into the tool between shell points), the answer is
  the contact itself: depth zero at GJK's contact point, with that triangle's normal.
"""

import math

from collision_engine import bvh
from collision_engine._jit import jit
from collision_engine.gjk import gjk, STATUS_NOT_CONVERGED, STATUS_OK
from collision_engine.narrowphase import core_of
from collision_engine.norms import norm3, unit3
from collision_engine.signed_volumes import closest_point_on_triangle
from collision_engine.support import POINT, support, TRIANGLE
from collision_engine.tool import BOX_FLOATS, FLOAT_HEADER, INT_HEADER, MEASURED_FLOATS

__all__ = ['mesh_tool_distance']

_UNIT_AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@jit
def _to_mesh(rel, x, y, z):
    """Return a point of the tool's frame in the mesh's frame (``rel``: the tool's pose there)."""
    return (rel[0] * x + rel[1] * y + rel[2] * z + rel[9],
            rel[3] * x + rel[4] * y + rel[5] * z + rel[10],
            rel[6] * x + rel[7] * y + rel[8] * z + rel[11])


@jit
def _extent(core, ux, uy, uz, offset):
    """Return the core's extent along u (tool frame), plus ``offset``: (lo, hi)."""
    sx, sy, sz, _ = support(core[0], core[1], core[2], core[3], core[4], ux, uy, uz, 0)
    tx, ty, tz, _ = support(core[0], core[1], core[2], core[3], core[4], -ux, -uy, -uz, 0)
    return ux * tx + uy * ty + uz * tz + offset, ux * sx + uy * sy + uz * sz + offset


@jit
def _set_tool_box(core, rel, box):
    """Write the core's extents in the mesh's frame to ``box`` (``tool.BOX_FLOATS``).

    [0:3] and [3:6]: its box along the mesh's axes (lo, hi); [6:15]: its own axes there (the
    rotation's columns); [15:21]: lo and hi along each of them; [21:25]: a unit direction n
    and the tool's least extent along it (``_set_direction``; none yet: zero).
    """
    box[21] = box[22] = box[23] = box[24] = 0.0
    for k in range(3):
        # Mesh axis k in the tool's frame is row k of the rotation.
        box[k], box[3 + k] = _extent(core, rel[3 * k], rel[3 * k + 1], rel[3 * k + 2],
                                     rel[9 + k])
        box[6 + 3 * k], box[7 + 3 * k], box[8 + 3 * k] = rel[k], rel[3 + k], rel[6 + k]
        offset = rel[k] * rel[9] + rel[3 + k] * rel[10] + rel[6 + k] * rel[11]
        ex, ey, ez = _UNIT_AXES[k]
        box[15 + 2 * k], box[16 + 2 * k] = _extent(core, ex, ey, ez, offset)


@jit
def _set_direction(core, rel, box, nx, ny, nz):
    """Store the unit direction n (mesh frame) and the core's least extent along it."""
    # -n in the tool's frame is R^T (-n); its support point, back in the mesh's frame, on n.
    dx = -(rel[0] * nx + rel[3] * ny + rel[6] * nz)
    dy = -(rel[1] * nx + rel[4] * ny + rel[7] * nz)
    dz = -(rel[2] * nx + rel[5] * ny + rel[8] * nz)
    sx, sy, sz, _ = support(core[0], core[1], core[2], core[3], core[4], dx, dy, dz, 0)
    x, y, z = _to_mesh(rel, sx, sy, sz)
    box[21], box[22], box[23], box[24] = nx, ny, nz, nx * x + ny * y + nz * z


@jit
def _gap2(lo_a, hi_a, lo_b, hi_b):
    """Squared gap between the intervals [lo_a, hi_a] and [lo_b, hi_b] (0 when they meet)."""
    gap = max(lo_a - hi_b, 0.0, lo_b - hi_a)
    return gap * gap


@jit
def _on_axis(box, k, x, y, z):
    """Return the point's coordinate along the tool's axis k."""
    return box[6 + 3 * k] * x + box[7 + 3 * k] * y + box[8 + 3 * k] * z


@jit
def _node_bound2(floats, b, box):
    """Lower bound on the squared distance from the tool to the node box at floats[b:b + 6]."""
    lx, ly, lz = floats[b], floats[b + 1], floats[b + 2]
    hx, hy, hz = floats[b + 3], floats[b + 4], floats[b + 5]
    mesh_axes = (_gap2(lx, hx, box[0], box[3]) + _gap2(ly, hy, box[1], box[4])
                 + _gap2(lz, hz, box[2], box[5]))
    own = 0.0
    for k in range(3):
        centre = _on_axis(box, k, 0.5 * (lx + hx), 0.5 * (ly + hy), 0.5 * (lz + hz))
        reach = 0.5 * ((hx - lx) * abs(box[6 + 3 * k]) + (hy - ly) * abs(box[7 + 3 * k])
                       + (hz - lz) * abs(box[8 + 3 * k]))
        own += _gap2(centre - reach, centre + reach, box[15 + 2 * k], box[16 + 2 * k])
    highest = (box[21] * 0.5 * (lx + hx) + box[22] * 0.5 * (ly + hy) + box[23] * 0.5 * (lz + hz)
               + 0.5 * ((hx - lx) * abs(box[21]) + (hy - ly) * abs(box[22])
                        + (hz - lz) * abs(box[23])))
    along = max(box[24] - highest, 0.0)
    return max(mesh_axes, own, along * along)


@jit
def _triangle_bound2(floats, c, box):
    """Lower bound on the squared distance from the tool to the triangle at floats[c:c + 9]."""
    mesh_axes = own = 0.0
    for k in range(3):
        a, b, d = floats[c + k], floats[c + 3 + k], floats[c + 6 + k]
        mesh_axes += _gap2(min(a, b, d), max(a, b, d), box[k], box[3 + k])
        a = _on_axis(box, k, floats[c], floats[c + 1], floats[c + 2])
        b = _on_axis(box, k, floats[c + 3], floats[c + 4], floats[c + 5])
        d = _on_axis(box, k, floats[c + 6], floats[c + 7], floats[c + 8])
        own += _gap2(min(a, b, d), max(a, b, d), box[15 + 2 * k], box[16 + 2 * k])
    highest = -math.inf
    for corner in range(3):
        p = c + 3 * corner
        highest = max(highest, box[21] * floats[p] + box[22] * floats[p + 1]
                      + box[23] * floats[p + 2])
    along = max(box[24] - highest, 0.0)
    return max(mesh_axes, own, along * along)


@jit
def _diagonal2(box):
    """Squared diagonal of the tool's box along its own axes."""
    return ((box[16] - box[15]) ** 2 + (box[18] - box[17]) ** 2 + (box[20] - box[19]) ** 2)


@jit
def _centre_nearer(floats, a, b, centre):
    """Whether the node box at floats[a:a + 6] has its centre nearer ``centre`` than b's."""
    cx, cy, cz = centre
    ax = floats[a] + floats[a + 3] - 2.0 * cx
    ay = floats[a + 1] + floats[a + 4] - 2.0 * cy
    az = floats[a + 2] + floats[a + 5] - 2.0 * cz
    bx = floats[b] + floats[b + 3] - 2.0 * cx
    by = floats[b + 1] + floats[b + 4] - 2.0 * cy
    bz = floats[b + 2] + floats[b + 5] - 2.0 * cz
    return ax * ax + ay * ay + az * az < bx * bx + by * by + bz * bz


@jit
def _nearest_triangle(floats, ints, corners, boxes, nodes, n_tri, core, rel, box, hint, size,
                      rel_tol, abs_tol, max_iter, W, stack, stack_d2):
    """Search the tree for the triangle nearest the core; stop at the first one in contact.

    The hint triangle is measured first if it is near (module docstring). Returns (contact,
    triangle, distance, a, v, status, lower, iterations) with a on the triangle and v = a - b.
    """
    centre = (0.5 * (box[0] + box[3]), 0.5 * (box[1] + box[4]), 0.5 * (box[2] + box[5]))
    state = (math.inf, -1, STATUS_OK, 0.0, math.inf, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, False)
    if 0 <= hint < n_tri and _triangle_bound2(floats, corners + 9 * hint, box) < _diagonal2(box):
        state = _measure(floats, ints, corners, hint, 1, core, rel, box, centre, size, rel_tol,
                         abs_tol, max_iter, W, state)
    stack[0], stack_d2[0] = 0, _node_bound2(floats, boxes, box)
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
                             ints[nodes + 3 * node + 2], core, rel, box, centre, size, rel_tol,
                             abs_tol, max_iter, W, state)
            continue
        near_d2 = _node_bound2(floats, boxes + 6 * child, box)
        far_d2 = _node_bound2(floats, boxes + 6 * (child + 1), box)
        near, far = child, child + 1
        if far_d2 < near_d2 or (far_d2 == near_d2 and _centre_nearer(
                floats, boxes + 6 * far, boxes + 6 * near, centre)):
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
def _measure(floats, ints, corners, first, count, core, rel, box, centre, size, rel_tol,
             abs_tol, max_iter, W, state):
    """Measure triangles first..first + count by GJK and fold them into the search's state.

    ``state`` is (best distance, its triangle, status, lower bound, least lower bound of an
    unconverged triangle, a (3), v (3), GJK iterations, contact); a contact ends the search.
    A triangle whose bound (``_triangle_bound2``) is not below the best is skipped.
    """
    best, best_t, status, lower, unsure, ax, ay, az, vx, vy, vz, total, contact = state
    cx, cy, cz = centre
    for t in range(first, first + count):
        c = corners + 9 * t
        if _triangle_bound2(floats, c, box) >= best * best:
            continue
        # The search starts toward the tool's centre, whatever was measured before: a
        # triangle's answer, to its last bit, is then the same in any order of the search.
        gx, gy, gz = cx - floats[c], cy - floats[c + 1], cz - floats[c + 2]
        s, touch, _, ux, uy, uz, low, iterations, _, px, py, pz = gjk(
            (TRIANGLE, floats, c, ints, 0), core, rel, gx, gy, gz, size, rel_tol, abs_tol,
            max_iter, W[:12], W[12:24])
        total += iterations
        if touch:
            return best, t, STATUS_OK, 0.0, unsure, px, py, pz, ux, uy, uz, total, True
        d = norm3(ux, uy, uz)
        if s != STATUS_OK:
            unsure = min(unsure, low)
        if d < best:
            best, best_t, status, lower = d, t, s, low
            ax, ay, az, vx, vy, vz = px, py, pz, ux, uy, uz
            nx, ny, nz = unit3(-vx, -vy, -vz)
            _set_direction(core, rel, box, nx, ny, nz)
    return best, best_t, status, lower, unsure, ax, ay, az, vx, vy, vz, total, contact


@jit
def _outside(floats, ints, lay, t, ax, ay, az, vx, vy, vz):
    """Whether the core's witness b = a - v lies outside the mesh (a: its nearest point)."""
    _, corners, face_normals, edge_normals, vertex_normals, _, faces, face_edges, _, _ = lay
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
def _bound_shell(floats, fo, grid, tool_floats, shell, n_shell, rel, bounds):
    """Write each shell point's bounds from the mesh's distance grid to tool_floats[bounds:].

    Lower and upper, two a point, the lower one lessened by a rounding slack.
    """
    slack = 1e-9 * floats[fo]
    for i in range(n_shell):
        px, py, pz = _to_mesh(rel, tool_floats[shell + 3 * i], tool_floats[shell + 3 * i + 1],
                              tool_floats[shell + 3 * i + 2])
        lower, upper = bvh.grid_bounds(floats, grid, px, py, pz)
        tool_floats[bounds + 2 * i], tool_floats[bounds + 2 * i + 1] = lower - slack, upper


@jit
def _least_upper(tool_floats, bounds, n_shell, best):
    """Return the shell point of least upper bound whose lower one is below ``best``, or -1."""
    chosen, least = -1, math.inf
    for i in range(n_shell):
        if tool_floats[bounds + 2 * i] < best and tool_floats[bounds + 2 * i + 1] <= least:
            chosen, least = i, tool_floats[bounds + 2 * i + 1]
    return chosen


@jit
def _ruled_out(tool_floats, work, measured, px, py, pz, best, hint):
    """Return whether what the points measured so far found rules p out, and where to search.

    A measured point q rules p out when its signed distance minus its distance to p (a lower
    bound on p's, the signed distance being 1-Lipschitz) is not below ``best``; so does a
    surface point a found for q when |p - a| <= -best (p's signed distance is at least
    -|p - a|). Returns (ruled out, the triangle of the surface point nearest p, else ``hint``).
    The latest points, most often p's neighbours in the order of the search, are tried first.
    """
    nearest2 = math.inf
    for j in range(measured - 1, -1, -1):
        w = work + MEASURED_FLOATS * j
        reach = tool_floats[w + 3] - best
        if reach >= 0.0:
            dx, dy, dz = px - tool_floats[w], py - tool_floats[w + 1], pz - tool_floats[w + 2]
            if dx * dx + dy * dy + dz * dz <= reach * reach:
                return True, hint
        dx, dy, dz = px - tool_floats[w + 4], py - tool_floats[w + 5], pz - tool_floats[w + 6]
        d2 = dx * dx + dy * dy + dz * dz
        if d2 < nearest2:
            nearest2, hint = d2, int(tool_floats[w + 7])
    return nearest2 <= best * best, hint


@jit
def _deepest_shell_point(floats, fo, ints, io, tool_floats, tool_ints, rel, hint, stack,
                         stack_d2):
    """Find the shell point of least signed distance, if any is inside (module docstring).

    Returns (found, distance, x, y, z, normal x, y, z, leaf triangle, original triangle,
    triangles tested).
    """
    n_shell, shell = tool_ints[1], int(tool_floats[6])
    work = int(tool_floats[7]) + 12 + BOX_FLOATS
    bounds = work + MEASURED_FLOATS * n_shell
    _bound_shell(floats, fo, bvh.grid_at(floats, fo, ints, io), tool_floats, shell, n_shell,
                 rel, bounds)
    best, found, measured, tested = 0.0, False, 0, 0
    x = y = z = mx = my = mz = 0.0
    leaf_t = triangle = -1
    i = _least_upper(tool_floats, bounds, n_shell, best)
    while i >= 0:
        tool_floats[bounds + 2 * i] = math.inf
        px, py, pz = _to_mesh(rel, tool_floats[shell + 3 * i], tool_floats[shell + 3 * i + 1],
                              tool_floats[shell + 3 * i + 2])
        ruled_out, hint = _ruled_out(tool_floats, work, measured, px, py, pz, best, hint)
        if ruled_out:
            i = _least_upper(tool_floats, bounds, n_shell, best)
            continue
        # The search starts from the triangle of the nearest surface point found, and stops at
        # any triangle within the deepest depth so far: p is then no deeper (its signed
        # distance is at least minus that triangle's distance), and that bound is kept of it.
        enough2 = best * best
        d, qx, qy, qz, ux, uy, uz, t, original, count = bvh.mesh_distance(
            floats, fo, ints, io, px, py, pz, hint, stack, stack_d2, enough2)
        tested += count
        if d * d <= enough2:
            d = -abs(d)
        elif d < best:
            best, found = d, True
            x, y, z, mx, my, mz, leaf_t, triangle = qx, qy, qz, ux, uy, uz, t, original
        w = work + MEASURED_FLOATS * measured
        tool_floats[w], tool_floats[w + 1], tool_floats[w + 2], tool_floats[w + 3] = px, py, pz, d
        tool_floats[w + 4], tool_floats[w + 5], tool_floats[w + 6] = qx, qy, qz
        tool_floats[w + 7] = t
        measured += 1
        i = _least_upper(tool_floats, bounds, n_shell, best)
    return found, best, x, y, z, mx, my, mz, leaf_t, triangle, tested


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
    if core[0] == POINT:
        d, x, y, z, nx, ny, nz, t, original, tested = bvh.mesh_distance(
            floats, fo, ints, io, rel[9], rel[10], rel[11], hint, stack, stack_d2, -1.0)
        return STATUS_OK, d - radius, d - radius, x, y, z, nx, ny, nz, tested, original, t
    lay = bvh.layout(floats, fo, ints, io)
    n_tri, corners, face_normals, _, _, boxes, _, _, original, nodes = lay
    box_at = int(tool_floats[7]) + 12
    box = tool_floats[box_at:box_at + BOX_FLOATS]
    _set_tool_box(core, rel, box)
    contact, t, d, ax, ay, az, vx, vy, vz, status, lower, tested = _nearest_triangle(
        floats, ints, corners, boxes, nodes, n_tri, core, rel, box, hint, size, rel_tol,
        abs_tol, max_iter, W, stack, stack_d2)
    if not contact and _outside(floats, ints, lay, t, ax, ay, az, vx, vy, vz):
        nx, ny, nz = unit3(-vx, -vy, -vz)
        return (status, d - radius, lower - radius, ax, ay, az, nx, ny, nz, tested,
                ints[original + t], t)
    f = face_normals + 3 * t
    fx, fy, fz = floats[f], floats[f + 1], floats[f + 2]
    found, depth, x, y, z, nx, ny, nz, leaf_t, triangle, more = _deepest_shell_point(
        floats, fo, ints, io, tool_floats, tool_ints, rel, t, stack, stack_d2)
    if not found:
        return (STATUS_OK, -radius, -radius, ax, ay, az, fx, fy, fz, tested + more,
                ints[original + t], t)
    return (STATUS_OK, depth - radius, depth - radius, x, y, z, nx, ny, nz, tested + more,
            triangle, leaf_t)
