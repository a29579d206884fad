"""Single-point signed distance from Python: our engine beside python-fcl and coal.

    .venv/bin/python bench/bench_collision.py [--objects cuboid cylinder cylinder_stl hand]
                                              [--methods ours ours-kernel python-fcl coal]
                                              [--random 2000] [--near 2000] [--tapping 10]
                                              [--inside 2000]

One call per point, from a Python loop, as a haptic loop makes them, after a warm-up. For each
object (the paper's, centred at (0, 0, -0.075) m) and point set (random in twice the bounding
box, within +-2 mm of the surface half inside, a 1 kHz tapping trajectory that goes 1 mm deep
at 20 sites, and uniform inside the object: the penetration depth, by EPA on a convex mesh),
every method answers the same points: printed are the median and p99 time of
a call (the timer's own cost is printed apart: it is included in every figure) and the largest
error against exact ground truth (``ground_truth/distances.py``: analytic for the primitives, brute
force with a winding-number sign for meshes), with the number of sign errors.

The methods: ours (``Scene.query``, the public API, points as tuples of floats); ours-kernel
(the same compiled call without the Python wrapper that builds the ``QueryResult``); python-fcl
(signed distance to a 1e-9 m probe sphere, radius added back, a fresh ``DistanceResult`` per
call); coal (the same probe through a cached ``ComputeDistance``, its result cleared per call).
FCL and coal use their ``Box`` and ``Cylinder`` primitives, a ``Convex`` for the convex STL and
a BVH for the hand, which they can only answer unsigned. Importable: ``run(...)`` returns the
rows as dicts.
"""

import argparse
import math
import time

from bench import machine
from ground_truth import distances
import numpy as np

from collision_engine import _kernels
from collision_engine._jit import jit
from collision_engine.epa import epa, scratch_size as epa_scratch_size
from collision_engine.gjk import gjk
from collision_engine.scene import load_scene, Scene, SceneObject
from collision_engine.shapes import Box, ConvexMesh, Cylinder, TriangleMesh
from collision_engine.support import pack_convex, POINT

__all__ = ['OBJECTS', 'point_sets', 'run', 'main']

# Bench object -> shipped scene file.
OBJECTS = {'cuboid': 'cuboid', 'cylinder': 'cylinder', 'cylinder_stl': 'paper_cylinder_stl',
           'hand': 'hand'}
PROBE_RADIUS = 1e-9
NEAR_BAND = 0.002
TAP_SITES = 20
TAP_DEPTH = 0.001
TAP_HEIGHT = 0.005
RATE = 1000.0
WARM_UP = 200


def _truth_function(scene_object):
    """Exact signed distance for world points: analytic for primitives, brute force for meshes."""
    shape, pose = scene_object.shape, scene_object.pose
    if isinstance(shape, Box):
        local = (lambda p: distances.box_signed_distance(p, shape.size))
    elif isinstance(shape, Cylinder):
        local = (lambda p: distances.cylinder_signed_distance(p, shape.radius, shape.height))
    else:  # a TriangleMesh, or a ConvexMesh's hull
        local = (lambda p: distances.mesh_signed_distance(p, shape.vertices, shape.faces)[0])
    return lambda world: local(pose.to_local(world))


def _outward(truth, points, step=1e-7):
    """Return unit outward directions: the central-difference gradient of the exact field."""
    gradient = np.stack([(truth(points + step * e) - truth(points - step * e)) / (2 * step)
                         for e in np.eye(3)], axis=-1)
    return gradient / np.linalg.norm(gradient, axis=-1, keepdims=True)


