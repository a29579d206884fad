"""The benchmarks' results the report shows: read from their stored runs, never measured here.

``make bench`` stores each benchmark that ``run_all.BENCHMARKS`` marks ``stored`` in
``bench/results/<name>.json`` (``result_files``); the report reads them all, typed where its
sections want objects. The one telerobotic figure measured by the demo itself, its scan of the
patient phantom, is read from the demo's bag here too, beside the benchmarks' rows it joins.
"""

from pathlib import Path
import shutil

from bench import result_files, teleop_scan
from bench.extreme_cases import ExtremeRow
from bench.run_all import BENCHMARKS
from bench.stiffness_sweep import SweepRow

__all__ = ['STORED', 'TELEOP_DEMO_DELAY', 'TELEOP_FIGURE', 'copy_teleop_figure', 'stored_results',
           'teleop_demo_row']

STORED = tuple(b.name for b in BENCHMARKS if b.stored)
TELEOP_DEMO_DELAY = 0.05  # [s] the demo's run (haptic_bringup.demo)
TELEOP_FIGURE = 'teleop_scan.png'  # drawn beside teleop_scan's stored results


def _typed(name: str, results):
    """Give the rows that the sections read as objects their classes back."""
    if name == 'stiffness_sweep':
        return {**results, 'rows': [SweepRow(**row) for row in results['rows']]}
    if name == 'extreme_cases':
        return [ExtremeRow(**row) for row in results]
    return results


def stored_results(folder: Path = result_files.RESULTS) -> dict:
    """Benchmark name → its last stored run (``result_files.Stored``), None if never stored."""
    found = {name: result_files.read(name, folder) for name in STORED}
    return {name: stored and result_files.Stored(stored.path, _typed(name, stored.results),
                                                 stored.measured, stored.command)
            for name, stored in found.items()}


def copy_teleop_figure(folder: Path, out: Path) -> bool:
    """Copy the stored scan's figure into the report as ``teleop_forces.png``, if there is one."""
    figure = folder / TELEOP_FIGURE
    if not figure.exists():
        return False
    shutil.copyfile(figure, out / 'teleop_forces.png')
    return True


def teleop_demo_row(demo_dir: Path) -> dict | None:
    """Return the demo's own scan (model at 50 ms) from its bag; None if it recorded none."""
    bag = demo_dir / 'teleop' / 'bag'
    return ({'scheme': 'model', 'source': 'ROS 2, demo', **teleop_scan.figures(
        teleop_scan.read_scan(bag), TELEOP_DEMO_DELAY)} if bag.exists() else None)
