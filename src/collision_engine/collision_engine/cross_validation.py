"""Cross-check our signed distance against FCL (python-fcl) on every N-th query.

FCL is an independent implementation, so a disagreement points at a bug on one side. It is
imported only when a scene enables this check. What the comparison can honestly reach depends
on what FCL computes exactly (measured with python-fcl 0.7.0.11 against analytic and brute-force
truth; see ``fcl_model``):

=============  ============================  ===========================================
our shape      FCL model                     FCL's own error
=============  ============================  ===========================================
Box            ``fcl.Box``, signed           about the probe radius
Sphere         ``fcl.Sphere``, signed        up to ~3 % of |d| (its GJK stops early)
Capsule        ``fcl.Capsule``, signed       up to ~3 % of |d|
Cylinder       ``fcl.Convex``, 512-gon       tessellation r (1 - cos(pi/512)) plus ~3 % of
                                             |d| (``fcl.Cylinder`` is mm off at the rim)
ConvexMesh     ``fcl.Convex``, signed        ~1e-9 m near the surface, ~3 % of |d| far
TriangleMesh   ``fcl.BVHModel``, UNSIGNED    exact to rounding, but inside it returns the
                                             positive distance: |d| is compared, and the
                                             sign is checked only by our ground-truth tests
=============  ============================  ===========================================

So a check passes when ``|ours - fcl| <= tolerance + relative |d| + model error``, with the
scene's ``tolerance`` on top of FCL's error; a closest point passes within that tolerance plus
the distance along the surface a curved shape's closest point can move for that distance error,
``sqrt(2 R tol)``. Traps handled here: a fresh ``DistanceResult`` per call (FCL only overwrites a
smaller distance, so a reused one goes stale), the probe sphere's radius added back, a BVH's
nearest point given in the mesh's local frame (shapes' are in the world frame), and any FCL
exception counted and reported, never raised into the loop.
"""

from dataclasses import dataclass
import math

import numpy as np

from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere, TriangleMesh

__all__ = ['CrossValidationStats', 'FclCrossValidator', 'PROBE_RADIUS', 'fcl_model']

PROBE_RADIUS = 1e-9
CYLINDER_SIDES = 512
FCL_RELATIVE_ERROR = 0.05


@dataclass(frozen=True)
class CrossValidationStats:
    """Running totals of the FCL cross-check.

    Attributes
    ----------
    checks : int
        Queries compared with FCL.
    disagreements : int
        Checks whose distance or closest point differed beyond the tolerance.
    errors : int
        Checks where FCL raised (counted, not propagated).
    max_discrepancy : float, m
        Largest ``|distance - fcl_distance|`` seen.
    max_point_discrepancy : float, m
        Largest distance between our closest point and FCL's.
    last_error : str
        The last FCL exception, '' if none.
    """

    checks: int = 0
    disagreements: int = 0
    errors: int = 0
    max_discrepancy: float = 0.0
    max_point_discrepancy: float = 0.0
    last_error: str = ''


@dataclass(frozen=True)
class _Model:
    geometry: object
    signed: bool
    relative_error: float
    absolute_error: float
    radius: float
    pose: object


def fcl_model(shape):
    """Make the FCL geometry that stands for one of our shapes; say FCL's error on it.

    Returns
    -------
    geometry : fcl.CollisionGeometry
    signed : bool
        False for a BVH (FCL gives the unsigned distance).
    relative_error : float
        FCL's error as a fraction of |d|.
    absolute_error : float, m
        FCL's error that does not scale with |d| (probe, tessellation).
    """
    import fcl

    probe = 2.0 * PROBE_RADIUS
    if isinstance(shape, Box):
        return fcl.Box(*shape.size), True, 0.0, probe
    if isinstance(shape, Sphere):
        return fcl.Sphere(shape.radius), True, FCL_RELATIVE_ERROR, probe
    if isinstance(shape, Capsule):
        return fcl.Capsule(shape.radius, shape.length), True, FCL_RELATIVE_ERROR, probe
    if isinstance(shape, Cylinder):
        angles = np.linspace(0.0, 2.0 * np.pi, CYLINDER_SIDES, endpoint=False)
        ring = np.column_stack((shape.radius * np.cos(angles), shape.radius * np.sin(angles)))
        half = 0.5 * shape.height
        hull = ConvexMesh(np.vstack((np.column_stack((ring, np.full(len(ring), half))),
                                     np.column_stack((ring, np.full(len(ring), -half))))))
        sagitta = shape.radius * (1.0 - math.cos(math.pi / CYLINDER_SIDES))
        return _convex(fcl, hull), True, FCL_RELATIVE_ERROR, probe + sagitta
    if isinstance(shape, ConvexMesh):
        return _convex(fcl, shape), True, FCL_RELATIVE_ERROR, probe
    if isinstance(shape, TriangleMesh):
        model = fcl.BVHModel()
        model.beginModel(len(shape.vertices), len(shape.faces))
        model.addSubModel(shape.vertices, shape.faces)
        model.endModel()
        return model, False, 0.0, probe
    raise TypeError(f'no FCL model for {type(shape).__name__}')


