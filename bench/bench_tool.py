"""A convex probe against the scene from Python: our query_tool beside python-fcl and coal.

    .venv/bin/python bench/bench_tool.py [--near 2000] [--tapping 10] [--truth 100]
                                         [--methods ours ours-kernel python-fcl coal]

The probe is a box 40 x 10 x 20 mm (an ultrasound probe's face is about 40 x 10 mm). One call
per pose, from a Python loop, as a haptic loop makes them, after a warm-up. The pose sets:

* hand near: the probe face down on the hand mesh (``scenes/hand.yaml``) at a site drawn by
  area, spun at random about the normal and tilted up to 20 degrees, its lowest corner within
  +-2 mm of the site (``ground_truth.tool_poses_near_surface``), also split into ``apart`` and
  ``overlap`` by the sign of each method's answer: independent poses, so no warm start helps;
* hand tapping: at 20 such sites, upright, the probe comes down from 5 mm above to 1 mm deep
  and back, sampled at 1 kHz: consecutive poses, as in the haptic loop;
* cuboid near: the same placement on the paper's cuboid (``scenes/cuboid.yaml``), a primitive.

Printed per method and set: the median and p99 time of a call (the timer's own cost, printed
apart, is included) and the largest error against independent truth (``ground_truth/distances.py``)
over the first ``--truth`` poses of each set: the least polytope distance of the probe to the
triangles apart, and in overlap the least exact signed distance over our point shell, the
method ``tool_mesh`` states; for the cuboid, the probe's polytope distance to the box. Every
method gets its inputs in its own form, built before the timing: ours a position and a
quaternion, FCL and coal their transforms. FCL uses ``fcl.Box`` and a ``BVHModel`` (signed
distance requested), coal ``ComputeDistance`` on ``Box`` and ``BVHModelOBBRSS``, its result
cleared per call; a BVH in either answers overlap without a depth.
"""

import argparse
import time

from bench import bench_collision, machine
from ground_truth import distances
import numpy as np
from scipy.spatial.transform import Rotation

from collision_engine import _kernels, Box, TriangleMesh
from collision_engine.scene import load_scene
from collision_engine.tool import pack_tool, point_shell

__all__ = ['PROBE_SIZE', 'pose_sets', 'run', 'main']

PROBE_SIZE = (0.04, 0.01, 0.02)
NEAR_BAND = 0.002
TAP_SITES, TAP_HEIGHT, TAP_DEPTH, RATE = 20, 0.005, 0.001, 1000.0
WARM_UP = 200


def _box_corners(size) -> np.ndarray:
    return (np.array(list(np.ndindex(2, 2, 2))) - 0.5) * np.asarray(size)


def _surface(shape) -> tuple[np.ndarray, np.ndarray]:
    """Return the object's surface as triangles (vertices, faces), local frame."""
    if isinstance(shape, TriangleMesh):
        return shape.vertices, shape.faces
    faces, _ = distances.outward_hull(_box_corners(shape.size))
    return _box_corners(shape.size), faces


def _truth(scene_object, rotation, position, spacing) -> float:
    """Independent signed distance of the probe in the object's frame (module docstring)."""
    vertices, faces = _surface(scene_object.shape)
    probe = _box_corners(PROBE_SIZE) @ rotation.T + position
    if isinstance(scene_object.shape, Box):
        return distances.polytope_pair_distance(vertices, probe)
    shell = point_shell(Box(PROBE_SIZE), spacing) @ rotation.T + position
    deepest = float(distances.mesh_signed_distance(shell, vertices, faces)[0].min())
    if deepest < 0.0:
        return deepest
    centre = probe.mean(axis=0)
    reach = np.linalg.norm(probe - centre, axis=1).max()
    triangles = vertices[faces]
    centroids = triangles.mean(axis=1)
    spans = np.linalg.norm(triangles - centroids[:, None], axis=2).max(axis=1)
    near = np.linalg.norm(centroids - centre, axis=1) - spans - reach <= NEAR_BAND + 0.02
    return max(0.0, min(distances.polytope_pair_distance(t, probe) for t in triangles[near]))


