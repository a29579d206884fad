"""The haptic loop over ROS 2 against its floor, and the loop's round trip per layout and rate.

    .venv/bin/python bench/bench_loop.py [--layouts separate composed composed-dds] [--runs 3]
                                         [--seconds 8] [--recorder off on] [--json PATH]
    .venv/bin/python bench/bench_loop.py --sweep [--rates 500 1000 2000] [--duration 10]
    .venv/bin/python bench/bench_loop.py --cross-validation [--runs 3] [--seconds 8]

The default compares the loop with its floor (``loop_floor.py``: the same topology with no work
per hop), alternating floor and loop runs, in each layout: ``separate`` (three processes),
``composed`` (one process, its streams handed over in the process: ``haptic_util.intra_process``)
and ``composed-dds`` (one process, its streams through DDS: the composed layout before that, its
baseline; the floor of both is the bare chain in one process). Each run has one outside
observer (a separate process subscribed to the poses and wrenches, as ``ros2 topic echo`` or RViz
would be), without and with the recorder. The floor is recorded by a recorder process; so is the
loop, but for ``composed``, which records itself (``haptic_bringup.process_recorder``): its CPU
includes its recording. ``--layouts composed-rp`` runs the composed loop with a recorder process
instead, as before the recorder moved in. Per run: CPU of every process over the window (100 %
= one core), and, seen by the observer, the pose rate, the share of poses answered by a wrench,
and pose -> wrench p50 and p99. Then the loop's figures as ratios to the floor's (medians over
the runs), and whether each target of the CPU issue holds.

``--cross-validation`` runs the loop on the hand (where an FCL query costs the most) with the
scene's FCL cross-check on and off, alternated, seen by the same observer: the cross-check runs
on a worker thread, so it must not show in the round trip.

``--sweep`` runs the loop alone at several rates and reads the driver's own round-trip record
(every wrench carries the stamp of its pose, so latency is on one clock).
"""
import argparse
import math
import pathlib
import sys
import tempfile
import time

from bench import machine, result_files, ros_domain
import numpy as np
import psutil
import yaml

from haptic_bringup.launcher import Loop, loop_environment, LoopConfig
from haptic_bringup.processes import start_child, stop_children
from haptic_util.paths import package_file

SCENE = 'package://collision_engine/scenes/cuboid.yaml'
HAND = 'package://collision_engine/scenes/hand.yaml'
CPU_WINDOW_SKIP = 1.0  # [s] CPU is measured inside the session, this far from either end
FLOOR = pathlib.Path(__file__).resolve().parent / 'loop_floor.py'
WARM_UP = 3.0  # [s] from start to the window: discovery, the driver's probe, first contacts
TAIL = 3.0  # [s] of experiment after the window: the cuboid's 10 s script ended inside it
OBSERVER_SETTLE = 0.5  # [s] after the observer first hears both streams (see _observed)
LAYOUTS = ('separate', 'composed', 'composed-dds')
# One process; its streams through DDS in the second; the third records with a recorder process
# (the composed layout's recording before it moved in: --layouts composed-rp).
COMPOSED = ('composed', 'composed-dds', 'composed-rp')
TARGETS = {'cpu': 1.25, 'p99': 1.5, 'rate': 0.99, 'answered': 99.9}  # the CPU issue's


def cpu_seconds(pids) -> float:
    total = 0.0
    for pid in pids:
        times = psutil.Process(pid).cpu_times()
        total += times.user + times.system
    return total


def run_once(layout: str, rate: float, duration: float, domain_id: int) -> dict:
    """One session; returns the driver's loop record plus CPU [% of one core]."""
    with tempfile.TemporaryDirectory() as tmp:
        stats = pathlib.Path(tmp) / 'stats.npz'
        config = LoopConfig(
            composed=layout in COMPOSED, intra_process=layout != 'composed-dds', scene=SCENE,
            experiment='cuboid', duration=duration,
            domain_id=domain_id, run_dir=pathlib.Path(tmp) / 'launch',
            overrides={'wand_driver': {'rate': float(rate), 'stats_file': str(stats)},
                       'collision_engine': {'marker_rate': 0.0},
                       'force_renderer': {'marker_rate': 0.0}})
        with Loop(config) as loop:
            pids = list(loop.pids().values())
            # CPU over a window inside the session, while every process still runs.
            time.sleep(CPU_WINDOW_SKIP)
            cpu_start, wall_start = cpu_seconds(pids), time.monotonic()
            time.sleep(duration - 2 * CPU_WINDOW_SKIP)
            cpu = cpu_seconds(pids) - cpu_start
            wall = time.monotonic() - wall_start
            ended = loop.wait(duration + 10.0)
        if ended is None or not stats.exists():
            raise RuntimeError(f'{layout} at {rate} Hz: the session did not finish')
        record = dict(np.load(stats))
    record['cpu_percent'] = 100.0 * cpu / wall
    return record


