"""Error against run time on the paper's three objects: our engine, the paper's method, peers.

    .venv/bin/python bench/error_time.py [--random 300] [--near 300] [--tapping 1]
                                         [--slow-points 200] [--json PATH]

Every method answers the same points (``bench_collision.point_sets``: random in twice the
bounding box, within +-2 mm of the surface, a 1 kHz tapping path), one Python call each, timed
as ``bench_collision`` times its methods, and is checked against exact truth: our engine on the
exact object and on the paper's STL's convex hull, the paper's collision code
(``paper_method``), python-fcl, coal, and trimesh's signed distance (every k-th point only,
``--slow-points`` in all). A method that cannot run says why. The report's chapter 3.
"""

import argparse
import math
import sys

from bench import bench_collision, machine, result_files
import numpy as np
from report_generator.paper_method import PaperMethod
from report_generator.report_experiments import Experiment, EXPERIMENTS
from report_generator.report_format import format_number
from report_generator.report_metrics import error_summary, false_samples
from report_generator.report_paper_replay import paper_rows

from collision_engine import ConvexMesh, load_scene
from collision_engine.scene import SceneObject

__all__ = ['error_time_rows', 'hull_object', 'main']


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


def hull_object(experiment: Experiment, exact: SceneObject) -> SceneObject:
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
         lambda: methods['ours'](hull_object(experiment, exact))),
        ('paper\'s method (re-implemented)', 'STL vertex rows',
         lambda: _paper_function(paper_rows(experiment)[0])),
        ('python-fcl', exact_kind, lambda: methods['python-fcl'](exact)),
        ('coal', exact_kind, lambda: methods['coal'](exact)),
        ('trimesh signed_distance', 'STL mesh', lambda: _trimesh_function(experiment)),
    ]


def error_time_rows(*, random: int, near: int, tapping: float, slow_points: int,
                    seed: int = 0) -> list[dict]:
    """Per object and method: per-query time and error against exact truth."""
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


def main(argv=None) -> int:
    """Print, and with --json store, the time and error of every method per object."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--random', type=int, default=300, help='random points per object')
    parser.add_argument('--near', type=int, default=300, help='near-surface points per object')
    parser.add_argument('--tapping', type=float, default=1.0, help='tapping seconds at 1 kHz')
    parser.add_argument('--slow-points', type=int, default=200, help='points trimesh answers')
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    print(f'machine: {machine.line("numba", "python-fcl", "coal", "trimesh")}')
    overhead = bench_collision.timer_overhead()
    print(f'timer overhead (an empty call, in every time): {overhead:.2f} us median')
    rows = error_time_rows(random=args.random, near=args.near, tapping=args.tapping,
                           slow_points=args.slow_points)
    for r in rows:
        figures = r.get('unavailable') or ', '.join(
            f'{key} {format_number(r[key])}' for key in ('median_us', 'p99_us', 'mean', 'max'))
        print(f'{r["object"]:<9} {r["method"]:<40} {figures}', flush=True)
    result_files.write(args.json, {'timer_overhead_us': overhead, 'rows': rows})
    return 0


if __name__ == '__main__':
    sys.exit(main())
