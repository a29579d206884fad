"""The pair kernels, compiled: signed distance between two convex shapes, and from a point.

Sign and frame rules, for this module and every pair answer built on it: the distance is
positive when the shapes are apart and negative by the penetration depth when they overlap (the
shortest translation of B that separates them); the unit ``normal`` points from A toward B (the
direction B must move to get farther from A: outward from A at its witness); the witnesses
satisfy ``point_b - point_a = distance * normal`` whether apart or overlapping.

How each pair is measured:

* A sphere is a point dilated by its radius and a capsule a segment dilated by its radius, and
  the signed distance of dilated shapes is that of their cores minus the radii (the Minkowski
  difference is dilated by the sum), in overlap as well. So a sphere against anything is the
  point query against the other shape, minus the radius: exact, by the closed-form interior
  distances of the primitives (``support.interior``), GJK outside, EPA inside a convex mesh. The
  point query is this special case with a radius of zero.
* Otherwise GJK runs on the cores' Minkowski difference (a capsule reads as its ``SEGMENT``).
  Apart, its answer is exact to the request's tolerance. In contact, two boxes have their depth
  in closed form, the least overlap over their 15 separating axes (``box_box``, which declines
  a few degenerate poses); EPA gives every other depth: exact to rounding for polytopes (boxes,
  convex meshes, segments against them); against a curved support (a cylinder) EPA stops at
  its tolerance or iteration cap, and says so in the status.
  Two segments that cross have a flat Minkowski difference, of depth zero: two capsules then
  overlap by the sum of their radii, along the common perpendicular of their axes.
"""

from collision_engine._jit import jit
from collision_engine.box_box import box_box_depth
from collision_engine.epa import epa
from collision_engine.gjk import gjk, STATUS_OK
from collision_engine.norms import norm3, unit3
from collision_engine.support import (BOX, CAPSULE, CONVEX_MESH, CYLINDER, interior, POINT,
                                      SEGMENT, SPHERE)

__all__ = ['core_of', 'pair_distance', 'point_distance', 'radius_of']


@jit
def point_distance(kind, floats, fo, ints, io, qx, qy, qz, cx, cy, cz, radius, gx, gy, gz,
                   rel_tol, abs_tol, max_iter, max_epa_iter, W, epa_floats, epa_ints):
    """Signed distance from q to a convex shape: GJK outside, exact interior or EPA inside.

    (cx, cy, cz) and ``radius`` are the shape's bounding sphere, (gx, gy, gz) a first search
    direction from the shape toward q (zero: from the shape's core toward q); W (36,) is GJK's
    scratch, ``epa_floats`` and ``epa_ints`` EPA's (``epa.scratch_size``). Returns (status,
    distance, lower bound, x, y, z, nx, ny, nz, iterations), local frame: the closest point x
    and the outward normal n there, with q = x + distance n.
    """
    s, x, y, z, nx, ny, nz = 0.0, qx, qy, qz, 1.0, 0.0, 0.0
    if kind != CONVEX_MESH:
        s, x, y, z, nx, ny, nz = interior(kind, floats, fo, qx, qy, qz)
        if s <= 0.0:
            return STATUS_OK, s, s, x, y, z, nx, ny, nz, 0
    if gx == 0.0 and gy == 0.0 and gz == 0.0:
        gx, gy, gz = qx - cx, qy - cy, qz - cz
        if kind == CYLINDER or kind == CAPSULE:
            gz = qz - min(max(qz, -floats[fo + 1]), floats[fo + 1])
    shape, point, simplex, supports, rel = _point_pair(kind, floats, fo, ints, io, qx, qy, qz, W)
    status, contact, count, vx, vy, vz, lower, iterations, inv, x, y, z = gjk(
        shape, point, rel, gx, gy, gz, radius, rel_tol, abs_tol, max_iter, simplex, supports)
    if not contact:
        ux, uy, uz = unit3(vx, vy, vz)
        return status, norm3(vx, vy, vz), lower, x, y, z, -ux, -uy, -uz, iterations
    if kind != CONVEX_MESH:
        # Within rounding of a primitive's surface: its exact interior formula holds there.
        return STATUS_OK, s, s, x, y, z, nx, ny, nz, iterations
    status, depth, bound, x, y, z, nx, ny, nz, more = epa(
        shape, point, rel, simplex, supports, count, inv, rel_tol, abs_tol, max_epa_iter,
        epa_floats, epa_ints)
    return status, -depth, -bound, x, y, z, nx, ny, nz, iterations + more


