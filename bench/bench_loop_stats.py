"""The driver's loop record over long sessions: resident memory and the 1 Hz report's cost.

    .venv/bin/python bench/bench_loop_stats.py [--hours 1 10] [--baseline 4b8ab33]

Each implementation runs in its own process, which feeds ``LoopStats`` the calls a 1 kHz driver
makes (``sent`` and ``answered`` per pose; no ROS) for the given simulated hours, and prints its
resident memory (RSS) and the median cost of one ``summary()`` -- what the driver's 1 Hz
diagnostics report calls on the loop's executor -- at each mark. The baseline is the module as it
was at commit ``--baseline`` (read from git, so it is the code that was replaced, unchanged), run
beside today's in the same invocation.
"""
import argparse
import functools
import importlib.util
import inspect
import json
import pathlib
import subprocess
import sys
import tempfile
import time

from bench import machine

ROOT = pathlib.Path(__file__).resolve().parents[1]
MODULE = 'src/haptic_wand_driver/haptic_wand_driver/loop_stats.py'
TICKS_PER_HOUR = 3_600_000  # 1 kHz
REPORTS = 20  # summary() calls timed at each mark

__all__ = ['main']


def measure(module_path: str, hours: list) -> list:
    """Run LoopStats from ``module_path`` through ``hours``; return a row per mark."""
    import numpy as np
    import psutil

    spec = importlib.util.spec_from_file_location('loop_stats_under_test', module_path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    stats = module.LoopStats()
    # As each driver called it: the baseline's report asked for the last 10 000 answers.
    report = (functools.partial(stats.summary, last=10_000)
              if 'last' in inspect.signature(stats.summary).parameters else stats.summary)
    process = psutil.Process()
    rows, done = [], 0
    for mark in sorted(hours):
        for k in range(done, int(mark * TICKS_PER_HOUR)):
            stamp = k * 1_000_000
            stats.sent(stamp)
            stats.answered(stamp, stamp + 700_000)
        done = int(mark * TICKS_PER_HOUR)
        costs = []
        for _ in range(REPORTS):
            start = time.perf_counter()
            report()
            costs.append(time.perf_counter() - start)
        rows.append({'hours': mark, 'rss_mb': process.memory_info().rss / 2**20,
                     'report_ms': 1e3 * float(np.median(costs))})
    return rows


def run(label: str, module_path: str, hours: list) -> list:
    """Measure in a fresh process, so one implementation's memory cannot count for another."""
    code = ('import json; from bench import bench_loop_stats as b; '
            f'print(json.dumps(b.measure({module_path!r}, {hours!r})))')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         check=True).stdout
    return [dict(row, implementation=label) for row in json.loads(out.splitlines()[-1])]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--hours', type=float, nargs='+', default=[1.0, 10.0])
    parser.add_argument('--baseline', default='4b8ab33', help='commit of the replaced module')
    args = parser.parse_args(argv)
    print(machine.line('numpy', 'psutil'))
    with tempfile.TemporaryDirectory() as folder:
        baseline = pathlib.Path(folder) / 'loop_stats_baseline.py'
        baseline.write_text(subprocess.run(['git', 'show', f'{args.baseline}:{MODULE}'],
                                           cwd=ROOT, capture_output=True, text=True,
                                           check=True).stdout)
        rows = (run(f'baseline ({args.baseline})', str(baseline), args.hours)
                + run('today', str(ROOT / MODULE), args.hours))
    print(f'{"implementation":<20} {"hours":>6} {"RSS MB":>8} {"summary() ms":>13}')
    for row in rows:
        print(f'{row["implementation"]:<20} {row["hours"]:>6g} {row["rss_mb"]:>8.1f} '
              f'{row["report_ms"]:>13.3f}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