def _near_surface(scene_object, truth, count, rng):
    shape = scene_object.shape
    if isinstance(shape, (TriangleMesh, ConvexMesh)):
        local, distance = distances.sample_near_surface(shape.vertices, shape.faces, count,
                                                        NEAR_BAND, rng)
        return scene_object.pose.to_world(local), distance
    centre, radius = shape.bounding_sphere()
    inside, outside = [], []
    while len(inside) < count // 2 or len(outside) < count - count // 2:
        local = centre + rng.uniform(-radius - NEAR_BAND, radius + NEAR_BAND, (20 * count, 3))
        world = scene_object.pose.to_world(local)
        d = truth(world)
        inside.extend(world[(d < 0) & (d > -NEAR_BAND)])
        outside.extend(world[(d > 0) & (d < NEAR_BAND)])
    points = np.array(inside[:count // 2] + outside[:count - count // 2])
    return points, truth(points)


def _tapping(truth, near_points, seconds, rng):
    """Tap 1 mm deep at sites on the surface, from 5 mm above, sampled at 1 kHz."""
    picks = near_points[rng.choice(len(near_points), TAP_SITES, replace=False)]
    normals = _outward(truth, picks)
    sites = picks - truth(picks)[:, None] * normals
    per_site = int(round(seconds * RATE / TAP_SITES))
    phase = np.sin(np.pi * np.arange(per_site) / per_site) ** 2
    height = TAP_HEIGHT - (TAP_HEIGHT + TAP_DEPTH) * phase
    points = (sites[:, None, :] + height[None, :, None] * normals[:, None, :]).reshape(-1, 3)
    return points, truth(points)


def _inside(scene_object, truth, low, high, count, rng):
    """Uniform points inside the object, by rejection from its local bounding box."""
    points = np.empty((0, 3))
    while len(points) < count:
        candidates = scene_object.pose.to_world(rng.uniform(low, high, (2 * count, 3)))
        points = np.vstack((points, candidates[truth(candidates) < 0.0]))
    return points[:count]


def point_sets(scene_object, *, random: int, near: int, tapping: float, inside: int = 0,
               seed: int = 0) -> dict:
    """Make the point sets of one object, world frame, with exact signed distances.

    ``inside`` points (none by default) make a fourth set, ``inside``.

    Returns
    -------
    dict of name -> (points (n, 3) float64 m, distance (n,) float64 m)
    """
    rng = np.random.default_rng(seed)
    truth = _truth_function(scene_object)
    centre, radius = scene_object.shape.bounding_sphere()
    if isinstance(scene_object.shape, (TriangleMesh, ConvexMesh)):
        low, high = scene_object.shape.vertices.min(0), scene_object.shape.vertices.max(0)
    else:
        low, high = centre - radius, centre + radius
    mid, half = 0.5 * (low + high), 0.5 * (high - low)
    random_points = scene_object.pose.to_world(mid + rng.uniform(-2 * half, 2 * half,
                                                                 (random, 3)))
    near_points, near_truth = _near_surface(scene_object, truth, near, rng)
    sets = {'random': (random_points, truth(random_points)),
            'near': (near_points, near_truth),
            'tapping': _tapping(truth, near_points, tapping, rng)}
    if inside:
        inside_points = _inside(scene_object, truth, low, high, inside, rng)
        sets['inside'] = (inside_points, truth(inside_points))
    return sets


def _ours(scene_object):
    scene = Scene([SceneObject(scene_object.name, scene_object.shape, scene_object.pose)])
    scene.warm_up()
    query = scene.query
    return (lambda point: query(point).distance), (lambda points: [tuple(p) for p in points])


def _ours_kernel(scene_object):
    """Call the compiled kernel alone, without the wrapper ``Scene.query`` adds around it."""
    scene = Scene([SceneObject(scene_object.name, scene_object.shape, scene_object.pose)])
    scene.warm_up()
    floats, ints, row = scene._floats, scene._ints, np.empty(_kernels.OUT_SIZE)
    kernel = _kernels.query_point

    def signed_distance(point):
        kernel(floats, ints, row, point[0], point[1], point[2])
        return row[0]

    return signed_distance, (lambda points: [tuple(p) for p in points])


def fcl_geometry(shape):
    """Return python-fcl's geometry for one of our shapes: its primitive, else a mesh."""
    import fcl

    if isinstance(shape, Box):
        return fcl.Box(*shape.size)
    if isinstance(shape, Cylinder):
        return fcl.Cylinder(shape.radius, shape.height)
    if isinstance(shape, ConvexMesh):
        faces = np.column_stack((np.full(len(shape.faces), 3), shape.faces)).ravel()
        return fcl.Convex(shape.vertices, len(shape.faces), faces)
    geometry = fcl.BVHModel()
    geometry.beginModel(len(shape.vertices), len(shape.faces))
    geometry.addSubModel(shape.vertices, shape.faces)
    geometry.endModel()
    return geometry


def coal_geometry(shape):
    """Return coal's geometry for one of our shapes: its primitive, else a mesh."""
    import coal

    if isinstance(shape, Box):
        return coal.Box(*shape.size)
    if isinstance(shape, Cylinder):
        return coal.Cylinder(shape.radius, shape.height)
    if isinstance(shape, ConvexMesh):
        points = coal.StdVec_Vec3s()
        points.extend(list(shape.vertices))
        return coal.Convex.convexHull(points, False, None)
    geometry = coal.BVHModelOBBRSS()
    geometry.beginModel(len(shape.faces), len(shape.vertices))
    geometry.addVertices(shape.vertices)
    geometry.addTriangles(shape.faces)
    geometry.endModel()
    return geometry


def _fcl(scene_object):
    import fcl

    shape, pose = scene_object.shape, scene_object.pose
    target = fcl.CollisionObject(fcl_geometry(shape),
                                 fcl.Transform(pose.rotation, pose.translation))
    probe = fcl.CollisionObject(fcl.Sphere(PROBE_RADIUS), fcl.Transform())
    request = fcl.DistanceRequest(enable_nearest_points=True, enable_signed_distance=True)

    def signed_distance(point):
        probe.setTranslation(point)
        return fcl.distance(target, probe, request, fcl.DistanceResult()) + PROBE_RADIUS

    return signed_distance, (lambda points: list(np.array(points)))


def _coal(scene_object):
    import coal

    shape, pose = scene_object.shape, scene_object.pose
    geometry = coal_geometry(shape)
    probe = coal.Sphere(PROBE_RADIUS)
    compute = coal.ComputeDistance(geometry, probe)
    placed = coal.Transform3s(pose.rotation, pose.translation)
    moved = coal.Transform3s()
    request = coal.DistanceRequest()
    result = coal.DistanceResult()
    keep_alive = (geometry, probe)

    def signed_distance(point, keep_alive=keep_alive):
        moved.setTranslation(point)
        result.clear()
        return compute(placed, moved, request, result) + PROBE_RADIUS

    return signed_distance, (lambda points: list(np.array(points)))


METHODS = {'ours': _ours, 'ours-kernel': _ours_kernel, 'python-fcl': _fcl, 'coal': _coal}


def _time_calls(function, inputs) -> tuple[np.ndarray, np.ndarray]:
    """Time each call alone; returns (durations in us, answers)."""
    for point in inputs[:WARM_UP]:
        function(point)
    durations = np.empty(len(inputs))
    answers = np.empty(len(inputs))
    clock = time.perf_counter_ns
    for k, point in enumerate(inputs):
        start = clock()
        answer = function(point)
        durations[k] = clock() - start
        answers[k] = answer
    return durations / 1e3, answers


def timer_overhead(count: int = 20000) -> float:
    """Median cost in us of timing an empty Python call the way every method is timed."""
    durations, _ = _time_calls(lambda point: 0.0, [None] * count)
    return float(np.median(durations))


def run(objects=tuple(OBJECTS), *, random: int = 2000, near: int = 2000, tapping: float = 10.0,
        inside: int = 2000, methods=tuple(METHODS), seed: int = 0) -> list[dict]:
    """Benchmark every method on every object and point set.

    Returns
    -------
    list of dict
        One row per (object, point set, method): ``object``, ``points``, ``method``, ``n``,
        ``median_us``, ``p99_us``, ``max_error_m``, ``sign_errors``.
    """
    rows = []
    for name in objects:
        scene_object = load_scene(distances.scene_path(OBJECTS[name])).objects[0]
        sets = point_sets(scene_object, random=random, near=near, tapping=tapping,
                          inside=inside, seed=seed)
        for method in methods:
            try:
                function, convert = METHODS[method](scene_object)
            except ImportError:
                continue
            for set_name, (points, truth) in sets.items():
                durations, answers = _time_calls(function, convert(points))
                meaningful = np.abs(truth) > 1e-9
                rows.append({
                    'object': name, 'points': set_name, 'method': method, 'n': len(points),
                    'median_us': float(np.median(durations)),
                    'p99_us': float(np.percentile(durations, 99)),
                    'max_error_m': float(np.max(np.abs(answers - truth))),
                    'sign_errors': int(np.count_nonzero(
                        np.sign(answers[meaningful]) != np.sign(truth[meaningful]))),
                })
    return rows


def format_rows(rows: list[dict], peer: str = 'coal') -> str:
    """Format the rows as a fixed-width table, each median also as a ratio to ``peer``'s."""
    peers = {(r['object'], r['points']): r['median_us'] for r in rows if r['method'] == peer}
    lines = [f'{"object":13s} {"points":8s} {"method":11s} {"n":>6s} {"median us":>10s} '
             f'{"/ " + peer:>8s} {"p99 us":>8s} {"max error m":>12s} {"sign err":>8s}']
    for r in rows:
        ratio = r['median_us'] / peers.get((r['object'], r['points']), math.nan)
        lines.append(f'{r["object"]:13s} {r["points"]:8s} {r["method"]:11s} {r["n"]:6d} '
                     f'{r["median_us"]:10.2f} {ratio:8.2f} {r["p99_us"]:8.2f} '
                     f'{r["max_error_m"]:12.2e} {r["sign_errors"]:8d}')
    return '\n'.join(lines)


@jit
def _epa_batch(kind, floats, ints, rels, simplices, supports, counts, invs, max_iter,
               scratch_floats, scratch_ints, allocate):
    """Run EPA on every prepared contact; ``allocate`` adds the 7 arrays it once allocated."""
    total = 0.0
    m = max_iter + 4
    for k in range(len(rels)):
        if allocate:  # the sizes and kinds of the arrays EPA allocated per call until 2026-11
            arrays = (np.empty((m, 3)), np.empty((2 * m, 3)), np.empty(2 * m))
            edges = (np.empty(6 * m, dtype=np.int64), np.empty(6 * m, dtype=np.int64))
            flags = np.zeros(2 * m, dtype=np.bool_)
            faces = np.empty((2 * m, 3), dtype=np.int64)
            total += arrays[0][0, 0] * 0.0 + flags[0] + (faces[0, 0] + edges[0][0]) * 0
        total += epa((kind, floats, 0, ints, 0), (POINT, floats, 0, ints, 0), rels[k],
                     simplices[k], supports[k], counts[k], invs[k], 1e-12, 1e-12, max_iter,
                     scratch_floats, scratch_ints)[1]
    return total


def epa_scratch_figures(name: str = 'cylinder_stl', count: int = 2000, rounds: int = 7,
                        seed: int = 0) -> dict:
    """Time EPA alone per call, with its preallocated scratch and with the 7 per-call arrays.

    The same contacts (points inside the object, GJK run beforehand) in one compiled batch per
    timing, the two variants alternated ``rounds`` times; returns the medians in us a call.
    """
    scene_object = load_scene(distances.scene_path(OBJECTS[name])).objects[0]
    shape = scene_object.shape
    sets = point_sets(scene_object, random=1, near=TAP_SITES, tapping=0.02, inside=count,
                      seed=seed)
    points = scene_object.pose.to_local(sets['inside'][0])
    kind, floats, ints = pack_convex(shape)
    radius = shape.bounding_sphere()[1]
    simplices, supports = np.zeros((count, 12)), np.zeros((count, 12))
    counts, invs = np.zeros(count, np.int64), np.ones(count)
    rels = np.column_stack((np.tile(np.eye(3).ravel(), (count, 1)), points))
    for k, point in enumerate(points):
        direction = point - shape.vertices.mean(axis=0)
        contact = gjk((kind, floats, 0, ints, 0), (POINT, floats, 0, ints, 0), rels[k],
                      *direction, radius, 1e-12, 1e-12, 100, simplices[k], supports[k])
        counts[k], invs[k] = contact[2], contact[8]
    max_iter = 128
    scratch = tuple(np.zeros(n, dtype) for n, dtype in zip(epa_scratch_size(max_iter),
                                                           (np.float64, np.int64)))
    times = {False: [], True: []}
    for _ in range(rounds):
        for allocate in (False, True):
            arguments = (kind, floats, ints, rels, simplices.copy(), supports.copy(), counts,
                         invs, max_iter, *scratch, allocate)
            _epa_batch(*arguments)  # compiled, and warm
            start = time.perf_counter_ns()
            _epa_batch(*arguments)
            times[allocate].append((time.perf_counter_ns() - start) / 1e3 / count)
    return {'preallocated_us': float(np.median(times[False])),
            'allocating_us': float(np.median(times[True]))}


def main(argv=None) -> None:
    """Print the machine, the timer's cost, and the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--objects', nargs='+', default=list(OBJECTS), choices=list(OBJECTS))
    parser.add_argument('--methods', nargs='+', default=list(METHODS), choices=list(METHODS))
    parser.add_argument('--random', type=int, default=2000, help='random points per object')
    parser.add_argument('--near', type=int, default=2000, help='near-surface points per object')
    parser.add_argument('--tapping', type=float, default=10.0, help='tapping seconds at 1 kHz')
    parser.add_argument('--inside', type=int, default=2000, help='points inside each object')
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args(argv)
    print('machine:', machine.line('numpy', 'numba', 'scipy', 'python-fcl', 'coal'))
    print(f'timer overhead (empty call, included below): {timer_overhead():.2f} us median')
    started = time.perf_counter()
    rows = run(args.objects, random=args.random, near=args.near, tapping=args.tapping,
               inside=args.inside, methods=args.methods, seed=args.seed)
    print(format_rows(rows))
    print(f'({time.perf_counter() - started:.0f} s; sign errors count points farther than '
          '1e-9 m from the surface; a BVH in FCL or coal is unsigned)')
    if args.inside and 'cylinder_stl' in args.objects:
        epa_times = epa_scratch_figures(count=args.inside, seed=args.seed)
        print(f'EPA alone inside the convex cylinder_stl, per call (compiled batch, median of 7):'
              f' preallocated scratch {epa_times["preallocated_us"]:.2f} us, allocating its 7 '
              f'arrays per call as before {epa_times["allocating_us"]:.2f} us '
              f'(ratio {epa_times["preallocated_us"] / epa_times["allocating_us"]:.2f})')


if __name__ == '__main__':
    main()
