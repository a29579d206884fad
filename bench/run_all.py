"""Run every benchmark in ``bench/`` in turn, each in a process of its own, and summarise.

    .venv/bin/python bench/run_all.py [--quick] [--only NAME [NAME ...]]
    make bench [ARGS='--quick --only loop stiff_wall']

Each script runs as ``python bench/<script>`` with this interpreter (``make bench`` uses the
venv's), its output printed as it comes; a script that fails is reported and the rest still
run. The last lines say, per script, ok or failed (with the exit code) and how long it took;
the exit code is 1 if any failed. ``--quick`` gives each script its own smaller sizes (fewer
points, repeats, runs or seconds: ``Benchmark.quick``); none of the scripts has a ``--quick``
of its own. ``BENCHMARKS`` must list every script in ``bench/`` that runs as a benchmark
(``tests/bench/test_run_all.py`` checks it), so a new one cannot be left out.

The benchmarks the report shows are ``stored``: a full run (not ``--quick``, whose sizes give no
figures) passes them ``--json bench/results/<name>.json``, and the report is built from those
files (``result_files``), each section saying when and where its file was measured.
"""

import argparse
from dataclasses import dataclass
import os
from pathlib import Path
import subprocess
import sys
import time

from bench import result_files

__all__ = ['BENCHMARKS', 'Benchmark', 'Outcome', 'main', 'run', 'summary']

BENCH = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Benchmark:
    """One benchmark script in ``bench/``, the arguments that make it quick, whether it is stored.

    A ``stored`` one's full run writes ``result_files.RESULTS / <name>.json``, which the report
    reads.
    """

    name: str
    script: str
    quick: tuple[str, ...] = ()
    stored: bool = False

    def arguments(self, quick: bool, results: Path) -> tuple[str, ...]:
        """Return the script's arguments: quick sizes, or where to store a full run."""
        if quick:
            return self.quick
        return ('--json', str(results / f'{self.name}.json')) if self.stored else ()


@dataclass(frozen=True)
class Outcome:
    """How one script's run ended: its exit code (0 is ok) and its duration, s."""

    benchmark: Benchmark
    returncode: int
    duration: float


BENCHMARKS = (
    Benchmark('collision', 'bench_collision.py', ('--random', '200', '--near', '200',
                                                  '--tapping', '1')),
    Benchmark('cross_validation', 'bench_cross_validation.py', ('--seconds', '1')),
    Benchmark('mesh_load', 'bench_mesh_load.py', ('--rounds', '1')),
    Benchmark('model_error', 'model_error.py', ('--contacts', '100')),
    Benchmark('error_time', 'error_time.py', ('--random', '100', '--near', '100', '--tapping',
                                              '0.4', '--slow-points', '60'), stored=True),
    Benchmark('gjk_tradeoff', 'gjk_tradeoff.py', ('--points', '200'), stored=True),
    Benchmark('wand_driver', 'bench_wand_driver.py', ('--repeats', '2', '--seconds', '2')),
    Benchmark('loop', 'bench_loop.py', ('--runs', '1', '--seconds', '3'), stored=True),
    Benchmark('loop_stats', 'bench_loop_stats.py', ('--hours', '0.1', '1')),
    Benchmark('stream_cost', 'stream_cost.py', ('--seconds', '2', '--runs', '1')),
    Benchmark('stiffness_sweep', 'stiffness_sweep.py', ('--points', '5'), stored=True),
    Benchmark('servo_rate', 'servo_rate.py',
              ('--rates', '1000', '4000', '--stiffness', '5000', '100000'), stored=True),
    Benchmark('stiff_wall', 'stiff_wall_loop.py', ('--duration', '4'), stored=True),
    Benchmark('extreme_cases', 'extreme_cases.py', ('--points', '60'), stored=True),
    Benchmark('tool', 'bench_tool.py', ('--near', '300', '--tapping', '1')),
    Benchmark('probe', 'bench_probe.py', ('--poses', '300')),
    Benchmark('teleop_lockstep', 'teleop_lockstep.py', ('--delays', '0.05'), stored=True),
    Benchmark('teleop_scan', 'teleop_scan.py', ('--delays', '0.05'), stored=True),
    Benchmark('link_door', 'bench_link_door.py', ('--messages', '2000', '--repeats', '1')),
    Benchmark('image', 'bench_image.py', ('--frames', '100', '--no-simus'), stored=True),
    Benchmark('imaging_session', 'imaging_session.py', ('--pairs', '1'), stored=True),
    Benchmark('link', 'bench_link.py', ('--seconds', '5'), stored=True),
    Benchmark('gateway_session', 'gateway_session.py', ('--pairs', '1'), stored=True),
    Benchmark('teleop_load', 'teleop_load.py', ('--schemes', 'model', '--loads', 'hogged',
                                                '--duration', '8'), stored=True),
    Benchmark('recording_load', 'recording_load.py', ('--layouts', 'composed', '--stops', 'end',
                                                      '--hogs', '0', '--seconds', '3')),
)


def run(benchmarks, *, quick: bool = False, folder: Path = BENCH,
        results: Path = result_files.RESULTS) -> list[Outcome]:
    """Run each benchmark's script from ``folder`` in turn; one failure does not stop the rest.

    A stored benchmark's full run writes its results into ``results``.
    """
    environment = dict(os.environ)
    environment.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    outcomes = []
    for count, benchmark in enumerate(benchmarks, 1):
        command = [sys.executable, str(folder / benchmark.script),
                   *benchmark.arguments(quick, results)]
        print(f'[bench] {count}/{len(benchmarks)} {benchmark.name}: {" ".join(command)}',
              flush=True)
        started = time.monotonic()
        returncode = subprocess.run(command, env=environment).returncode
        outcomes.append(Outcome(benchmark, returncode, time.monotonic() - started))
        print(f'[bench]     {benchmark.name}: {_verdict(outcomes[-1])}', flush=True)
    return outcomes


def _verdict(outcome: Outcome) -> str:
    state = 'ok' if outcome.returncode == 0 else f'failed (exit {outcome.returncode})'
    return f'{state}, {outcome.duration:.1f} s'


def summary(outcomes: list[Outcome]) -> str:
    """Return one line per script: its name, its file, ok or failed, and its duration."""
    width = max((len(o.benchmark.name) for o in outcomes), default=0)
    return '\n'.join(f'{o.benchmark.name:<{width}}  {o.benchmark.script:<22} {_verdict(o)}'
                     for o in outcomes)


def main(argv=None) -> int:
    """Run the benchmarks asked for, then print the summary; 1 if any failed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--quick', action='store_true',
                        help='smaller sizes for every script (a smoke run, not figures)')
    parser.add_argument('--only', nargs='+', metavar='NAME',
                        choices=[b.name for b in BENCHMARKS],
                        help='run only these, in the usual order')
    args = parser.parse_args(argv)
    chosen = [b for b in BENCHMARKS if not args.only or b.name in args.only]
    outcomes = run(chosen, quick=args.quick)
    print('[bench] summary:', summary(outcomes), sep='\n', flush=True)
    if not args.quick and any(o.benchmark.stored for o in outcomes):
        print(f'[bench] the report\'s results are in {result_files.RESULTS}; `make report` '
              '(or `make demo`) builds the report from them', flush=True)
    return 0 if all(o.returncode == 0 for o in outcomes) else 1


if __name__ == '__main__':
    sys.exit(main())
