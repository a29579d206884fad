"""Our GJK's tolerance and iteration-cap trade-off: error and time as each setting varies.

    .venv/bin/python bench/gjk_tradeoff.py [--points 600] [--json PATH]

On the true cylinder (analytic support) and the hand's convex hull (hundreds of vertices), one
``Scene.query`` per point as the collision node makes them, in a scene built with the
``DistanceRequest`` of each setting, over the same points per shape (random, near the surface,
tapping: ``bench_collision.point_sets``), against exact truth. The report's chapter 3.
"""

import argparse
import sys

from bench import bench_collision, machine, result_files
from bench.error_time import hull_object
import numpy as np
from report_generator.report_experiments import EXPERIMENTS
from report_generator.report_format import format_number
from report_generator.report_metrics import error_summary

from collision_engine import DistanceRequest, load_scene, Scene, STATUS_NOT_CONVERGED

__all__ = ['ITERATION_CAPS', 'TOLERANCES', 'main', 'tradeoff_rows']

TOLERANCES = (1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
ITERATION_CAPS = (1, 2, 3, 4, 6, 8, 12, 16, 100)


def tradeoff_rows(points: int, seed: int = 0) -> list[dict]:
    """Error and time of our GJK per shape, tolerance and iteration cap."""
    cylinder = load_scene(EXPERIMENTS['cylinder'].scene_file).objects[0]
    hand = load_scene(EXPERIMENTS['hand'].scene_file).objects[0]
    shapes = {'cylinder (exact)': cylinder,
              'hand\'s convex hull': hull_object(EXPERIMENTS['hand'], hand)}
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


def main(argv=None) -> int:
    """Print, and with --json store, the trade-off table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--points', type=int, default=600, help='points per shape')
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    print(f'machine: {machine.line("numba")}')
    rows = tradeoff_rows(args.points)
    for r in rows:
        print(f'{r["shape"]:<20} {r["sweep"]:<13} {r["value"]:<7g} median '
              f'{format_number(r["median_us"])} us, iterations {format_number(r["iterations"])},'
              f' max error {format_number(r["max"])} m', flush=True)
    result_files.write(args.json, rows)
    return 0


if __name__ == '__main__':
    sys.exit(main())