def row(label: str, latencies: np.ndarray, record: dict) -> str:
    p50, p90, p99 = 1e3 * np.percentile(latencies, [50, 90, 99])
    return (f'{label:<28} {float(record["rate_hz"]):7.0f} {float(record["answered_percent"]):8.2f}'
            f' {p50:7.3f} {p90:7.3f} {p99:7.3f} {1e3 * latencies.max():7.2f}'
            f' {record["cpu_percent"]:6.0f}')


def _floor_children(layout: str, recorder: bool, folder: pathlib.Path, env: dict) -> list:
    python = sys.executable
    roles = ['composed'] if layout in COMPOSED else ['driver', 'collision', 'force']
    children = [start_child(role, [python, str(FLOOR), role, '--ros-args'], env)
                for role in roles]
    if recorder:
        children.append(start_child('recorder', [
            python, '-m', 'haptic_bringup.recorder', '--ros-args', '-p',
            f'output:={folder / "bag"}'], env))
    return children


def session(kind: str, layout: str, recorder: bool, seconds: float, domain_id: int,
            scene: str = SCENE, experiment: str = 'cuboid') -> dict:
    """One run of the floor or the loop with the outside observer; its figures."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        env = loop_environment(domain_id, folder / 'log')
        observed = folder / 'observed.npz'
        loop = None
        if kind == 'loop':
            loop = Loop(LoopConfig(
                composed=layout in COMPOSED, intra_process=layout != 'composed-dds',
                record_in_process=layout == 'composed', scene=scene,
                experiment=experiment,
                duration=WARM_UP + seconds + TAIL,
                record=str(folder / 'bag') if recorder else None, domain_id=domain_id,
                run_dir=folder / 'launch', overrides={'collision_engine': {'marker_rate': 0.0},
                                                      'force_renderer': {'marker_rate': 0.0}}))
            loop.start()
            children = list(loop.children)
        else:
            children = _floor_children(layout, recorder, folder, env)
        observer = start_child('observer', [sys.executable, str(FLOOR), 'observer',
                                            str(observed), '--ros-args'], env)
        try:
            time.sleep(WARM_UP)
            processes = {c.name: psutil.Process(c.pid) for c in [*children, observer]}
            start_cpu = {name: _cpu(p) for name, p in processes.items()}
            start_ns, start = time.time_ns(), time.monotonic()
            time.sleep(seconds)
            wall = time.monotonic() - start
            end_ns = time.time_ns()
            cpu = {name: 100.0 * (_cpu(p) - start_cpu[name]) / wall
                   for name, p in processes.items()}
        finally:
            stop_children([observer])
            if loop is not None:
                loop.stop()
            else:
                stop_children(children)
        seen = np.load(observed)
    return {'kind': kind, 'cpu': cpu, **_observed(seen, start_ns, end_ns)}


def _cpu(process: psutil.Process) -> float:
    times = process.cpu_times()
    return times.user + times.system


def _observed(seen, start_ns: int, end_ns: int) -> dict:
    """Rate, share answered and latency of the poses stamped inside the window.

    The window starts no earlier than the observer hears both streams (its first pose and its
    first wrench, plus ``OBSERVER_SETTLE``): DDS matches each of its readers on its own, and a
    pose seen before the wrench reader matched has its answer lost to the observer, not the loop
    (3.5 % of the poses of a run whose loop started quickly, without the recorder).
    """
    wrenches = seen['wrenches']
    if seen['poses'].size and wrenches.size:
        heard = max(int(seen['poses'][0]), int(wrenches[0, 1])) + round(OBSERVER_SETTLE * 1e9)
        start_ns = max(start_ns, heard)
    poses = seen['poses'][(seen['poses'] >= start_ns) & (seen['poses'] < end_ns)]
    first = {}
    for stamp, arrival in wrenches.tolist():
        first.setdefault(stamp, arrival)
    latency = np.array([first[s] - s for s in poses.tolist() if s in first]) * 1e-9
    return {'rate': poses.size / ((end_ns - start_ns) * 1e-9),
            'answered': 100.0 * latency.size / max(poses.size, 1),
            'p50': float(np.percentile(latency, 50)) if latency.size else math.nan,
            'p99': float(np.percentile(latency, 99)) if latency.size else math.nan}


def loop_cpu(run: dict) -> float:
    """CPU of the loop's own processes (not the recorder's, nor the observer's), %."""
    return sum(v for name, v in run['cpu'].items() if name not in ('recorder', 'observer'))


