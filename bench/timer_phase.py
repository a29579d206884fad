"""A session whose processes start their timers at one instant, beside the code before it.

    .venv/bin/python bench/timer_phase.py [--pairs 3] [--baseline REF] [--hogs 1] [--json PATH]

The model-mediated scan over a 50 ms link, as ``make demo`` runs it (``bench.scan_streams``),
from this tree and from the code at ``--baseline`` (``git archive`` of it, its packages first on
the sites' path, as ``bench/teleop_load.py`` runs its baseline), alternated in one run. Each
process started its timers as its nodes were made, and the EventsExecutor woke once for each
1 kHz timer's firing: the remote site's robot, follower and gateway handover three times a
millisecond. ``haptic_util.executor.align_timers`` starts them together. Printed: the 1 kHz
streams, this tree over the baseline (targets as for any change to a session: rates and
answered share >= 0.99, p99 <= 1.1), and the CPU of every process of the session, in all and by
site. The load average is printed with each run: only the ratios of runs side by side are
figures.
"""
import argparse
import contextlib
import os
import pathlib
import sys
import tempfile

from bench import machine, result_files, ros_domain
from bench.scan_streams import scan, stream_ratios, TARGETS, total_cpu
from bench.teleop_load import baseline_tree, loaded
import numpy as np

__all__ = ['main']

BASELINE = 'de5f2d5'  # main before the timers were aligned
CODES = ('aligned', 'baseline')


@contextlib.contextmanager
def children_environment(env: dict):
    """Start the session's processes with ``env`` (None: this process's own) meanwhile."""
    saved = dict(os.environ)
    os.environ.update(env or {})
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


def run(env: dict | None, domain_id: int) -> dict:
    """One scan and its figures, its processes started with ``env``."""
    with tempfile.TemporaryDirectory() as tmp, children_environment(env):
        row, _ = scan(pathlib.Path(tmp), domain_id)
    sites = {role: sum(cpu for name, cpu in row['cpu_percent'].items()
                       if name.startswith(role)) for role in ('operator', 'remote')}
    return {**row, 'site_cpu_percent': sites}


def summary(pairs: list) -> dict:
    """Return the ratios aligned / baseline of each stream figure, and each code's CPU."""
    ratios, ranges = stream_ratios(pairs)
    cpu = {code: {'total': float(np.median([total_cpu(p[k]) for p in pairs])),
                  **{role: float(np.median([p[k]['site_cpu_percent'][role] for p in pairs]))
                     for role in ('operator', 'remote')}}
           for k, code in enumerate(CODES)}
    return {'pairs': len(pairs), 'ratios': ratios, 'ranges': ranges, 'cpu_percent': cpu,
            'targets': TARGETS}


def _print_row(code: str, row: dict) -> None:
    print(f'{code:>8}: operator {row["operator_rate_hz"]:.0f} Hz, round trip p99 '
          f'{1e3 * row["operator_round_trip_p99_s"]:.2f} ms; robot {row["robot_rate_hz"]:.0f} Hz, '
          f'tick p99 {1e3 * row["robot_tick_p99_s"]:.2f} ms; commands {row["commands_hz"]:.0f}/s; '
          f'CPU {total_cpu(row):.0f} % (operator site {row["site_cpu_percent"]["operator"]:.0f}, '
          f'remote site {row["site_cpu_percent"]["remote"]:.0f}); load {row["load"]:.1f}',
          flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--pairs', type=int, default=3)
    parser.add_argument('--baseline', default=BASELINE, help='git ref of the code before')
    parser.add_argument('--hogs', type=int, default=0,
                        help='other processes, each keeping a core busy, for the whole run')
    ros_domain.add_option(parser, help="the operator's site; the remote's is the next")
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    ros_domain.keep_local()
    print(f'machine: {machine.line("ros-jazzy-rclpy", "eclipse-zenoh")}; hogs {args.hogs}; '
          f'baseline {args.baseline}')
    with tempfile.TemporaryDirectory() as tmp:
        baseline = baseline_tree(args.baseline, pathlib.Path(tmp))

        def runs() -> list:
            pairs = []
            for pair in range(args.pairs):
                order = CODES if pair % 2 == 0 else CODES[::-1]
                rows = {code: run(None if code == 'aligned' else baseline, args.domain_id)
                        for code in order}
                for code in order:
                    _print_row(code, rows[code])
                pairs.append(tuple(rows[code] for code in CODES))
            return pairs
        pairs = loaded(runs, args.hogs)
    result = summary(pairs)
    print('aligned / baseline, median [range] over the pairs (targets: rates and answered '
          '>= 0.99, p99 <= 1.1): ' + ', '.join(
              f'{key} {value:.3f} [{low:.3f}-{high:.3f}]' for (key, value), (low, high)
              in zip(result['ratios'].items(), result['ranges'].values())))
    print('CPU, % of one core (median): ' + '; '.join(
        f'{code}: {cpu["total"]:.0f} in all, operator site {cpu["operator"]:.0f}, remote site '
        f'{cpu["remote"]:.0f}' for code, cpu in result['cpu_percent'].items()))
    result_files.write(args.json, {'pairs': [dict(zip(CODES, pair)) for pair in pairs],
                                   'summary': result, 'hogs': args.hogs,
                                   'baseline': args.baseline})
    return 0


if __name__ == '__main__':
    sys.exit(main())