def _tapping(vertices, faces, seconds, rng):
    """Upright taps at 20 sites: (rotations, positions), local frame, 1 kHz."""
    rotations, positions = distances.tool_poses_near_surface(
        vertices, faces, PROBE_SIZE, TAP_SITES, 0.0, rng, tilt=0.0)
    normals = rotations[:, :, 2]
    per_site = int(round(seconds * RATE / TAP_SITES))
    phase = np.sin(np.pi * np.arange(per_site) / per_site) ** 2
    height = TAP_HEIGHT - (TAP_HEIGHT + TAP_DEPTH) * phase
    points = positions[:, None, :] + height[None, :, None] * normals[:, None, :]
    return np.repeat(rotations, per_site, axis=0), points.reshape(-1, 3)


def pose_sets(*, near: int, tapping: float, truth: int, spacing: float, seed: int = 0) -> list:
    """Make the pose sets, scene frame, with the truth of their first ``truth`` poses.

    Returns
    -------
    list of (scene name, set name, rotations (n, 3, 3), positions (n, 3) m, truth (k,) m)
    """
    rng = np.random.default_rng(seed)
    sets = []
    for name in ('hand', 'cuboid'):
        scene_object = load_scene(distances.scene_path(name)).objects[0]
        vertices, faces = _surface(scene_object.shape)
        local = {'near': distances.tool_poses_near_surface(vertices, faces, PROBE_SIZE, near,
                                                           NEAR_BAND, rng)}
        if name == 'hand' and tapping:
            local['tapping'] = _tapping(vertices, faces, tapping, rng)
        for set_name, (rotations, positions) in local.items():
            exact = np.array([_truth(scene_object, r, p, spacing)
                              for r, p in zip(rotations[:truth], positions[:truth])])
            pose = scene_object.pose
            sets.append((name, set_name, pose.rotation @ rotations, pose.to_world(positions),
                         exact))
    return sets


def _rows(scene_name, set_name, method, durations, answers, exact) -> list[dict]:
    """One row for the set, and for the hand's near poses one each apart and in overlap.

    The split is by the sign of the answer of the same method (ours matches the truth's sign on
    every pose checked; a BVH in FCL or coal answers overlap with 0 or less, without depth).
    """
    subsets = [(set_name, np.ones(len(answers), dtype=bool))]
    if scene_name == 'hand' and set_name == 'near':
        subsets += [('apart', answers > 0.0), ('overlap', answers <= 0.0)]
    rows = []
    for name, chosen in subsets:
        checked = chosen[:len(exact)]
        rows.append({
            'scene': scene_name, 'poses': name, 'method': method, 'n': int(chosen.sum()),
            'median_us': float(np.median(durations[chosen])),
            'p99_us': float(np.percentile(durations[chosen], 99)),
            'max_error_m': float(np.max(np.abs(answers[:len(exact)] - exact)[checked],
                                        initial=0.0)),
            'checked': int(checked.sum())})
    return rows


def _ours(scene, probe):
    def query(pose):
        return scene.query_tool(probe, pose).distance

    return query, (lambda rotations, positions: [
        (tuple(p), tuple(q)) for p, q in zip(positions.tolist(),
                                             Rotation.from_matrix(rotations).as_quat().tolist())])


def _ours_kernel(scene, probe):
    tool_floats, tool_ints = pack_tool(probe, spacing=scene.shell_spacing,
                                       workspace_size=scene.workspace_size)
    floats, ints, row, kernel = scene._floats, scene._ints, np.empty(_kernels.OUT_SIZE), \
        _kernels.query_tool

    def query(pose):
        kernel(floats, ints, tool_floats, tool_ints, row, *pose)
        return row[0]

    return query, (lambda rotations, positions: [
        (*p, *q) for p, q in zip(positions.tolist(),
                                 Rotation.from_matrix(rotations).as_quat().tolist())])


