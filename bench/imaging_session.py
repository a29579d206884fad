"""The probe's image in the telerobotic session: what it costs the 1 kHz loops, and how late it is.

    .venv/bin/python bench/imaging_session.py [--pairs 3] [--imager 5 idle ...]
        [--thread-priority 50 0] [--hogs 1] [--json PATH]

The model-mediated scan over a 50 ms link (5 ms jitter, 1 % loss), as ``make demo`` runs it,
with the remote site's imager on and off (``LoopConfig.imaging``), alternated in one run (on,
off, then off, on, ...): the same machine, the same load, the baseline beside each. Every
figure is measured from outside the imager, over the scan's press and sweep (3 to 15 s after
the session's start, ``wand/session_start``):

- **the 1 kHz streams**: the operator's loop as its driver measures it (poses a second, the
  share answered, the round trip's p99: ``stats_file``); the robot's ticks from the stamps of
  the ``robot/tcp_pose`` its own process recorded (a second, and the tick's p99); the commands
  that reached the remote site and the feedback that reached the operator, a second. Targets,
  on over off: rates and answered share >= 0.99, p99 <= 1.1;
- **the CPU** of every process of the session (``psutil``, % of one core): what imaging adds,
  and that per frame (the added CPU over the frames a second the operator received);
- **pose to image**: the frame's stamp (the TCP pose it shows) to its arrival in the
  operator's bag, p50 and p99, the link's delay included (target: p99 <= 50 ms + the delay);
  and to its publication at the remote site, as the imager reports it.

The imager is a process of its own beside the remote site's, whose frame thread yields the cores to
the loops (``haptic_util.priority``): by default at a niceness 5 above theirs, or under
``SCHED_IDLE``. ``--imager`` names how, one or more (a niceness such as ``5``, or ``idle``). The
loops' own processes run at each real-time priority ``--thread-priority`` names (``SCHED_FIFO``,
the nodes' ``thread_priority``), one or more; 0 is normal scheduling, the nodes' default and the
baseline. Each pair of a priority and an imager is run beside an
imaging-off run at that priority in each group of runs, the order turning from one group to the
next. ``--hogs N`` keeps N cores busy with other processes for the whole run (a sonographer's
workstation is never idle). The load average is printed with each run: the machine is shared,
and only the ratios of runs side by side are figures.
"""
import argparse
import pathlib
import sys
import tempfile

from bench import machine, result_files, ros_domain
from bench.scan_streams import LINK, rate, scan, stream_ratios, TARGETS, total_cpu, WINDOW
from bench.teleop_load import loaded
import numpy as np

from haptic_bringup.bag import typestore_with
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import read_frames, reported

__all__ = ['label', 'main', 'run', 'summary']

OFF, IDLE = 'off', 'idle'  # the baseline; the imager's frame thread under SCHED_IDLE


def imager_parameters(variant: str) -> dict:
    """Return the imager's parameters for ``variant``: ``idle``, or a niceness."""
    return {'idle': True} if variant == IDLE else {'idle': False, 'niceness': int(variant)}


def run(variant: str, priority: int, domain_id: int) -> dict:
    """One scan, its figures: the imager off (``OFF``) or yielding as ``variant`` says.

    The loops run at real-time ``priority`` (0: normal scheduling).
    """
    imaging = variant != OFF
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        row, start = scan(folder, domain_id, imaging=imaging, thread_priority=priority,
                          overrides={'probe_imager': imager_parameters(variant)} if imaging
                          else {})
        row.update({'imaging': imaging, 'variant': variant, 'thread_priority': priority})
        if imaging:
            typestore = typestore_with(custom_definitions())
            frames = read_frames(folder / 'bag', typestore)
            shown = (frames.stamp >= start + WINDOW[0]) & (frames.stamp < start + WINDOW[1])
            latency = (frames.received - frames.stamp)[shown]
            said = {key: reported(folder / 'bag', typestore, key).get('probe_imager',
                                                                      ['nan'])[-1]
                    for key in ('pose_to_publication_p99_s', 'frame_cpu_p50_s')}
            row.update({'frames_hz': rate(frames.stamp[shown]),
                        'pose_to_image_p50_s': float(np.percentile(latency, 50)),
                        'pose_to_image_p99_s': float(np.percentile(latency, 99)),
                        'pose_to_publication_p99_s': float(said['pose_to_publication_p99_s']),
                        'frame_cpu_p50_s': float(said['frame_cpu_p50_s'])})
    return row


def label(variant: str, priority: int) -> str:
    """Name a way of sharing the cores: the loops' scheduling and the imager's."""
    loops = f'SCHED_FIFO {priority}' if priority else 'normal scheduling'
    imager = 'SCHED_IDLE' if variant == IDLE else f'niceness +{variant}'
    return f'loops at {loops}, imager at {imager}'