def compare(layout: str, recorder: bool, runs: int, seconds: float, domain_id: int,
            report=print) -> dict:
    """Alternate floor and loop runs; return the runs and the loop's ratios to the floor."""
    floor, loop = [], []
    for run in range(runs):
        for kind, runs_of_kind in (('floor', floor), ('loop', loop)):
            result = session(kind, layout, recorder, seconds, domain_id)
            runs_of_kind.append(result)
            report(_run_line(f'{layout}, recorder {"on" if recorder else "off"}, {kind} '
                             f'#{run + 1}', result))
    median = {kind: {key: float(np.median([f(r) for r in results])) for key, f in (
        ('cpu', loop_cpu), ('rate', lambda r: r['rate']), ('answered', lambda r: r['answered']),
        ('p50', lambda r: r['p50']), ('p99', lambda r: r['p99']))}
        for kind, results in (('floor', floor), ('loop', loop))}
    ratios = {key: median['loop'][key] / median['floor'][key]
              for key in ('cpu', 'rate', 'p50', 'p99')}
    return {'layout': layout, 'recorder': recorder, 'floor': floor, 'loop': loop,
            'median': median, 'ratios': ratios}


def _run_line(label: str, run: dict) -> str:
    processes = ', '.join(f'{name} {value:.0f}' for name, value in run['cpu'].items())
    return (f'{label:<36} loop CPU {loop_cpu(run):5.0f} %  rate {run["rate"]:6.0f} Hz  '
            f'answered {run["answered"]:7.3f} %  p50 {1e3 * run["p50"]:6.2f} ms  '
            f'p99 {1e3 * run["p99"]:6.2f} ms  ({processes})')


def verdicts(comparison: dict) -> list:
    """Return the CPU issue's targets for this comparison, as (what, holds) pairs."""
    ratios, loop = comparison['ratios'], comparison['median']['loop']
    checks = [(f'loop CPU {ratios["cpu"]:.2f} x the floor\'s (target <= {TARGETS["cpu"]})',
               ratios['cpu'] <= TARGETS['cpu'])]
    if comparison['recorder']:
        checks += [
            (f'answered {loop["answered"]:.2f} % (target >= {TARGETS["answered"]})',
             loop['answered'] >= TARGETS['answered']),
            (f'p99 {ratios["p99"]:.2f} x the floor\'s (target <= {TARGETS["p99"]})',
             ratios['p99'] <= TARGETS['p99']),
            (f'rate {ratios["rate"]:.3f} x the floor\'s (target >= {TARGETS["rate"]})',
             ratios['rate'] >= TARGETS['rate'])]
    return checks


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--layouts', nargs='+', default=list(LAYOUTS),
                        choices=[*LAYOUTS, 'composed-rp'])
    parser.add_argument('--recorder', nargs='+', default=['off', 'on'], choices=['off', 'on'])
    parser.add_argument('--runs', type=int, default=3, help='floor/loop pairs per case')
    parser.add_argument('--seconds', type=float, default=8.0, help='measured window per run')
    parser.add_argument('--sweep', action='store_true', help='the loop alone at --rates')
    parser.add_argument('--cross-validation', action='store_true',
                        help="the loop on the hand with the scene's FCL cross-check on and off")
    parser.add_argument('--rates', nargs='+', type=float, default=[1000.0])
    parser.add_argument('--duration', type=float, default=10.0, help='per --sweep run')
    ros_domain.add_option(parser)
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    ros_domain.keep_local()
    print(f'machine: {machine.line("ros-jazzy-rclpy", "numba")}')
    if args.sweep:
        return sweep(args)
    if args.cross_validation:
        return cross_validation(args)
    print(f'{args.runs} alternated floor/loop pair(s) of {args.seconds:g} s per case; CPU in % '
          'of one core; rate, answered and latency seen by the outside observer')
    table = []
    for layout in args.layouts:
        for recorder in args.recorder:
            comparison = compare(layout, recorder == 'on', args.runs, args.seconds,
                                 args.domain_id, report=lambda line: print(line, flush=True))
            table.append(comparison)
    print()
    print(f'{"case":<28} {"CPU x":>6} {"rate x":>7} {"answered %":>11} {"p50 x":>6} '
          f'{"p99 x":>6}  targets')
    for comparison in table:
        ratios, loop = comparison['ratios'], comparison['median']['loop']
        held = all(ok for _, ok in verdicts(comparison))
        case = f'{comparison["layout"]}, recorder {"on" if comparison["recorder"] else "off"}'
        print(f'{case:<28} '
              f'{ratios["cpu"]:6.2f} {ratios["rate"]:7.3f} {loop["answered"]:11.3f} '
              f'{ratios["p50"]:6.2f} {ratios["p99"]:6.2f}  {"held" if held else "MISSED"}')
        for what, ok in verdicts(comparison):
            print(f'    {"ok  " if ok else "MISS"} {what}')
    result_files.write(args.json, table)
    return 0


