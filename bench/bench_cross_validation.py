"""What the FCL cross-check costs a 1 kHz query: off, on a worker thread, and inline as before.

    .venv/bin/python bench/bench_cross_validation.py [--seconds 5] [--every 10]

``Scene.query`` is called at 1 kHz (each call starts on a 1 ms tick, as the node's callback
would; between ticks the loop sleeps, as an executor waiting for messages does, and spins
only its last 0.3 ms), on a 1 mm tapping path near each object's surface, and every call is
timed. Three ways: without the cross-check; with it on its worker thread (the query hands
every ``every``-th answer to a bounded queue); and with ``FclCrossValidator.check`` called
inline after every ``every``-th query, as the query did before the worker existed. Printed per
object and way: median, p99, p99.9 and max time of a query in us, each as a ratio to the same
figure without the cross-check (measured in the same run), and the checker's totals.

python-fcl holds the GIL through a distance call, so while the worker is inside FCL (about
5-30 us, rarely milliseconds) a query waits for it; the winding number is compiled without the
GIL. A checker in a process of its own would remove that wait.
"""

import argparse
import time

from bench import bench_collision, machine
from ground_truth import distances
import numpy as np

from collision_engine.cross_validation import FclCrossValidator
from collision_engine.scene import load_scene, Scene
from collision_engine.scene_file import CrossValidationSpec

RATE = 1000.0
SPIN = 3e-4  # s: the last part of a tick spent spinning, for a punctual start
TOLERANCE = 1e-6


def paced(query, points, period: float = 1.0 / RATE) -> np.ndarray:
    """Call ``query`` on each point at the start of its own tick; return each call's us."""
    durations = np.empty(len(points))
    clock = time.perf_counter
    tick = clock()
    for k, point in enumerate(points):
        tick += period
        idle = tick - clock() - SPIN
        if idle > 0.0:
            time.sleep(idle)  # releases the GIL, as an executor waiting for messages does
        while clock() < tick:
            pass
        start = clock()
        query(point)
        durations[k] = (clock() - start) * 1e6
    return durations


def inline_checked(scene: Scene, every: int):
    """Scene.query followed by a synchronous FCL check every ``every``-th call (the old way)."""
    validator = FclCrossValidator([o.shape for o in scene.objects],
                                  [o.pose for o in scene.objects], tolerance=TOLERANCE)
    count = [0]

    def query(point):
        result = scene.query(point)
        if count[0] % every == 0:
            validator.check(result.object_index, point, result.distance, result.point)
        count[0] += 1
        return result

    return query, validator


def run(name: str, seconds: float, every: int) -> list[dict]:
    """Time the three ways on one shipped scene's object; one row per way."""
    shipped = load_scene(distances.scene_path(name))
    sets = bench_collision.point_sets(shipped.objects[0], random=10, near=200, tapping=seconds)
    points = [tuple(p) for p in sets['tapping'][0]]
    plain = Scene(shipped.objects, frame_id=shipped.frame_id)
    worker = Scene(shipped.objects, frame_id=shipped.frame_id,
                   cross_validation=CrossValidationSpec(fcl=True, every=every,
                                                        tolerance=TOLERANCE))
    inline, validator = inline_checked(plain, every)
    rows = []
    for way, query in (('off', plain.query), ('worker thread', worker.query),
                       ('inline (before)', inline)):
        for point in points[:200]:  # warm up
            query(point)
        durations = paced(query, points)
        rows.append({'object': name, 'way': way, 'median': float(np.median(durations)),
                     'p99': float(np.percentile(durations, 99)),
                     'p999': float(np.percentile(durations, 99.9)),
                     'max': float(durations.max())})
    worker.wait_for_cross_validation(timeout=60.0)
    rows[1]['stats'] = worker.cross_validation_stats
    rows[2]['stats'] = validator.stats
    worker.close()
    return rows


def main(argv=None) -> None:
    """Print the machine and one line per object and way."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=5.0, help='tapping seconds per way')
    parser.add_argument('--every', type=int, default=10, help='check every n-th query')
    parser.add_argument('--objects', nargs='+', default=['hand', 'cuboid'])
    args = parser.parse_args(argv)
    print('machine:', machine.line('numpy', 'numba', 'python-fcl'))
    print(f'{"object":8s} {"way":16s} {"median us":>9s} {"/ off":>6s} {"p99 us":>8s} '
          f'{"/ off":>6s} {"p99.9 us":>8s} {"/ off":>6s} {"max us":>8s} {"/ off":>6s}  checks, '
          f'disagreements, dropped, sign checks')
    for name in args.objects:
        rows = run(name, args.seconds, args.every)
        off = rows[0]
        for row in rows:
            stats = row.get('stats')
            totals = (f'{stats.checks}, {stats.disagreements}, {stats.dropped}, '
                      f'{stats.sign_checks}' if stats else '')
            print(f'{name:8s} {row["way"]:16s} {row["median"]:9.2f} '
                  f'{row["median"] / off["median"]:6.2f} {row["p99"]:8.2f} '
                  f'{row["p99"] / off["p99"]:6.2f} {row["p999"]:8.1f} '
                  f'{row["p999"] / off["p999"]:6.2f} {row["max"]:8.1f} '
                  f'{row["max"] / off["max"]:6.2f}  {totals}')


if __name__ == '__main__':
    main()
