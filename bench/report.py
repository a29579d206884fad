"""The report: the paper's three experiments, reproduced over ROS 2, measured against exact truth.

    .venv/bin/python bench/report.py [--demo-dir build/demo] [--out report]
                                     [--skip probe timing tradeoff loop sweep stiffwall servo
                                             extreme teleop]
                                     [--quick]

Reads the bags ``demo`` recorded (the simulated wand tapping the hand, the cylinder and the
cuboid over ROS 2), computes the exact signed distance and outward normal along each recorded
tip trajectory (``tests/ground_truth.py``: analytic for the box and the cylinder, brute force
with a winding-number sign for the hand; it shares no code with the engine), replays the
paper's own collision code (``paper_method.py``, on the paper's STL objects) along the same
trajectories, and writes ``README.md`` with PNG figures into ``--out``: the paper's Figures
1-3 and Tables 1, 2, 4 with its reported values beside ours, error against run time for every
method, our GJK's tolerance trade-off, the loop against its floor, the stiffness sweep, the
stiff wall over the loop (local against remote rendering), the servo rate, the
extreme-geometry table, the probe's torque against the analytic face (``report_probe``), the
telerobotic scan per scheme and delay, message counts, and the
machine. Every number of ours is
computed by the run; the paper's are typed in from it (``PAPER``) and labelled as such.

``--skip`` leaves out slow stages while iterating (their sections then say so); ``--quick``
uses fewer points and shorter loop runs.

This file runs the stages in order; each concept lives in its own module beside it:
``report_experiments`` (the three experiments and the paper's values), ``report_recordings``
(the bags), ``report_truth`` (exact ground truth), ``report_paper_replay`` (the paper's code on
our paths), ``report_metrics`` (errors, false values, force directions), ``report_benchmarks``
(what is measured live), ``report_figures``, ``report_sections`` and ``report_document`` (the
Markdown), ``report_provenance`` (machine, versions, commit), ``report_format`` (numbers as
text).
"""

import argparse
import os
from pathlib import Path
import sys
import time

import bench_collision
import extreme_cases
from report_benchmarks import (colgate_bound, error_time_rows, floor_rows, stiff_wall_rows,
                               TELEOP_PLOTTED, teleop_rows, tradeoff_rows)
from report_document import Findings, readme
from report_experiments import EXPERIMENTS
from report_figures import (error_time_figure, experiment_figure, headline_figure, sweep_figure,
                            teleop_figure, tradeoff_figure)
from report_metrics import measure
from report_paper_replay import replay_paper
from report_probe import probe_figure, read_probe_runs
from report_provenance import provenance
from report_recordings import control_contacts, read_recording, typestore
from report_truth import exact_truth
import servo_rate
import stiffness_sweep

__all__ = ['SKIPPABLE', 'STAGES', 'build', 'main']

ROOT = Path(__file__).resolve().parents[1]
STAGES = ('bags', 'truth', 'paper', 'figures', 'probe', 'timing', 'tradeoff', 'loop', 'sweep',
          'stiffwall', 'servo', 'extreme', 'teleop', 'write')
SKIPPABLE = ('probe', 'timing', 'tradeoff', 'loop', 'sweep', 'stiffwall', 'servo', 'extreme',
             'teleop')
FORCE_SCALE = 0.3  # the teleop leader's default


class _Stages:
    """Prints one line as each stage starts and one as it ends, with its duration."""

    def __init__(self, skipped) -> None:
        self.skipped = set(skipped)
        self.count = 0
        self.durations = {}

    def run(self, name: str, title: str, work):
        self.count += 1
        prefix = f'[report] {self.count}/{len(STAGES)} {title}'
        if name in self.skipped:
            print(f'{prefix}: skipped', flush=True)
            return None
        print(f'{prefix} ...', flush=True)
        started = time.monotonic()
        result = work()
        self.durations[name] = time.monotonic() - started
        print(f'[report]     {title}: done in {self.durations[name]:.1f} s', flush=True)
        return result


