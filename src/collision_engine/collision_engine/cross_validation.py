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

Since FCL is unsigned inside a mesh, the sign of our distance to a ``TriangleMesh`` is checked
apart, by the generalized winding number of the mesh at the tip (``winding``: 1 inside, 0
outside), wherever the tip is farther than the tolerance from the surface.

The checks run off the query's thread (``CrossValidationWorker``): the query hands a sample to a
bounded queue and returns; a worker thread compares it with FCL. When the queue is full the
sample is dropped and counted, so a slow FCL call never delays a query.
"""

from dataclasses import dataclass, replace
import math
import queue
import threading
import weakref

import numpy as np

from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere, TriangleMesh
from collision_engine.winding import winding_number

__all__ = ['CrossValidationStats', 'CrossValidationWorker', 'FclCrossValidator', 'PROBE_RADIUS',
           'fcl_model']

PROBE_RADIUS = 1e-9
CYLINDER_SIDES = 512
FCL_RELATIVE_ERROR = 0.05
QUEUE_CAPACITY = 64  # samples waiting for the worker; more are dropped


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
    sign_checks : int
        Checks whose sign was compared with the winding number (meshes, off the surface).
    sign_disagreements : int
        Of those, the ones whose sign differed (each also counts as a disagreement).
    dropped : int
        Samples not checked because the worker's queue was full.
    """

    checks: int = 0
    disagreements: int = 0
    errors: int = 0
    max_discrepancy: float = 0.0
    max_point_discrepancy: float = 0.0
    last_error: str = ''
    sign_checks: int = 0
    sign_disagreements: int = 0
    dropped: int = 0


@dataclass(frozen=True, eq=False)
class _Model:
    geometry: object
    signed: bool
    relative_error: float
    absolute_error: float
    radius: float
    pose: object
    corners: np.ndarray | None  # (t, 3, 3) m, local frame, for the winding number of a mesh


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
    """Compares answers with FCL (and a mesh's sign with its winding number); keeps totals.

    Synchronous: ``CrossValidationWorker`` runs it off the query's thread.

    Parameters
    ----------
    shapes : list of shapes
    poses : list of Pose
        Local to world, one per shape.
    tolerance : float, m
        Allowed discrepancy beyond FCL's own error (module docstring); also how far from a
        mesh's surface the tip must be for its sign to be compared.
    tip_radius : float, m
        The scene's tip radius, which our distances have subtracted.
    """

    def __init__(self, shapes: list, poses: list, *, tolerance: float,
                 tip_radius: float = 0.0) -> None:
        import fcl

        self._fcl = fcl
        self._tolerance = tolerance
        self._tip_radius = tip_radius
        self._objects = []
        for shape, pose in zip(shapes, poses):
            geometry, signed, relative, absolute = fcl_model(shape)
            _, radius = shape.bounding_sphere()
            corners = None
            if isinstance(shape, TriangleMesh):
                corners = np.ascontiguousarray(shape.vertices[shape.faces])
            transform = fcl.Transform(np.asarray(pose.rotation), np.asarray(pose.translation))
            self._objects.append((fcl.CollisionObject(geometry, transform),
                                  _Model(geometry, signed, relative, absolute, radius, pose,
                                         corners)))
        self._probe = fcl.CollisionObject(fcl.Sphere(PROBE_RADIUS), fcl.Transform())
        self._request = fcl.DistanceRequest(enable_nearest_points=True,
                                            enable_signed_distance=True)
        self.stats = CrossValidationStats()

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
        """Compare one answer with FCL, and a mesh's sign with its winding number; never raises.

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
        sign_checked, sign_differs = self._sign_differs(model, tip, distance)
        disagrees = discrepancy > allowed or point_discrepancy > point_allowed or sign_differs
        self.stats = replace(
            stats, checks=stats.checks + 1, disagreements=stats.disagreements + int(disagrees),
            max_discrepancy=max(stats.max_discrepancy, discrepancy),
            max_point_discrepancy=max(stats.max_point_discrepancy, point_discrepancy),
            sign_checks=stats.sign_checks + int(sign_checked),
            sign_disagreements=stats.sign_disagreements + int(sign_differs))
        return fcl_distance, discrepancy

    def _sign_differs(self, model: _Model, tip, distance: float) -> tuple[bool, bool]:
        """Compare our inside/outside with the winding number's: (compared, differs)."""
        centre = distance + self._tip_radius  # the tip centre's signed distance
        if model.corners is None or abs(centre) <= self._tolerance:
            return False, False
        x, y, z = model.pose.to_local(np.asarray(tip, dtype=np.float64)).tolist()
        inside = winding_number(model.corners, x, y, z) > 0.5
        return True, inside != (centre < 0.0)


