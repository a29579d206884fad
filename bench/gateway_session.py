"""Each site's gateway in its site's process, against the gateways as processes of their own.

    .venv/bin/python bench/gateway_session.py [--pairs 3] [--hogs 1] [--thread-priority 50]
        [--json PATH]

The model-mediated scan over a 50 ms link (5 ms jitter, 1 % loss), as ``make demo`` runs it
(``bench.scan_streams``), with the gateways in the sites' processes (``LoopConfig
.gateway_in_process``, the deployed layout) and as two processes of their own (the baseline),
alternated in one run (in, apart, then apart, in, ...): the same machine, the same load. What
``bench/bench_link.py`` measures of the link alone, this measures of a whole session: the 1 kHz
streams, in over apart (targets: rates and answered share >= 0.99, p99 <= 1.1), and the CPU of
every process of the session, in all and by site (a site: its process, and its gateway's when
apart). ``--hogs N`` keeps N cores busy with other processes for the whole run;
``--thread-priority P`` runs the sites' processes (and the gateways') under ``SCHED_FIFO`` P.
The load average is printed with each run: the machine is shared, and only the ratios of runs
side by side are figures.
"""
import argparse
import pathlib
import sys
import tempfile

from bench import machine, result_files, ros_domain
from bench.scan_streams import scan, stream_ratios, TARGETS, total_cpu
from bench.teleop_load import loaded
import numpy as np

__all__ = ['main', 'run', 'summary']

LAYOUTS = {True: 'in the sites', False: 'apart'}


def run(in_process: bool, domain_id: int, priority: int = 0) -> dict:
    """One scan, its figures, with the gateways in the sites' processes or apart."""
    with tempfile.TemporaryDirectory() as tmp:
        row, _ = scan(pathlib.Path(tmp), domain_id, gateway_in_process=in_process,
                      thread_priority=priority or None)
    sites = {role: sum(cpu for name, cpu in row['cpu_percent'].items()
                       if name.startswith(role)) for role in ('operator', 'remote')}
    return {**row, 'gateway_in_process': in_process, 'site_cpu_percent': sites}


def summary(rows: list) -> dict:
    """Return the ratios in / apart of each stream figure, within each group, and the CPU."""
    groups = sorted({row['group'] for row in rows})
    pairs = [tuple(next(r for r in rows if r['group'] == group
                        and r['gateway_in_process'] is layout) for layout in (True, False))
             for group in groups]
    ratios, ranges = stream_ratios(pairs)

    def median(runs, value) -> float:
        return float(np.median([value(r) for r in runs]))
    cpu = {LAYOUTS[layout]: {
        'total': median([p[k] for p in pairs], total_cpu),
        **{role: median([p[k] for p in pairs], lambda r, role=role: r['site_cpu_percent'][role])
           for role in ('operator', 'remote')}} for k, layout in enumerate((True, False))}
    return {'pairs': len(pairs), 'ratios': ratios, 'ranges': ranges, 'cpu_percent': cpu,
            'targets': TARGETS}


def _print_row(row: dict) -> None:
    print(f'gateways {LAYOUTS[row["gateway_in_process"]]:>12}: operator '
          f'{row["operator_rate_hz"]:.0f} Hz, {row["operator_answered_percent"]:.1f} % answered, '
          f'round trip p99 {1e3 * row["operator_round_trip_p99_s"]:.2f} ms; robot '
          f'{row["robot_rate_hz"]:.0f} Hz, tick p99 {1e3 * row["robot_tick_p99_s"]:.2f} ms; '
          f'commands {row["commands_hz"]:.0f}/s, feedback {row["feedback_hz"]:.0f}/s; CPU '
          f'{total_cpu(row):.0f} % (' + ', '.join(
              f'{n} {c:.0f}' for n, c in row['cpu_percent'].items())
          + f'); load {row["load"]:.1f}', flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--pairs', type=int, default=3,
                        help='groups of runs: the gateways in the sites, and apart')
    parser.add_argument('--hogs', type=int, default=0,
                        help='other processes, each keeping a core busy, for the whole run')
    parser.add_argument('--thread-priority', type=int, default=0, metavar='P',
                        help="the sites' real-time priority (0: normal scheduling, the "
                        "nodes' default)")
    ros_domain.add_option(parser, help="the operator's site; the remote's is the next")
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    ros_domain.keep_local()
    print(f'machine: {machine.line("ros-jazzy-rclpy", "eclipse-zenoh")}; hogs {args.hogs}, '
          f'thread priority {args.thread_priority}')

    def runs() -> list:
        rows = []
        for group in range(args.pairs):
            for layout in ((True, False) if group % 2 == 0 else (False, True)):
                rows.append({**run(layout, args.domain_id, args.thread_priority),
                             'group': group})
                _print_row(rows[-1])
        return rows
    rows = loaded(runs, args.hogs)
    result = summary(rows)
    print('in the sites / apart, median [range] over the groups (targets: rates and answered '
          '>= 0.99, p99 <= 1.1): ' + ', '.join(
              f'{key} {value:.3f} [{low:.3f}-{high:.3f}]' for (key, value), (low, high)
              in zip(result['ratios'].items(), result['ranges'].values())))
    print('CPU, % of one core (median): ' + '; '.join(
        f'gateways {layout}: {cpu["total"]:.0f} in all, operator site {cpu["operator"]:.0f}, '
        f'remote site {cpu["remote"]:.0f}' for layout, cpu in result['cpu_percent'].items()))
    result_files.write(args.json, {'rows': rows, 'summary': result, 'hogs': args.hogs,
                                   'thread_priority': args.thread_priority})
    return 0


if __name__ == '__main__':
    sys.exit(main())
