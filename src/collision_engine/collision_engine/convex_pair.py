"""Signed distance between two posed convex shapes: the public pair query.

``distance_between(shape_a, pose_a, shape_b, pose_b, request)`` answers with a fresh, frozen
``PairResult``, as ``distance`` does for a point. The sign, normal and witness rules, and how
each pair is measured (closed forms for spheres and capsules, GJK apart, EPA or, for two boxes,
a closed form in overlap), are in ``narrowphase``, which holds the compiled kernels.
"""

from dataclasses import dataclass
import weakref

import numpy as np

from collision_engine._jit import jit
from collision_engine.distance import DistanceRequest
from collision_engine.epa import scratch_size
from collision_engine.narrowphase import pair_distance
from collision_engine.support import BOX, CAPSULE, CONVEX_MESH, CYLINDER, pack_convex, SPHERE

__all__ = ['PairResult', 'distance_between']

_PACKED = weakref.WeakKeyDictionary()
_CONVEX_KINDS = (BOX, SPHERE, CYLINDER, CAPSULE, CONVEX_MESH)


@jit
def _pair_kernel(kind_a, floats_a, ints_a, kind_b, floats_b, ints_b, rel, gx, gy, gz, size,
                 rel_tol, abs_tol, max_iter, max_epa_iter, W, epa_floats, epa_ints):
    """``pair_distance`` on two shapes packed apart (``pack_convex``): the public API's call."""
    return pair_distance((kind_a, floats_a, 0, ints_a, 0), (kind_b, floats_b, 0, ints_b, 0),
                         rel, gx, gy, gz, size, rel_tol, abs_tol, max_iter, max_epa_iter, W,
                         epa_floats, epa_ints)


@dataclass(frozen=True, eq=False)
class PairResult:
    """The signed distance between two posed convex shapes (world frame, m).

    Attributes
    ----------
    distance : float, m
        Positive apart, minus the penetration depth when overlapping.
    lower_bound : float, m
        The proven bound below ``distance`` (GJK's support plane apart, EPA's in overlap);
        equal to it within the request's tolerance when converged.
    witness_points : (2, 3) float64, m
        The point of A and the point of B, ``B - A = distance * normal``, in the order of
        coal's ``nearest_points``.
    normal : (3,) float64
        Unit, from A toward B: outward from A at its witness.
    iterations : int
        GJK and EPA iterations.
    status : int
        0 OK or 1 NOT_CONVERGED (the distance is then the best bound found).
    """

    distance: float
    lower_bound: float
    witness_points: np.ndarray
    normal: np.ndarray
    iterations: int
    status: int


def _packed(shape) -> tuple:
    """Pack a convex shape once (kind, floats, ints, bounding radius); refuse a mesh."""
    packed = _PACKED.get(shape)
    if packed is None:
        if getattr(shape, 'kind', None) not in _CONVEX_KINDS:
            raise ValueError(f'{shape!r} is not a convex shape (Box, Sphere, Cylinder, Capsule '
                             'or ConvexMesh)')
        centre, radius = shape.bounding_sphere()
        packed = (*pack_convex(shape), float(np.linalg.norm(centre)) + radius)
        _PACKED[shape] = packed
    return packed


def distance_between(shape_a, pose_a, shape_b, pose_b,
                     request: DistanceRequest = DistanceRequest()) -> PairResult:
    """Signed distance between two convex shapes, each with its own pose.

    Parameters
    ----------
    shape_a, shape_b : Box, Sphere, Cylinder, Capsule or ConvexMesh
    pose_a, pose_b : Pose
        Each shape's local frame in the world frame.
    request : DistanceRequest
        Tolerances, iteration caps, and ``guess``: a first search direction from A toward B,
        world frame (e.g. the previous answer's normal).

    Returns
    -------
    PairResult

    Raises
    ------
    ValueError
        If a shape is not convex (a ``TriangleMesh``: use ``Scene.query_tool``).
    """
    kind_a, floats_a, ints_a, radius_a = _packed(shape_a)
    kind_b, floats_b, ints_b, radius_b = _packed(shape_b)
    rotation_a = pose_a.rotation
    rel = np.concatenate(((rotation_a.T @ pose_b.rotation).ravel(),
                          rotation_a.T @ (pose_b.translation - pose_a.translation)))
    gx, gy, gz = (rotation_a.T @ request.guess).tolist() if request.guess else (0.0, 0.0, 0.0)
    epa_floats, epa_ints = scratch_size(request.max_epa_iterations)
    status, d, lower, ax, ay, az, nx, ny, nz, iterations = _pair_kernel(
        kind_a, floats_a, ints_a, kind_b, floats_b, ints_b, rel, gx, gy, gz,
        radius_a + radius_b, request.rel_tol, request.abs_tol, request.max_iterations,
        request.max_epa_iterations, np.empty(36), np.empty(epa_floats),
        np.empty(epa_ints, dtype=np.int64))
    point_a = pose_a.to_world(np.array([ax, ay, az]))
    normal = pose_a.vector_to_world(np.array([nx, ny, nz]))
    witnesses = np.array([point_a, point_a + d * normal])
    for array in (witnesses, normal):
        array.setflags(write=False)
    return PairResult(float(d), float(lower), witnesses, normal, int(iterations), int(status))
