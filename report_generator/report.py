"""The report: the paper's three experiments, reproduced over ROS 2, measured against exact truth.

    .venv/bin/python report_generator/report.py [--demo-dir build/demo] [--results bench/results]
                                                [--out report]

Reads the bags ``demo`` recorded (the simulated wand tapping the hand, the cylinder and the
cuboid over ROS 2, the probe, the telerobotic scan), computes the exact signed distance and
outward normal along each recorded tip trajectory (``ground_truth/distances.py``: analytic for the
box and the cylinder, brute force with a winding-number sign for the hand; it shares no code
with the engine), replays the paper's own collision code (``paper_method.py``, on the paper's
STL objects) along the same trajectories, and writes ``README.md`` with PNG figures into
``--out``: the paper's Figures 1-3 and Tables 1, 2, 4 with its reported values beside ours,
the probe's torque against the analytic face (``report_probe``), the demo's telerobotic scan and
its probe images (``report_image``), message counts, and the machine. Every number of ours
there is computed by this run; the paper's are typed in from it (``PAPER``) and labelled as
such.

The benchmarks' sections (error against run time, our GJK's trade-off, the loop against its
floor, the stiffness sweep, the stiff wall over the loop, the servo rate, the extreme-geometry
table, the telerobotic scan per scheme and delay) are not measured here: they come from the
benchmarks' last stored runs in ``--results`` (``make bench`` writes them), and each says when,
on which machine and commit, and by what command it was measured.

This file runs the stages in order; each concept lives in its own module beside it:
``report_experiments`` (the three experiments and the paper's values), ``report_recordings``
(the bags), ``report_truth`` (exact ground truth), ``report_paper_replay`` (the paper's code on
our paths), ``report_metrics`` (errors, false values, force directions), ``report_benchmarks``
(the stored benchmark results), ``report_figures``, ``report_sections`` and ``report_document``
(the Markdown), ``report_provenance`` (machine, versions, commit), ``report_format`` (numbers as
text).
"""

import argparse
from pathlib import Path
import sys
import time

from bench import result_files
from report_generator.report_benchmarks import copy_teleop_figure, stored_results, teleop_demo_row
from report_generator.report_document import Findings, readme
from report_generator.report_experiments import EXPERIMENTS
from report_generator.report_figures import (error_time_figure, experiment_figure, headline_figure,
                                             sweep_figure, tradeoff_figure)
from report_generator.report_image import image_figures, read_image_scan
from report_generator.report_metrics import measure
from report_generator.report_paper_replay import replay_paper
from report_generator.report_probe import probe_figure, read_probe_runs
from report_generator.report_provenance import provenance
from report_generator.report_recordings import control_contacts, read_recording, typestore
from report_generator.report_truth import exact_truth

__all__ = ['STAGES', 'build', 'main']

ROOT = Path(__file__).resolve().parents[1]
STAGES = ('bags', 'truth', 'paper', 'figures', 'probe', 'teleop', 'image', 'stored', 'write')


class _Stages:
    """Prints one line as each stage starts and one as it ends, with its duration."""

    def __init__(self) -> None:
        self.count = 0
        self.durations = {}

    def run(self, name: str, title: str, work):
        self.count += 1
        print(f'[report] {self.count}/{len(STAGES)} {title} ...', flush=True)
        started = time.monotonic()
        result = work()
        self.durations[name] = time.monotonic() - started
        print(f'[report]     {title}: done in {self.durations[name]:.1f} s', flush=True)
        return result


def _stored_figures(stored: dict, results: Path, out: Path) -> None:
    """Draw the stored benchmarks' figures from their rows; copy the scan's, drawn when run."""
    if stored['error_time']:
        error_time_figure(stored['error_time'].results['rows'], out / 'error_vs_time.png')
    if stored['gjk_tradeoff']:
        tradeoff_figure(stored['gjk_tradeoff'].results, out / 'gjk_tradeoff.png')
    if stored['stiffness_sweep']:
        sweep = stored['stiffness_sweep'].results
        sweep_figure(sweep['rows'], sweep['colgate_bound'], out / 'stiffness_sweep.png')
    if stored['teleop_scan']:
        copy_teleop_figure(results, out)


def build(args) -> Path:
    """Run every stage and write the report; returns the README's path."""
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    stages = _Stages()
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
    if probe.flat is not None or probe.phantom is not None:
        probe_figure(probe, out / 'probe.png')
    teleop = stages.run('teleop', 'the demo\'s telerobotic scan',
                        lambda: teleop_demo_row(args.demo_dir))

    def image():
        scan = read_image_scan(args.demo_dir, type_store)
        if scan is not None:
            image_figures(scan, out)
        return scan

    image_scan = stages.run('image', 'the probe\'s image along the scan', image)

    def stored():
        found = stored_results(args.results)
        _stored_figures(found, args.results, out)
        return found

    benchmarks = stages.run('stored', 'the benchmarks\' last stored results', stored)

    def write():
        findings = Findings(
            recordings, truths, replays, measures, control_contacts(args.demo_dir, type_store),
            probe, teleop, benchmarks, args.results, image_scan)
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
    parser.add_argument('--results', type=Path, default=result_files.RESULTS,
                        help='the benchmarks\' stored results (make bench writes them)')
    parser.add_argument('--out', type=Path, default=ROOT / 'report')
    args = parser.parse_args(argv)
    args.argv = sys.argv[1:] if argv is None else argv
    try:
        build(args)
    except FileNotFoundError as error:
        print(f'[report] {error}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