def _fcl(scene, probe):
    import fcl

    scene_object = scene.objects[0]
    shape, pose = scene_object.shape, scene_object.pose
    target = fcl.CollisionObject(bench_collision.fcl_geometry(shape),
                                 fcl.Transform(pose.rotation, pose.translation))
    tool = fcl.CollisionObject(fcl.Box(*probe.size), fcl.Transform())
    request = fcl.DistanceRequest(enable_signed_distance=True)

    def query(transform):
        tool.setTransform(transform)
        return fcl.distance(target, tool, request, fcl.DistanceResult())

    return query, (lambda rotations, positions: [
        fcl.Transform(r, p) for r, p in zip(rotations, positions)])


def _coal(scene, probe):
    import coal

    scene_object = scene.objects[0]
    shape, pose = scene_object.shape, scene_object.pose
    geometry = bench_collision.coal_geometry(shape)
    tool = coal.Box(*probe.size)
    compute = coal.ComputeDistance(geometry, tool)
    placed = coal.Transform3s(pose.rotation, pose.translation)
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    keep_alive = (geometry, tool)

    def query(transform, keep_alive=keep_alive):
        result.clear()
        return compute(placed, transform, request, result)

    return query, (lambda rotations, positions: [
        coal.Transform3s(r, p) for r, p in zip(rotations, positions)])


METHODS = {'ours': _ours, 'ours-kernel': _ours_kernel, 'python-fcl': _fcl, 'coal': _coal}


def run(*, near: int = 2000, tapping: float = 10.0, truth: int = 100,
        methods=tuple(METHODS), seed: int = 0) -> list[dict]:
    """Benchmark every method on every pose set.

    Returns
    -------
    list of dict
        One row per (scene, pose set, method): ``scene``, ``poses``, ``method``, ``n``,
        ``median_us``, ``p99_us``, ``max_error_m`` (over the poses with truth), ``checked``.
    """
    scenes = {name: load_scene(distances.scene_path(name)) for name in ('hand', 'cuboid')}
    probe = Box(PROBE_SIZE)
    sets = pose_sets(near=near, tapping=tapping, truth=truth,
                     spacing=scenes['hand'].shell_spacing, seed=seed)
    rows = []
    for scene_name, set_name, rotations, positions, exact in sets:
        for method in methods:
            try:
                query, convert = METHODS[method](scenes[scene_name], probe)
            except ImportError:
                continue
            durations, answers = bench_collision._time_calls(query, convert(rotations,
                                                                            positions))
            rows.extend(_rows(scene_name, set_name, method, durations, answers, exact))
    return rows


def format_rows(rows: list[dict]) -> str:
    """Format the rows as a fixed-width table."""
    lines = [f'{"scene":7s} {"poses":8s} {"method":11s} {"n":>6s} {"median us":>10s} '
             f'{"p99 us":>8s} {"max error m":>12s} {"checked":>8s}']
    for r in rows:
        lines.append(f'{r["scene"]:7s} {r["poses"]:8s} {r["method"]:11s} {r["n"]:6d} '
                     f'{r["median_us"]:10.2f} {r["p99_us"]:8.2f} {r["max_error_m"]:12.2e} '
                     f'{r["checked"]:8d}')
    return '\n'.join(lines)


def main(argv=None) -> None:
    """Print the machine, the timer's cost, and the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--methods', nargs='+', default=list(METHODS), choices=list(METHODS))
    parser.add_argument('--near', type=int, default=2000, help='near-surface probe poses')
    parser.add_argument('--tapping', type=float, default=10.0, help='tapping seconds at 1 kHz')
    parser.add_argument('--truth', type=int, default=100,
                        help='poses of each set checked against ground truth')
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args(argv)
    print('machine:', machine.line('numpy', 'numba', 'scipy', 'python-fcl', 'coal'))
    print(f'timer overhead (empty call, included below): '
          f'{bench_collision.timer_overhead():.2f} us median')
    started = time.perf_counter()
    rows = run(near=args.near, tapping=args.tapping, truth=args.truth, methods=args.methods,
               seed=args.seed)
    print(format_rows(rows))
    print(f'({time.perf_counter() - started:.0f} s; probe box {PROBE_SIZE} m; errors over the '
          'first poses of each set with truth ("checked"); a BVH in FCL or coal has no depth)')


if __name__ == '__main__':
    main()