class CrossValidationWorker:
    """Checks every ``every``-th query with an ``FclCrossValidator``, on a thread of its own.

    The query only counts itself (``due``) and offers its answer (``submit``) to a bounded
    queue without waiting; a full queue drops the sample and counts it. ``close`` stops the
    thread; so does garbage collection of the worker (``weakref.finalize``).

    Parameters
    ----------
    validator : FclCrossValidator
        Used by the worker thread only, from here on.
    every : int
        Check queries 0, every, 2 every, ...
    capacity : int
        Samples the queue holds.
    """

    def __init__(self, validator: FclCrossValidator, *, every: int,
                 capacity: int = QUEUE_CAPACITY) -> None:
        self._validator = validator
        self._every = every
        self._count = 0
        self._dropped = 0
        self._samples = queue.Queue(maxsize=capacity)
        self._submitted = 0  # written by the querying thread only
        self._checked = [0]  # written by the worker only, under _done
        self._done = threading.Condition()
        self._stop = threading.Event()
        self._thread = threading.Thread(
            target=_work, args=(validator, self._samples, self._done, self._checked,
                                self._stop),
            name='fcl-cross-validation', daemon=True)
        self._thread.start()
        self._finalizer = weakref.finalize(self, _stop_worker, self._samples, self._stop,
                                           self._thread, 1.0)

    @property
    def stats(self) -> CrossValidationStats:
        """Running totals: the validator's, with the samples dropped."""
        return replace(self._validator.stats, dropped=self._dropped)

    @property
    def disagreements(self) -> int:
        """FCL disagreements so far: what every answer carries, without building the totals."""
        return self._validator.stats.disagreements

    @property
    def running(self) -> bool:
        """Whether the worker thread is alive."""
        return self._thread.is_alive()

    def due(self) -> bool:
        """Count one query; true when this one is to be checked."""
        due = self._count % self._every == 0
        self._count += 1
        return due

    def submit(self, index: int, tip, distance: float, point) -> bool:
        """Offer one answer for checking, never waiting; false when dropped (queue full)."""
        try:
            self._samples.put_nowait((index, tip, distance, point))
        except queue.Full:
            self._dropped += 1
            return False
        self._submitted += 1
        return True

    def drain(self, timeout: float | None = None) -> bool:
        """Wait until every submitted sample is checked; false on timeout.

        Call it from the thread that submits (as tests and shutdown do).
        """
        with self._done:
            return self._done.wait_for(lambda: self._checked[0] >= self._submitted, timeout)

    def close(self, timeout: float = 1.0) -> None:
        """Stop the worker thread (samples still queued are not checked)."""
        self._finalizer.detach()
        _stop_worker(self._samples, self._stop, self._thread, timeout)


def _work(validator: FclCrossValidator, samples: queue.Queue, done: threading.Condition,
          checked: list, stop: threading.Event) -> None:
    """Check samples until stopped.

    It holds no reference to its ``CrossValidationWorker``, so that the worker can be collected
    (and its finalizer stop this thread).
    """
    while not stop.is_set():
        sample = samples.get()
        if sample is None:
            return
        validator.check(*sample)
        with done:
            checked[0] += 1
            done.notify_all()


def _stop_worker(samples: queue.Queue, stop: threading.Event, thread: threading.Thread,
                 timeout: float) -> None:
    stop.set()
    try:
        samples.put(None, timeout=timeout)  # wakes a worker waiting for a sample
    except queue.Full:
        pass  # the worker is busy with a sample; it sees the stop flag after it
    thread.join(timeout)
