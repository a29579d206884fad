"""The compiled entry points: one call answers one whole query, from one packed scene.

A call from Python into numba costs about 0.3-1 us plus about 0.2 us per array argument, as
much as a primitive's whole computation, so each query is one call taking the packed scene as
one float64 and one int64 array, an output row, and the point as three floats.

Packed scene layout
-------------------
``floats``: ``[tip radius, rel_tol, abs_tol, scratch offset]``, then per object a record of
``OBJECT_FLOATS`` values: rotation (9, row-major, local to world), translation (3),
bounding-sphere centre in the local frame (3) and in the world frame (3), bounding-sphere radius
(1); then the shapes' float blocks; then scratch space: GJK's simplex (12), the support points
of A it came from (12) and B's pose in A's frame (12), the search stack's box distances (s),
EPA's floats (``epa.scratch_size``).
``ints``: ``[object count, GJK iteration cap, EPA iteration cap, scratch offset]``, then per
object ``[kind, object float record offset, shape float offset, shape int offset, hint]``
(``hint`` is the last nearest triangle of a mesh, rewritten by every query as a warm start),
then the shapes' int blocks (layouts in ``support`` and ``bvh``), then scratch space: the
search stack's length s, sized for the deepest mesh tree of the scene
(``bvh.search_stack_size``), its nodes (s), EPA's ints.

The scratch space lives in the packed arrays because allocating it costs as much as a
primitive's query; so does the hint. Hence one packed scene must not serve two threads at once.

Output rows (``OUT_SIZE`` float64 each, in one flat array), world frame, m
--------------------------------------------------------------------------
distance (tip radius subtracted), closest point (3), outward normal (3), object index (-1 for
none), iterations, status, tip (3), triangle index (-1 unless a mesh), lower bound on the
distance (tip radius subtracted; equal to the distance to rounding when converged).
"""

import math

import numpy as np

from collision_engine import bvh
from collision_engine._jit import jit
from collision_engine.epa import scratch_size
from collision_engine.gjk import (STATUS_INVALID_INPUT, STATUS_NO_OBJECT, STATUS_NOT_CONVERGED,
                                  STATUS_OK)
from collision_engine.narrowphase import pair_distance, point_distance
from collision_engine.norms import norm3
from collision_engine.support import pack_convex, TRIANGLE_MESH
from collision_engine.tool import FLOAT_HEADER as TOOL_FLOAT_HEADER
from collision_engine.tool import INT_HEADER as TOOL_INT_HEADER
from collision_engine.tool_mesh import mesh_tool_distance

__all__ = ['OUT_SIZE', 'OBJECT_FLOATS', 'QUATERNION_TOLERANCE', 'pack_scene', 'place_object',
           'query_point', 'query_points', 'query_each_object', 'query_shape', 'query_tool']

OUT_SIZE = 15
OBJECT_FLOATS = 19
_HEADER_FLOATS = 4
_HEADER_INTS = 4
_OBJECT_INTS = 5
_GJK_SCRATCH = 36  # simplex (12), A's support points (12), B's pose in A's frame (12)
QUATERNION_TOLERANCE = 1e-6  # a tool pose's quaternion norm may be off 1 by this much