def build(args) -> Path:
    """Run every stage and write the report; returns the README's path."""
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    stages = _Stages(args.skip)
    started = time.monotonic()
    type_store = typestore()
    recordings = stages.run('bags', 'reading the three bags', lambda: {
        name: read_recording(e, args.demo_dir, type_store) for name, e in EXPERIMENTS.items()})
    truths = stages.run('truth', 'exact ground truth along each recorded trajectory', lambda: {
        name: exact_truth(EXPERIMENTS[name], r.session.tip) for name, r in recordings.items()})
    replays = stages.run('paper', 'the paper\'s method replayed on the same trajectories',
                         lambda: {name: replay_paper(EXPERIMENTS[name], r.session.tip,
                                                     r.velocity)
                                  for name, r in recordings.items()})
    measures = {name: measure(recordings[name], truths[name], replays[name])
                for name in recordings}

    def figures():
        for name in recordings:
            experiment_figure(recordings[name], truths[name], replays[name], measures[name],
                              out / f'experiment_{name}.png')
        headline_figure(measures, out / 'headline.png')

    stages.run('figures', 'figures 1-3 and the headline figure', figures)
    probe = stages.run('probe', 'the probe runs against the analytic face',
                       lambda: read_probe_runs(args.demo_dir, type_store))
    if probe is not None and (probe.flat is not None or probe.phantom is not None):
        probe_figure(probe, out / 'probe.png')
    quick = args.quick
    timing = stages.run('timing', 'error against run time, every method', lambda: error_time_rows(
        random=100 if quick else 300, near=100 if quick else 300, tapping=0.4 if quick else 1.0,
        slow_points=60 if quick else 200))
    if timing:
        error_time_figure(timing, out / 'error_vs_time.png')
    tradeoff = stages.run('tradeoff', 'our GJK: tolerance and iteration-cap trade-off',
                          lambda: tradeoff_rows(200 if quick else 600))
    if tradeoff:
        tradeoff_figure(tradeoff, out / 'gjk_tradeoff.png')
    loop = stages.run('loop', 'the loop against its floor over ROS 2',
                      lambda: floor_rows(4.0 if quick else 8.0, 1 if quick else 2, args.domain_id))
    sweep = stages.run('sweep', 'stiffness sweep, passivity on and off', stiffness_sweep.sweep)
    bound = colgate_bound()
    if sweep:
        sweep_figure(sweep, bound, out / 'stiffness_sweep.png')
    stiff_wall = stages.run('stiffwall', 'a stiff wall over the real ROS 2 loop', lambda: (
        stiff_wall_rows(4.0 if quick else 6.0, args.domain_id)))
    servo = stages.run('servo', 'the device\'s servo rate', lambda: servo_rate.rows(
        (1e3, 4e3) if quick else (1e3, 2e3, 4e3, 1e4), (1e3, 1e4, 1e5, 2e5, 5e5, 1e6)))
    extreme = stages.run('extreme', 'extreme-geometry table',
                         lambda: extreme_cases.rows(60 if quick else 200))
    teleop = stages.run('teleop', 'the telerobotic scan, every scheme and delay',
                        lambda: teleop_rows(args.demo_dir, args.demo_dir / 'report_teleop',
                                            args.domain_id, quick))
    if teleop:
        teleop_figure(teleop['traces'], FORCE_SCALE, TELEOP_PLOTTED, out / 'teleop_forces.png')

    def write():
        findings = Findings(
            recordings, truths, replays, measures, control_contacts(args.demo_dir, type_store),
            timing, bench_collision.timer_overhead() if timing else None, tradeoff, loop, sweep,
            bound, stiff_wall, servo, extreme, probe, teleop)
        return readme(findings, provenance=provenance(), argv=args.argv, demo_dir=args.demo_dir,
                      durations=stages.durations)

    text = stages.run('write', 'writing README.md', write)
    path = out / 'README.md'
    path.write_text(text)
    print(f'[report] wrote {path} and {len(list(out.glob("*.png")))} figures in '
          f'{time.monotonic() - started:.0f} s', flush=True)
    return path


def main(argv=None) -> int:
    """Write the report; one progress line per stage."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--demo-dir', type=Path, default=ROOT / 'build' / 'demo')
    parser.add_argument('--out', type=Path, default=ROOT / 'report')
    parser.add_argument('--skip', nargs='*', default=[], choices=SKIPPABLE)
    parser.add_argument('--quick', action='store_true', help='fewer points, shorter loop runs')
    parser.add_argument('--domain-id', type=int,
                        default=int(os.environ.get('ROS_DOMAIN_ID', 42)))
    args = parser.parse_args(argv)
    args.argv = sys.argv[1:] if argv is None else argv
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    try:
        build(args)
    except FileNotFoundError as error:
        print(f'[report] {error}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