@jit
def _point_pair(kind, floats, fo, ints, io, qx, qy, qz, W):
    """Pose the point q as GJK's B against the packed shape, and split W into GJK's scratch.

    Returns (shape, point, simplex, supports, rel): ``rel`` holds q as the point's pose.
    """
    rel = W[24:36]
    rel[0], rel[1], rel[2], rel[3], rel[4], rel[5], rel[6], rel[7], rel[8] = (
        1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    rel[9], rel[10], rel[11] = qx, qy, qz
    return (kind, floats, fo, ints, io), (POINT, floats, 0, ints, 0), W[:12], W[12:24], rel


@jit
def radius_of(shape):
    """Return the radius a sphere or capsule is dilated by (0 for the other shapes)."""
    if shape[0] == SPHERE or shape[0] == CAPSULE:
        return shape[1][shape[2]]
    return 0.0


@jit
def core_of(shape):
    """Return the shape without its radius: a sphere's centre, a capsule's segment, or it."""
    if shape[0] == SPHERE:
        return (POINT, shape[1], shape[2], shape[3], shape[4])
    if shape[0] == CAPSULE:
        return (SEGMENT, shape[1], shape[2], shape[3], shape[4])
    return shape


@jit
def pair_distance(a, b, rel, gx, gy, gz, size, rel_tol, abs_tol, max_iter, max_epa_iter, W,
                  epa_floats, epa_ints):
    """Signed distance between convex shapes A and B (packed as in ``support``), A's frame.

    ``rel`` (12,) is B's pose in A's frame (``gjk.support_difference``); (gx, gy, gz) a first
    search direction from A toward B (zero: from A's origin toward B's); ``size`` (m) about
    the pair's size (the sum of their bounding radii). W (36,) and the EPA arrays are scratch,
    as for ``point_distance``. Returns (status, distance, lower bound, ax, ay, az, nx, ny, nz,
    iterations): the witness a on A and the unit normal n from A toward B (module docstring);
    B's witness is a + distance n.
    """
    if b[0] == SPHERE:
        return _against_point(a, rel[9], rel[10], rel[11], radius_of(b), gx, gy, gz, size,
                              rel_tol, abs_tol, max_iter, max_epa_iter, W, epa_floats, epa_ints)
    if a[0] == SPHERE:
        return _sphere_against(a, b, rel, gx, gy, gz, size, rel_tol, abs_tol, max_iter,
                               max_epa_iter, W, epa_floats, epa_ints)
    return _between_cores(a, b, rel, gx, gy, gz, size, rel_tol, abs_tol, max_iter,
                          max_epa_iter, W, epa_floats, epa_ints)


@jit
def _against_point(a, qx, qy, qz, radius, gx, gy, gz, size, rel_tol, abs_tol, max_iter,
                   max_epa_iter, W, epa_floats, epa_ints):
    """Measure A against a sphere of ``radius`` at q (A's frame): the point query minus it."""
    status, d, lower, x, y, z, nx, ny, nz, iterations = point_distance(
        a[0], a[1], a[2], a[3], a[4], qx, qy, qz, 0.0, 0.0, 0.0, size, gx, gy, gz, rel_tol,
        abs_tol, max_iter, max_epa_iter, W, epa_floats, epa_ints)
    return status, d - radius, lower - radius, x, y, z, nx, ny, nz, iterations


@jit
def _sphere_against(a, b, rel, gx, gy, gz, size, rel_tol, abs_tol, max_iter, max_epa_iter, W,
                    epa_floats, epa_ints):
    """Sphere A against B: B's point query at A's centre, turned back into A's frame."""
    # A's centre, and the search direction from B toward it, in B's frame: R^T (0 - t), -R^T g.
    qx = -(rel[0] * rel[9] + rel[3] * rel[10] + rel[6] * rel[11])
    qy = -(rel[1] * rel[9] + rel[4] * rel[10] + rel[7] * rel[11])
    qz = -(rel[2] * rel[9] + rel[5] * rel[10] + rel[8] * rel[11])
    hx = -(rel[0] * gx + rel[3] * gy + rel[6] * gz)
    hy = -(rel[1] * gx + rel[4] * gy + rel[7] * gz)
    hz = -(rel[2] * gx + rel[5] * gy + rel[8] * gz)
    status, d, lower, x, y, z, mx, my, mz, iterations = _against_point(
        b, qx, qy, qz, radius_of(a), hx, hy, hz, size, rel_tol, abs_tol, max_iter, max_epa_iter,
        W, epa_floats, epa_ints)
    # (x, y, z) is B's witness and m points from B toward A, in B's frame: A's witness is
    # x + d m, and the normal from A toward B is -m, both taken to A's frame.
    px, py, pz = x + d * mx, y + d * my, z + d * mz
    ax = rel[0] * px + rel[1] * py + rel[2] * pz + rel[9]
    ay = rel[3] * px + rel[4] * py + rel[5] * pz + rel[10]
    az = rel[6] * px + rel[7] * py + rel[8] * pz + rel[11]
    nx = -(rel[0] * mx + rel[1] * my + rel[2] * mz)
    ny = -(rel[3] * mx + rel[4] * my + rel[5] * mz)
    nz = -(rel[6] * mx + rel[7] * my + rel[8] * mz)
    return status, d, lower, ax, ay, az, nx, ny, nz, iterations


@jit
def _between_cores(a, b, rel, gx, gy, gz, size, rel_tol, abs_tol, max_iter, max_epa_iter, W,
                   epa_floats, epa_ints):
    """GJK on the cores (EPA in contact), then the radii subtracted (module docstring)."""
    core_a, core_b = core_of(a), core_of(b)
    if gx == 0.0 and gy == 0.0 and gz == 0.0:
        gx, gy, gz = rel[9], rel[10], rel[11]
    simplex, supports = W[:12], W[12:24]
    status, contact, count, vx, vy, vz, lower, iterations, inv, x, y, z = gjk(
        core_a, core_b, rel, gx, gy, gz, size, rel_tol, abs_tol, max_iter, simplex, supports)
    if not contact:
        d = norm3(vx, vy, vz)
        nx, ny, nz = unit3(-vx, -vy, -vz)
    elif core_a[0] == SEGMENT and core_b[0] == SEGMENT:
        d = lower = 0.0
        nx, ny, nz = _crossing_normal(rel)
    else:
        status, d, lower, x, y, z, nx, ny, nz, more = _depth(
            core_a, core_b, rel, simplex, supports, count, inv, rel_tol, abs_tol, max_epa_iter,
            epa_floats, epa_ints)
        iterations += more
    ra, rb = radius_of(a), radius_of(b)
    return (status, d - ra - rb, lower - ra - rb, x + ra * nx, y + ra * ny, z + ra * nz,
            nx, ny, nz, iterations)


@jit
def _depth(a, b, rel, simplex, supports, count, inv, rel_tol, abs_tol, max_epa_iter,
           epa_floats, epa_ints):
    """Signed distance of overlapping cores: two boxes' closed form, else EPA's.

    Returns (status, distance, lower bound, x, y, z, nx, ny, nz, EPA iterations).
    """
    if a[0] == BOX and b[0] == BOX:
        fa, fb = a[1], b[1]
        ok, depth, x, y, z, nx, ny, nz = box_box_depth(
            (fa[a[2]], fa[a[2] + 1], fa[a[2] + 2]), (fb[b[2]], fb[b[2] + 1], fb[b[2] + 2]), rel)
        if ok:
            return STATUS_OK, -depth, -depth, x, y, z, nx, ny, nz, 0
    status, depth, bound, x, y, z, nx, ny, nz, more = epa(
        a, b, rel, simplex, supports, count, inv, rel_tol, abs_tol, max_epa_iter, epa_floats,
        epa_ints)
    return status, -depth, -bound, x, y, z, nx, ny, nz, more


@jit
def _crossing_normal(rel):
    """Return the common perpendicular of crossing segments (A's axis z, B's R e_z), to B.

    Parallel segments have no single one: any perpendicular of A's axis serves.
    """
    nx, ny, nz = unit3(-rel[5], rel[2], 0.0)  # e_z x (R e_z)
    if nx == 0.0 and ny == 0.0:
        nx = 1.0
    if nx * rel[9] + ny * rel[10] < 0.0:
        nx, ny = -nx, -ny
    return nx, ny, nz