def pack_scene(shapes: list, poses: list, *, tip_radius: float, rel_tol: float, abs_tol: float,
               max_iterations: int, max_epa_iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """Pack shapes and their poses into the layout above.

    Parameters
    ----------
    shapes : list of shapes (``shapes`` module)
    poses : list of Pose, local to world
    tip_radius : float, m

    Returns
    -------
    floats : (k,) float64
    ints : (j,) int64
    """
    n = len(shapes)
    float_blocks, int_blocks, records, table = [], [], [], []
    float_at = _HEADER_FLOATS + OBJECT_FLOATS * n
    int_at = _HEADER_INTS + _OBJECT_INTS * n
    for index, (shape, pose) in enumerate(zip(shapes, poses)):
        kind, shape_floats, shape_ints = _pack_shape(shape)
        records.append(_object_record(shape, pose))
        table.append([kind, _HEADER_FLOATS + OBJECT_FLOATS * index, float_at, int_at, -1])
        float_blocks.append(shape_floats)
        int_blocks.append(shape_ints)
        float_at += len(shape_floats)
        int_at += len(shape_ints)
    stack = max([bvh.search_stack_size(block) for (kind, *_), block in zip(table, int_blocks)
                 if kind == TRIANGLE_MESH], default=1)
    epa_floats, epa_ints = scratch_size(max_epa_iterations)
    floats = np.concatenate([[tip_radius, rel_tol, abs_tol, float_at], *records, *float_blocks,
                             np.zeros(_GJK_SCRATCH + stack + epa_floats)])
    ints = np.concatenate([[n, max_iterations, max_epa_iterations, int_at], *table, *int_blocks,
                           [stack], np.zeros(stack + epa_ints)])
    return floats.astype(np.float64), ints.astype(np.int64)


def _object_record(shape, pose) -> np.ndarray:
    centre, radius = shape.bounding_sphere()
    return np.concatenate((pose.rotation.ravel(), pose.translation, centre,
                           pose.to_world(centre), [radius]))


def place_object(floats: np.ndarray, ints: np.ndarray, index: int, shape, pose) -> None:
    """Move object ``index`` of a packed scene to ``pose`` (its shape stays packed)."""
    r = ints[_HEADER_INTS + _OBJECT_INTS * index + 1]
    floats[r:r + OBJECT_FLOATS] = _object_record(shape, pose)


def _pack_shape(shape) -> tuple[int, np.ndarray, np.ndarray]:
    if shape.kind == TRIANGLE_MESH:
        floats, ints = bvh.pack_triangle_mesh(shape.vertices, shape.faces,
                                              grid_vertices=bvh.GRID_VERTICES)
        return TRIANGLE_MESH, floats, ints
    return pack_convex(shape)


@jit
def _object_distance(floats, ints, k, px, py, pz, gx, gy, gz, W, stack, stack_d2):
    """Signed distance from the world point p to object k, in the world frame.

    Returns (status, distance, lower bound, x, y, z, nx, ny, nz, iterations, triangle).
    """
    entry = _HEADER_INTS + _OBJECT_INTS * k
    kind, r, fo, io = ints[entry], ints[entry + 1], ints[entry + 2], ints[entry + 3]
    dx, dy, dz = px - floats[r + 9], py - floats[r + 10], pz - floats[r + 11]
    qx = floats[r] * dx + floats[r + 3] * dy + floats[r + 6] * dz
    qy = floats[r + 1] * dx + floats[r + 4] * dy + floats[r + 7] * dz
    qz = floats[r + 2] * dx + floats[r + 5] * dy + floats[r + 8] * dz
    triangle = -1
    if kind == TRIANGLE_MESH:
        distance, x, y, z, nx, ny, nz, leaf_t, triangle, iterations = bvh.mesh_distance(
            floats, fo, ints, io, qx, qy, qz, ints[entry + 4], stack, stack_d2, -1.0)
        ints[entry + 4] = leaf_t
        status, lower = STATUS_OK, distance
    else:
        lx = floats[r] * gx + floats[r + 3] * gy + floats[r + 6] * gz
        ly = floats[r + 1] * gx + floats[r + 4] * gy + floats[r + 7] * gz
        lz = floats[r + 2] * gx + floats[r + 5] * gy + floats[r + 8] * gz
        epa_floats, epa_ints = _epa_scratch(floats, ints)
        status, distance, lower, x, y, z, nx, ny, nz, iterations = point_distance(
            kind, floats, fo, ints, io, qx, qy, qz,
            floats[r + 12], floats[r + 13], floats[r + 14], floats[r + 18], lx, ly, lz,
            floats[1], floats[2], ints[1], ints[2], W, epa_floats, epa_ints)
    wx, wy, wz, mx, my, mz = _to_world(floats, r, x, y, z, nx, ny, nz)
    return status, distance, lower, wx, wy, wz, mx, my, mz, iterations, triangle


@jit
def _to_world(floats, r, x, y, z, nx, ny, nz):
    """Return the point (x, y, z) and the direction n of object record r's frame in the world's."""
    return (floats[r] * x + floats[r + 1] * y + floats[r + 2] * z + floats[r + 9],
            floats[r + 3] * x + floats[r + 4] * y + floats[r + 5] * z + floats[r + 10],
            floats[r + 6] * x + floats[r + 7] * y + floats[r + 8] * z + floats[r + 11],
            floats[r] * nx + floats[r + 1] * ny + floats[r + 2] * nz,
            floats[r + 3] * nx + floats[r + 4] * ny + floats[r + 5] * nz,
            floats[r + 6] * nx + floats[r + 7] * ny + floats[r + 8] * nz)


@jit
def _write(out, row, distance, x, y, z, nx, ny, nz, index, iterations, status, px, py, pz,
           triangle, lower):
    """Fill output row ``row`` of the flat output array (rows of ``OUT_SIZE``)."""
    base = row * OUT_SIZE
    out[base] = distance
    out[base + 1], out[base + 2], out[base + 3] = x, y, z
    out[base + 4], out[base + 5], out[base + 6] = nx, ny, nz
    out[base + 7] = index
    out[base + 8] = iterations
    out[base + 9] = status
    out[base + 10], out[base + 11], out[base + 12] = px, py, pz
    out[base + 13] = triangle
    out[base + 14] = lower


@jit
def _invalid(out, row, px, py, pz):
    """Write an INVALID_INPUT row and return true when p is not finite."""
    if math.isfinite(px) and math.isfinite(py) and math.isfinite(pz):
        return False
    _write(out, row, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, -1, 0,
           STATUS_INVALID_INPUT, px, py, pz, -1, np.nan)
    return True


@jit
def _nearest(floats, ints, out, row, px, py, pz, W, stack, stack_d2):
    """Nearest object to p (signed), written to out[row]."""
    if _invalid(out, row, px, py, pz):
        return
    best = best_lower = np.inf
    best_status, best_k, best_t, total = STATUS_NO_OBJECT, -1, -1, 0
    x = y = z = nx = ny = nz = np.nan
    unsure = np.inf
    for k in range(ints[0]):
        r = ints[_HEADER_INTS + _OBJECT_INTS * k + 1]
        reach = norm3(px - floats[r + 15], py - floats[r + 16], pz - floats[r + 17])
        if reach - floats[r + 18] >= best:
            continue
        status, d, lower, ox, oy, oz, mx, my, mz, iterations, t = _object_distance(
            floats, ints, k, px, py, pz, 0.0, 0.0, 0.0, W, stack, stack_d2)
        total += iterations
        if status != STATUS_OK:
            unsure = min(unsure, lower)
        if d < best:
            best, best_lower, best_status, best_k, best_t = d, lower, status, k, t
            x, y, z, nx, ny, nz = ox, oy, oz, mx, my, mz
    if unsure < best:
        # An unconverged object might be nearer than the answer: the answer is a bound only.
        best_status = STATUS_NOT_CONVERGED
    _write(out, row, best - floats[0], x, y, z, nx, ny, nz, best_k, total, best_status,
           px, py, pz, best_t, min(best_lower, unsure) - floats[0])


@jit
def _scratch(floats, ints):
    """View the scratch space: GJK's (``_GJK_SCRATCH``,), the search stack, its distances."""
    f = int(floats[3])
    i = ints[3]
    stack = ints[i]
    g = f + _GJK_SCRATCH
    return floats[f:g], ints[i + 1:i + 1 + stack], floats[g:g + stack]


@jit
def _epa_scratch(floats, ints):
    """View EPA's scratch space, for the scene's EPA iteration cap: (floats, ints)."""
    f = int(floats[3])
    i = ints[3]
    stack = ints[i]
    n_floats, n_ints = scratch_size(ints[2])
    g = f + _GJK_SCRATCH + stack
    return floats[g:g + n_floats], ints[i + 1 + stack:i + 1 + stack + n_ints]


@jit
def query_point(floats, ints, out, px, py, pz):
    """Nearest object to the world point p, written to ``out`` (OUT_SIZE,)."""
    W, stack, stack_d2 = _scratch(floats, ints)
    _nearest(floats, ints, out, 0, px, py, pz, W, stack, stack_d2)


@jit
def query_points(floats, ints, points, out):
    """Nearest object to each world point, points (n, 3) to out (n * OUT_SIZE,)."""
    W, stack, stack_d2 = _scratch(floats, ints)
    for row in range(points.shape[0]):
        _nearest(floats, ints, out, row, points[row, 0], points[row, 1], points[row, 2],
                 W, stack, stack_d2)


@jit
def query_each_object(floats, ints, out, px, py, pz):
    """Signed distance from p to every object, out (objects * OUT_SIZE,)."""
    W, stack, stack_d2 = _scratch(floats, ints)
    for k in range(ints[0]):
        status, d, lower, x, y, z, nx, ny, nz, iterations, t = _object_distance(
            floats, ints, k, px, py, pz, 0.0, 0.0, 0.0, W, stack, stack_d2)
        _write(out, k, d - floats[0], x, y, z, nx, ny, nz, k, iterations, status,
               px, py, pz, t, lower - floats[0])


@jit
def query_shape(floats, ints, out, px, py, pz, gx, gy, gz):
    """Object 0 alone with a first search direction (world frame): the single-shape API."""
    if _invalid(out, 0, px, py, pz):
        return
    W, stack, stack_d2 = _scratch(floats, ints)
    status, d, lower, x, y, z, nx, ny, nz, iterations, t = _object_distance(
        floats, ints, 0, px, py, pz, gx, gy, gz, W, stack, stack_d2)
    _write(out, 0, d - floats[0], x, y, z, nx, ny, nz, 0, iterations, status, px, py, pz,
           t, lower - floats[0])


@jit
def _unit_quaternion(qx, qy, qz, qw):
    """Whether the quaternion is a unit one, and its rotation matrix (row-major).

    A quaternion whose norm is off 1 by more than ``QUATERNION_TOLERANCE``, or with NaN or
    infinite parts, is refused: it is a corrupt pose, not a rotation to renormalise.
    """
    norm = norm3(qx, qy, norm3(qz, qw, 0.0))
    valid = abs(norm - 1.0) <= QUATERNION_TOLERANCE
    if not valid:
        norm = 1.0
    x, y, z, w = qx / norm, qy / norm, qz / norm, qw / norm
    rotation = (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w),
                2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w),
                2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y))
    return valid, rotation