def summary(rows: list, variant: str, priority: int) -> dict:
    """Return the ratios on (as ``variant``) / off of each stream figure, and the CPU imaging adds.

    The runs are those with the loops at ``priority``.

    ``rows`` come in groups, one run off and one with each variant side by side at each
    priority, which share the machine's load more than runs further apart: each ratio is taken
    within a group, and its median and range over the groups are given.
    """
    groups = sorted({row['group'] for row in rows})
    pairs = [tuple(next(r for r in rows if r['group'] == group and r['variant'] == v
                        and r['thread_priority'] == priority)
                   for v in (variant, OFF)) for group in groups]
    on, off = [pair[0] for pair in pairs], [pair[1] for pair in pairs]

    def median(runs, key):
        return float(np.median([r[key] for r in runs]))

    ratios, ranges = stream_ratios(pairs)
    added = float(np.median([total_cpu(a) - total_cpu(b) for a, b in pairs]))
    frames_hz = median(on, 'frames_hz')
    return {'pairs': len(pairs), 'ratios': ratios, 'ranges': ranges,
            'cpu_on_percent': float(np.median([total_cpu(r) for r in on])),
            'cpu_off_percent': float(np.median([total_cpu(r) for r in off])),
            'cpu_added_percent': added, 'frames_hz': frames_hz,
            'cpu_per_frame_s': added / 100.0 / frames_hz,
            'frame_cpu_p50_s': median(on, 'frame_cpu_p50_s'),
            'pose_to_image_p99_s': median(on, 'pose_to_image_p99_s'),
            'pose_to_publication_p99_s': median(on, 'pose_to_publication_p99_s'),
            'delay_s': LINK['delay'], 'targets': TARGETS}


def _print_row(row: dict) -> None:
    image = (f'  frames {row["frames_hz"]:.1f}/s, pose to image p50/p99 '
             f'{1e3 * row["pose_to_image_p50_s"]:.1f}/{1e3 * row["pose_to_image_p99_s"]:.1f} ms '
             f'(published p99 {1e3 * row["pose_to_publication_p99_s"]:.1f} ms)'
             if row['imaging'] else '')
    print(f'loops {row["thread_priority"]:>2}, imaging {row["variant"]:>4}: operator '
          f'{row["operator_rate_hz"]:.0f} Hz, {row["operator_answered_percent"]:.1f} % answered, '
          f'round trip p99 '
          f'{1e3 * row["operator_round_trip_p99_s"]:.2f} ms; robot {row["robot_rate_hz"]:.0f} '
          f'Hz, tick p99 {1e3 * row["robot_tick_p99_s"]:.2f} ms; commands '
          f'{row["commands_hz"]:.0f}/s, feedback {row["feedback_hz"]:.0f}/s; CPU '
          f'{total_cpu(row):.0f} % ('
          + ', '.join(f'{n} {c:.0f}' for n, c in row['cpu_percent'].items())
          + f'){image}; load {row["load"]:.1f}', flush=True)


def _print_summary(name: str, result: dict) -> None:
    ratios = [f'{key} {value:.3f} [{low:.3f}-{high:.3f}]' for (key, value), (low, high)
              in zip(result['ratios'].items(), result['ranges'].values())]
    print(f'{name}, on / off within each group, median [range] (targets: rates and '
          'answered >= 0.99, p99 <= 1.1): ' + ', '.join(ratios))
    print(f'  CPU: {result["cpu_on_percent"]:.0f} % of a core on, '
          f'{result["cpu_off_percent"]:.0f} % off: imaging adds {result["cpu_added_percent"]:.0f}'
          f' % at {result["frames_hz"]:.1f} frames/s, {1e3 * result["cpu_per_frame_s"]:.1f} ms a '
          f'frame (the imager\'s own thread: {1e3 * result["frame_cpu_p50_s"]:.1f} ms)')
    print(f'  pose to image p99 {1e3 * result["pose_to_image_p99_s"]:.1f} ms at the operator, '
          f'{1e3 * LINK["delay"]:.0f} ms of it the link\'s delay (target <= '
          f'{50 + 1e3 * LINK["delay"]:.0f} ms); to publication at the remote site p99 '
          f'{1e3 * result["pose_to_publication_p99_s"]:.1f} ms', flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--pairs', type=int, default=3,
                        help='groups of runs: imaging off, and on as each --imager')
    parser.add_argument('--imager', nargs='+', default=['5'], metavar='HOW',
                        help="how the imager's frame thread yields: a niceness (0-19; the "
                        "node's default, 5) or idle (SCHED_IDLE); the first is the summary's")
    parser.add_argument('--thread-priority', nargs='+', type=int, default=[50, 0], metavar='P',
                        help="the loops' real-time priority, one or more (0: normal scheduling, "
                        'the baseline); the first is the summary\'s')
    parser.add_argument('--hogs', type=int, default=0,
                        help='other processes, each keeping a core busy, for the whole run')
    ros_domain.add_option(parser)
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    ros_domain.keep_local()
    print(f'machine: {machine.line("ros-jazzy-rclpy")}')
    for variant in args.imager:
        imager_parameters(variant)  # a bad one stops here, not after the first runs
    cases = [(v, p) for p in args.thread_priority for v in (OFF, *args.imager)]

    def runs() -> list:
        rows = []
        for group in range(args.pairs):
            for variant, priority in cases[group % len(cases):] + cases[:group % len(cases)]:
                rows.append({**run(variant, priority, args.domain_id), 'group': group})
                _print_row(rows[-1])
        return rows
    rows = loaded(runs, args.hogs)
    results = {label(v, p): summary(rows, v, p) for p in args.thread_priority
               for v in args.imager}
    for name, result in results.items():
        _print_summary(name, result)
    first = label(args.imager[0], args.thread_priority[0])
    result_files.write(args.json, {'rows': rows, 'summary': results[first],
                                   'variant': args.imager[0],
                                   'thread_priority': args.thread_priority[0],
                                   'hogs': args.hogs,
                                   'variants': results})
    return 0


if __name__ == '__main__':
    sys.exit(main())