def hand_scene(fcl: bool, folder: pathlib.Path) -> str:
    """Write the shipped hand scene with its FCL cross-check on or off; return its path."""
    shipped = package_file(HAND)
    scene = yaml.safe_load(shipped.read_text())
    scene['cross_validation']['fcl'] = fcl
    for item in scene['objects']:
        mesh = item['shape']['mesh']
        mesh['file'] = str(shipped.parent / mesh['file'])
    path = folder / f'hand_fcl_{"on" if fcl else "off"}.yaml'
    path.write_text(yaml.safe_dump(scene))
    return str(path)


def cross_validation(args) -> int:
    print(f'{args.runs} alternated pair(s) of {args.seconds:g} s, three processes on the hand; '
          'rate, answered and latency seen by the outside observer')
    results = {'off': [], 'on': []}
    with tempfile.TemporaryDirectory() as tmp:
        for run in range(args.runs):
            for state in ('off', 'on'):
                result = session('loop', 'separate', False, args.seconds, args.domain_id,
                                 scene=hand_scene(state == 'on', pathlib.Path(tmp)),
                                 experiment='hand')
                results[state].append(result)
                print(_run_line(f'FCL cross-check {state} #{run + 1}', result), flush=True)
    median = {state: {key: float(np.median([r[key] for r in runs]))
                      for key in ('rate', 'answered', 'p50', 'p99')}
              for state, runs in results.items()}
    collision_cpu = {state: float(np.median([r['cpu']['collision_engine'] for r in runs]))
                     for state, runs in results.items()}
    print()
    print(f'{"FCL cross-check":<16} {"collision CPU %":>15} {"answered %":>11} {"p50 ms":>7} '
          f'{"p99 ms":>7}')
    for state in ('off', 'on'):
        m = median[state]
        print(f'{state:<16} {collision_cpu[state]:15.0f} {m["answered"]:11.3f} '
              f'{1e3 * m["p50"]:7.3f} {1e3 * m["p99"]:7.3f}')
    print(f'p99 on/off: {median["on"]["p99"] / median["off"]["p99"]:.2f}')
    return 0


def sweep(args) -> int:
    print(f'{args.runs} run(s) of {args.duration:g} s per layout and rate; latency in ms; '
          'CPU in % of one core, all loop processes')
    print(f'{"layout / rate / run":<28} {"pose Hz":>7} {"answered":>8} {"p50":>7} {"p90":>7} '
          f'{"p99":>7} {"max":>7} {"CPU %":>6}')
    for layout in args.layouts:
        for rate in args.rates:
            records = []
            for run in range(args.runs):
                record = run_once(layout, rate, args.duration, args.domain_id)
                records.append(record)
                print(row(f'{layout} {rate:g} Hz #{run + 1}', record['latencies'], record),
                      flush=True)
            pooled = {key: np.mean([float(r[key]) for r in records])
                      for key in ('rate_hz', 'answered_percent', 'cpu_percent')}
            latencies = np.concatenate([r['latencies'] for r in records])
            print(row(f'{layout} {rate:g} Hz, pooled', latencies, pooled), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