@jit
def _tool_in_object(floats, r, R, px, py, pz, rel):
    """Write the tool's pose (R, p: scene frame) in the frame of the object at record r."""
    dx, dy, dz = px - floats[r + 9], py - floats[r + 10], pz - floats[r + 11]
    for i in range(3):
        for j in range(3):
            rel[3 * i + j] = (floats[r + i] * R[j] + floats[r + 3 + i] * R[3 + j]
                              + floats[r + 6 + i] * R[6 + j])
        rel[9 + i] = floats[r + i] * dx + floats[r + 3 + i] * dy + floats[r + 6 + i] * dz


@jit
def query_tool(floats, ints, tool_floats, tool_ints, out, px, py, pz, qx, qy, qz, qw):
    """Nearest object to the tool posed at p with quaternion q (scene frame), to ``out``.

    The tool is packed by ``tool.pack_tool``. The output row is that of the point queries with
    the tool's witness point in place of the tip (``Scene.query_tool``).
    """
    valid, R = _unit_quaternion(qx, qy, qz, qw)
    if not valid or _invalid(out, 0, px, py, pz):
        _write(out, 0, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, -1, 0,
               STATUS_INVALID_INPUT, px, py, pz, -1, np.nan)
        return
    W, stack, stack_d2 = _scratch(floats, ints)
    epa_floats, epa_ints = _epa_scratch(floats, ints)
    rel = tool_floats[int(tool_floats[7]):int(tool_floats[7]) + 12]
    tool = (tool_ints[0], tool_floats, TOOL_FLOAT_HEADER, tool_ints, TOOL_INT_HEADER)
    bound = tool_floats[1]
    cx = R[0] * tool_floats[2] + R[1] * tool_floats[3] + R[2] * tool_floats[4] + px
    cy = R[3] * tool_floats[2] + R[4] * tool_floats[3] + R[5] * tool_floats[4] + py
    cz = R[6] * tool_floats[2] + R[7] * tool_floats[3] + R[8] * tool_floats[4] + pz
    best = best_lower = np.inf
    best_status, best_k, best_t, total = STATUS_NO_OBJECT, -1, -1, 0
    x = y = z = nx = ny = nz = np.nan
    for k in range(ints[0]):
        entry = _HEADER_INTS + _OBJECT_INTS * k
        kind, r, fo, io = ints[entry], ints[entry + 1], ints[entry + 2], ints[entry + 3]
        reach = norm3(cx - floats[r + 15], cy - floats[r + 16], cz - floats[r + 17])
        if reach - floats[r + 18] - bound >= best:
            continue
        _tool_in_object(floats, r, R, px, py, pz, rel)
        size = floats[r + 18] + bound
        t = -1
        if kind == TRIANGLE_MESH:
            status, d, lower, ox, oy, oz, mx, my, mz, iterations, t, leaf_t = mesh_tool_distance(
                floats, fo, ints, io, tool_floats, tool_ints, tool_ints[0], rel, ints[entry + 4],
                size, floats[1], floats[2], ints[1], W, stack, stack_d2)
            ints[entry + 4] = leaf_t
        else:
            status, d, lower, ox, oy, oz, mx, my, mz, iterations = pair_distance(
                (kind, floats, fo, ints, io), tool, rel, 0.0, 0.0, 0.0, size, floats[1],
                floats[2], ints[1], ints[2], W, epa_floats, epa_ints)
        total += iterations
        if d < best:
            best, best_lower, best_status, best_k, best_t = d, lower, status, k, t
            x, y, z, nx, ny, nz = _to_world(floats, r, ox, oy, oz, mx, my, mz)
    _write(out, 0, best, x, y, z, nx, ny, nz, best_k, total, best_status,
           x + best * nx, y + best * ny, z + best * nz, best_t, best_lower)
