"""What the report measures live on this machine, beside the bags: times, trade-offs, loops.

Error against run time for every method, our GJK's tolerance and iteration-cap trade-off, the
loop latency over ROS 2 at 0.5, 1 and 2 kHz, the stiff wall over the real loop, and the
telerobotic scan; each builds on a bench script (``bench_collision``, ``bench_loop``,
``stiff_wall_loop``, ``teleop_lockstep``, ``teleop_scan``), so the report measures things as
those scripts do.
"""

import math
from pathlib import Path

import bench_collision
import numpy as np
from paper_method import PaperMethod
from report_experiments import Experiment, EXPERIMENTS
from report_metrics import error_summary, false_samples
from report_paper_replay import paper_rows
import stiff_wall_loop
import stiffness_sweep
import teleop_lockstep
import teleop_scan

from collision_engine import ConvexMesh, DistanceRequest, load_scene, Scene, STATUS_NOT_CONVERGED
from collision_engine.scene import SceneObject

__all__ = ['ITERATION_CAPS', 'LOOP_LAYOUTS', 'STIFF_WALLS', 'TOLERANCES',
           'colgate_bound', 'error_time_rows', 'floor_rows', 'stiff_wall_rows', 'teleop_rows',
           'tradeoff_rows']

STIFF_WALLS = (160.0, 1e3, 5e3, 2e4, 1e5)  # [N/m] over the real loop
TELEOP_SCHEMES = ('direct', 'tdpa', 'model')
TELEOP_DELAYS = (0.0, 0.01, 0.025, 0.05, 0.1, 0.25)  # [s] one way
TELEOP_PLOTTED = 0.1  # [s] the delay whose runs over ROS 2 are plotted
TELEOP_JITTER, TELEOP_LOSS = 0.1, 0.01  # of the delay; a probability
TELEOP_DEMO_DELAY = 0.05  # [s] the demo's run (haptic_bringup.demo)
LOOP_LAYOUTS = ('separate', 'composed', 'composed-dds')
TOLERANCES = (1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
ITERATION_CAPS = (1, 2, 3, 4, 6, 8, 12, 16, 100)


def _paper_function(rows: np.ndarray):
    method = PaperMethod(rows)
    return (lambda point: method.query(point).signed_distance), list


def _trimesh_function(experiment: Experiment):
    import trimesh
    import trimesh.proximity

    rows, _ = paper_rows(experiment)
    mesh = trimesh.Trimesh(rows, np.arange(len(rows)).reshape(-1, 3))
    mesh.merge_vertices()
    trimesh.proximity.signed_distance(mesh, rows[:1])  # raises now if rtree is missing

    def signed_distance(point):
        return -float(trimesh.proximity.signed_distance(mesh, point[None])[0])

    return signed_distance, list


def _hull_object(experiment: Experiment, exact: SceneObject) -> SceneObject:
    """Our GJK on the convex hull of the paper's STL, placed as the exact object."""
    if experiment.paper_scene != experiment.scene:
        return load_scene(experiment.paper_scene_file).objects[0]
    return SceneObject(f'{exact.name} hull', ConvexMesh(exact.shape.vertices), exact.pose)


def _methods(experiment: Experiment, exact: SceneObject) -> list:
    """List (method, geometry, factory) for every method on one object."""
    exact_kind = type(exact.shape).__name__
    ours_exact = ('ours: exact mesh (BVH + pseudonormals)' if exact_kind == 'TriangleMesh'
                  else 'ours: GJK, exact primitive')
    methods = bench_collision.METHODS
    return [
        (ours_exact, exact_kind, lambda: methods['ours'](exact)),
        ('ours: GJK on the STL\'s convex hull', 'ConvexMesh',
         lambda: methods['ours'](_hull_object(experiment, exact))),
        ('paper\'s method (re-implemented)', 'STL vertex rows',
         lambda: _paper_function(paper_rows(experiment)[0])),
        ('python-fcl', exact_kind, lambda: methods['python-fcl'](exact)),
        ('coal', exact_kind, lambda: methods['coal'](exact)),
        ('trimesh signed_distance', 'STL mesh', lambda: _trimesh_function(experiment)),
    ]


def error_time_rows(*, random: int, near: int, tapping: float, slow_points: int,
                    seed: int = 0) -> list[dict]:
    """Per object and method: per-query time and error against exact truth.

    Every method answers the same points (``bench_collision.point_sets``: random in twice the
    bounding box, within +-2 mm of the surface, a 1 kHz tapping path), one Python call each,
    timed as ``bench_collision`` times its methods; trimesh answers every k-th point only, for
    ``slow_points`` in all. A method that cannot run says why.
    """
    rows = []
    for experiment in EXPERIMENTS.values():
        exact = load_scene(experiment.scene_file).objects[0]
        sets = bench_collision.point_sets(exact, random=random, near=near, tapping=tapping,
                                          seed=seed)
        points = np.vstack([p for p, _ in sets.values()])
        truth = np.concatenate([d for _, d in sets.values()])
        for method, geometry, factory in _methods(experiment, exact):
            row = {'object': experiment.name, 'method': method, 'geometry': geometry}
            try:
                function, convert = factory()
            except ImportError as error:
                rows.append({**row, 'unavailable': f'{type(error).__name__}: {error}'})
                continue
            pick = slice(None, None, max(1, len(points) // slow_points)) if method.startswith(
                'trimesh') else slice(None)
            durations, answers = bench_collision._time_calls(function, convert(points[pick]))
            rows.append({**row, 'n': len(answers), 'median_us': float(np.median(durations)),
                         'p99_us': float(np.percentile(durations, 99)),
                         **error_summary(answers, truth[pick]),
                         'sign_errors': int(np.count_nonzero(
                             false_samples(answers, truth[pick], threshold=math.inf)))})
    return rows


def tradeoff_rows(points: int, seed: int = 0) -> list[dict]:
    """Error and time of our GJK as its tolerance and iteration cap vary.

    On the true cylinder (analytic support) and the hand's convex hull (hundreds of vertices),
    one ``Scene.query`` per point as the collision node makes them, in a scene built with the
    ``DistanceRequest`` of each setting, over the same points per shape (random, near the
    surface, tapping); truth as elsewhere.
    """
    cylinder = load_scene(EXPERIMENTS['cylinder'].scene_file).objects[0]
    hand = load_scene(EXPERIMENTS['hand'].scene_file).objects[0]
    shapes = {'cylinder (exact)': cylinder,
              'hand\'s convex hull': _hull_object(EXPERIMENTS['hand'], hand)}
    settings = ([('tolerance', t, DistanceRequest(rel_tol=t, abs_tol=t)) for t in TOLERANCES]
                + [('iteration cap', k, DistanceRequest(max_iterations=k))
                   for k in ITERATION_CAPS])
    rows = []
    for label, scene_object in shapes.items():
        sets = bench_collision.point_sets(scene_object, random=points // 2, near=points // 2,
                                          tapping=0.1, seed=seed)
        world = np.vstack([p for p, _ in sets.values()])
        inputs = [tuple(point) for point in world]
        truth = np.concatenate([d for _, d in sets.values()])
        for sweep, value, request in settings:
            scene = Scene([scene_object], request=request)
            scene.warm_up()
            durations, answers = bench_collision._time_calls(
                lambda p, query=scene.query: query(p).distance, inputs)
            results = [scene.query(p) for p in inputs]
            rows.append({'shape': label, 'sweep': sweep, 'value': value,
                         'median_us': float(np.median(durations)),
                         'p99_us': float(np.percentile(durations, 99)),
                         **error_summary(answers, truth),
                         'iterations': float(np.mean([r.iterations for r in results])),
                         'not_converged': int(sum(r.status == STATUS_NOT_CONVERGED
                                                  for r in results)),
                         'n': len(inputs)})
    return rows


def floor_rows(seconds: float, runs: int, domain_id: int) -> list[dict]:
    """``bench_loop.compare`` per layout, recorder off and on: the loop against its floor."""
    import bench_loop

    return [bench_loop.compare(layout, recorder, runs, seconds, domain_id, report=print)
            for layout in LOOP_LAYOUTS for recorder in (False, True)]


def stiff_wall_rows(duration: float, domain_id: int) -> list[dict]:
    """``stiff_wall_loop.compare`` per wall stiffness: local and remote, and the ideal wall."""
    return [row for k in STIFF_WALLS
            for row in stiff_wall_loop.compare(k, duration=duration, domain_id=domain_id)]


def colgate_bound() -> float:
    """Return the Colgate passivity bound on K for the stiffness sweep's device and wall, N/m."""
    from force_renderer import passivity_bound, PipelineConfig

    return passivity_bound(stiffness_sweep.DEVICE.damping, PipelineConfig().servo_period,
                           stiffness_sweep.WALL_DAMPING)


def teleop_rows(demo_dir: Path, work_dir: Path, domain_id: int, quick: bool) -> dict:
    """Run the telerobotic scan: each scheme and delay in lockstep, the plotted delay over ROS 2.

    Returns ``lockstep`` and ``ros`` rows (``teleop_scan.figures`` plus ``scheme`` and
    ``source``), the ROS runs' series by scheme (``traces``), and the demo's own run (``demo``:
    model at 50 ms, from its bag), None if the demo did not record it.
    """
    delays = (0.05, 0.25) if quick else TELEOP_DELAYS
    lockstep = [{'scheme': scheme, 'source': 'lockstep', **teleop_scan.figures(
        teleop_lockstep.as_series(teleop_lockstep.scan(
            scheme, delay, jitter=TELEOP_JITTER * delay, loss=TELEOP_LOSS)), delay)}
        for delay in delays for scheme in teleop_lockstep.SCHEMES]
    ros, traces = [], {}
    for scheme in TELEOP_SCHEMES:
        folder = work_dir / f'teleop_{scheme}'
        ros.append({'source': 'ROS 2', **teleop_scan.run(
            scheme, TELEOP_PLOTTED, jitter=TELEOP_JITTER, loss=TELEOP_LOSS,
            domain_id=domain_id, keep=folder)})
        traces[scheme] = teleop_scan.read_scan(folder / 'bag')
    bag = demo_dir / 'teleop' / 'bag'
    demo = ({'scheme': 'model', 'source': 'ROS 2, demo', **teleop_scan.figures(
        teleop_scan.read_scan(bag), TELEOP_DEMO_DELAY)} if bag.exists() else None)
    return {'lockstep': lockstep, 'ros': ros, 'traces': traces, 'demo': demo}
