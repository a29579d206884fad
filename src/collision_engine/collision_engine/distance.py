"""One shape, one point: a coal/FCL-like request/result API over the same kernels as a scene.

``distance(shape, pose, point, request)`` answers with a fresh, frozen ``DistanceResult`` (no
stale minimum can leak from a reused result, the trap of FCL and coal). The request carries the
tolerances, the iteration caps and a warm-start search direction, so that their effect on
accuracy and speed can be swept. Not thread-safe for one shape object: its packed form is cached
and reused between calls.
"""

from dataclasses import dataclass
import weakref

import numpy as np

from collision_engine import _kernels
from collision_engine.gjk import STATUS_INVALID_INPUT
from collision_engine.transforms import Pose
from haptic_contract.checks import finite_components, finite_number, whole_number

__all__ = ['DistanceRequest', 'DistanceResult', 'distance']

_PACKED = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class DistanceRequest:
    """How hard to work for one answer.

    Attributes
    ----------
    rel_tol : float
        GJK/EPA stop when the gap between their upper and lower bounds is below this fraction
        of the distance.
    abs_tol : float, m
        ... or below this many metres. Both are floored at float64 rounding.
    max_iterations : int
        GJK iteration cap; reaching it gives status NOT_CONVERGED and the best upper bound.
    max_epa_iterations : int
        EPA iteration cap (points inside a convex mesh).
    guess : (3,) float or None
        First GJK search direction, world frame, from the shape toward the point (e.g. the
        previous answer's normal). None: from the shape's centre or axis. Meshes ignore it.
    """

    rel_tol: float = 1e-12
    abs_tol: float = 1e-12
    max_iterations: int = 100
    max_epa_iterations: int = 128
    guess: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        for name in ('rel_tol', 'abs_tol'):
            object.__setattr__(self, name, finite_number(getattr(self, name),
                                                         f'DistanceRequest.{name}', minimum=0.0))
        for name in ('max_iterations', 'max_epa_iterations'):
            object.__setattr__(self, name, whole_number(getattr(self, name),
                                                        f'DistanceRequest.{name}'))
        if self.guess is not None:
            object.__setattr__(self, 'guess', finite_components(self.guess, 3,
                                                                'DistanceRequest.guess'))


@dataclass(frozen=True, eq=False)
class DistanceResult:
    """The signed distance from a point to one shape (world frame, m).

    Attributes
    ----------
    distance : float, m
        Negative inside.
    lower_bound : float, m
        GJK's proven lower bound (``distance`` is the upper one), from its last support plane.
        Farther than ~1e-9 of the shape's size from the surface it meets ``distance`` within
        the request's tolerance; nearer, that plane's normal carries the rounding of a vector
        as short as the distance, so the bound can be loose (even 0) while ``distance`` stays
        exact to rounding. Inside a primitive or a mesh it equals ``distance``.
    point : (3,) float64, m
        Closest point on the shape's surface.
    normal : (3,) float64
        Unit outward surface normal at ``point``.
    witness_points : (2, 3) float64, m
        ``point`` and the query point, in the order of coal's ``nearest_points``.
    iterations : int
        GJK and EPA iterations (triangles tested for a mesh).
    status : int
        0 OK or 1 NOT_CONVERGED.
    triangle : int
        Nearest triangle of a mesh, -1 otherwise.
    """

    distance: float
    lower_bound: float
    point: np.ndarray
    normal: np.ndarray
    witness_points: np.ndarray
    iterations: int
    status: int
    triangle: int


def _packed(shape, request: DistanceRequest) -> tuple[np.ndarray, np.ndarray]:
    """Pack the shape as a one-object scene (once), its scratch sized for the EPA cap."""
    floats, ints = _PACKED.get(shape, (None, None))
    if ints is None or ints[2] != request.max_epa_iterations:
        floats, ints = _kernels.pack_scene(
            [shape], [Pose()], tip_radius=0.0, rel_tol=0.0, abs_tol=0.0, max_iterations=1,
            max_epa_iterations=request.max_epa_iterations)
        _PACKED[shape] = floats, ints
    floats[1], floats[2] = request.rel_tol, request.abs_tol
    ints[1], ints[2] = request.max_iterations, request.max_epa_iterations
    return floats, ints


def distance(shape, pose: Pose, point, request: DistanceRequest = DistanceRequest()
             ) -> DistanceResult:
    """Signed distance from a point to one posed shape.

    Parameters
    ----------
    shape : Box, Sphere, Cylinder, Capsule, ConvexMesh or TriangleMesh
    pose : Pose
        The shape's local frame in the world frame.
    point : (3,) float, m, world frame
    request : DistanceRequest

    Returns
    -------
    DistanceResult

    Raises
    ------
    ValueError
        If ``point`` is not 3 finite numbers.
    """
    values = np.asarray(point, dtype=np.float64)
    if values.shape != (3,):
        raise ValueError(f'point must be 3 numbers (m), got {point!r}')
    floats, ints = _packed(shape, request)
    _kernels.place_object(floats, ints, 0, shape, pose)
    gx, gy, gz = request.guess or (0.0, 0.0, 0.0)
    row = np.empty(_kernels.OUT_SIZE)
    _kernels.query_shape(floats, ints, row, *values.tolist(), gx, gy, gz)
    if row[9] == STATUS_INVALID_INPUT:
        raise ValueError(f'point must be finite, got {values.tolist()}')
    closest = row[1:4].copy()
    witnesses = np.array([closest, values])
    for array in (closest, witnesses):
        array.setflags(write=False)
    normal = row[4:7].copy()
    normal.setflags(write=False)
    return DistanceResult(float(row[0]), float(row[14]), closest, normal, witnesses,
                          int(row[8]), int(row[9]), int(row[13]))