def _convex(fcl, hull: ConvexMesh):
    faces = np.column_stack((np.full(len(hull.faces), 3), hull.faces)).ravel()
    return fcl.Convex(hull.vertices, len(hull.faces), faces)


class FclCrossValidator:
    """Compares every ``every``-th answer with FCL and keeps the running totals.

    Parameters
    ----------
    shapes : list of shapes
    poses : list of Pose
        Local to world, one per shape.
    every : int
        Check queries 0, every, 2 every, ...
    tolerance : float, m
        Allowed discrepancy beyond FCL's own error (module docstring).
    tip_radius : float, m
        The scene's tip radius, which our distances have subtracted.
    """

    def __init__(self, shapes: list, poses: list, *, every: int, tolerance: float,
                 tip_radius: float = 0.0) -> None:
        import fcl

        self._fcl = fcl
        self._every = every
        self._tolerance = tolerance
        self._tip_radius = tip_radius
        self._count = 0
        self._objects = []
        for shape, pose in zip(shapes, poses):
            geometry, signed, relative, absolute = fcl_model(shape)
            _, radius = shape.bounding_sphere()
            transform = fcl.Transform(np.asarray(pose.rotation), np.asarray(pose.translation))
            self._objects.append((fcl.CollisionObject(geometry, transform),
                                  _Model(geometry, signed, relative, absolute, radius, pose)))
        self._probe = fcl.CollisionObject(fcl.Sphere(PROBE_RADIUS), fcl.Transform())
        self._request = fcl.DistanceRequest(enable_nearest_points=True,
                                            enable_signed_distance=True)
        self.stats = CrossValidationStats()

    def due(self) -> bool:
        """Count one query; true when this one is to be checked."""
        due = self._count % self._every == 0
        self._count += 1
        return due

    def fcl_distance(self, index: int, tip) -> tuple[float, np.ndarray]:
        """Ask FCL for the distance (tip radius subtracted) and closest point of an object."""
        target, model = self._objects[index]
        self._probe.setTranslation(np.asarray(tip, dtype=np.float64))
        result = self._fcl.DistanceResult()
        distance = self._fcl.distance(target, self._probe, self._request, result)
        point = np.asarray(result.nearest_points[0], dtype=np.float64)
        if not model.signed:
            point = model.pose.to_world(point)
        return distance + PROBE_RADIUS - self._tip_radius, point

    def check(self, index: int, tip, distance: float, point) -> tuple[float, float]:
        """Compare one answer with FCL; never raises.

        Parameters
        ----------
        index : int
            The object our query found nearest.
        tip : (3,) float, m
        distance : float, m
            Our signed distance (tip radius subtracted).
        point : (3,) float, m
            Our closest point.

        Returns
        -------
        fcl_distance : float, m (NaN when FCL failed)
        discrepancy : float, m (NaN when FCL failed)
        """
        stats = self.stats
        try:
            fcl_distance, fcl_point = self.fcl_distance(index, tip)
        except Exception as error:  # noqa: B902 -- FCL must never break the loop
            self.stats = CrossValidationStats(
                stats.checks, stats.disagreements, stats.errors + 1, stats.max_discrepancy,
                stats.max_point_discrepancy, f'{type(error).__name__}: {error}')
            return math.nan, math.nan
        model = self._objects[index][1]
        ours = distance if model.signed else abs(distance + self._tip_radius) - self._tip_radius
        discrepancy = abs(ours - fcl_distance)
        point_discrepancy = float(np.linalg.norm(np.asarray(point) - fcl_point))
        allowed = (self._tolerance + model.relative_error * abs(ours + self._tip_radius)
                   + model.absolute_error)
        point_allowed = allowed + math.sqrt(2.0 * model.radius * allowed)
        if model.relative_error == 0.0:
            point_allowed = allowed
        disagrees = discrepancy > allowed or point_discrepancy > point_allowed
        self.stats = CrossValidationStats(
            stats.checks + 1, stats.disagreements + int(disagrees), stats.errors,
            max(stats.max_discrepancy, discrepancy),
            max(stats.max_point_discrepancy, point_discrepancy), stats.last_error)
        return fcl_distance, discrepancy
