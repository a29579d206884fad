"""The committed ``report/README.md``: its images, and the stored benchmark results it shows.

The report's PNGs are committed so that the report shows its figures on the repository page;
a figure left untracked (or ignored) would be a broken picture there. Its benchmarks' sections
come from the results ``make bench`` stored in ``bench/results/``: those are committed too, and
each section must cite the very file it was built from (a result measured again without the
report rebuilt, or the other way round, fails here).
"""
from pathlib import Path
import re
import subprocess

from bench.result_files import describe, read, RESULTS
import pytest
from report_generator.report_benchmarks import STORED, TELEOP_FIGURE

ROOT = Path(__file__).resolve().parents[2]
REPORT = ROOT / 'report'
IMAGE_LINK = re.compile(r'!\[[^\]]*\]\(([^)\s]+)\)')
LARGEST_IMAGE = 150_000  # [bytes] figures are saved as palette PNGs well under this


def linked_images() -> list[str]:
    return IMAGE_LINK.findall((REPORT / 'README.md').read_text())


def tracked_files(folder: str = 'report') -> set[str]:
    try:
        done = subprocess.run(['git', 'ls-files', '--', folder], cwd=ROOT, capture_output=True,
                              text=True, timeout=30)
    except OSError as error:
        pytest.skip(f'no git here: {error}')
    if done.returncode != 0:
        pytest.skip(f'not a git checkout: {done.stderr.strip()}')
    return set(done.stdout.split())


def test_the_committed_report_is_a_full_run_with_all_eleven_figures():
    # The loop's rate-sweep figure gave way to the table against the floor (the CPU issue); the
    # probe's sweep, the telerobotic scan's forces and the probe's image (frames along the scan,
    # and as it presses in) came with their chapters.
    assert len(set(linked_images())) == 11


def test_every_linked_image_is_in_report_and_tracked_by_git():
    tracked = tracked_files()
    for link in linked_images():
        path = (REPORT / link).resolve()
        assert path.parent == REPORT, f'{link}: not a file in report/'
        assert path.is_file(), f'{link}: linked, but not in report/'
        assert f'report/{path.name}' in tracked, f'{link}: in report/, but not tracked by git'


def test_the_committed_figures_are_small():
    for link in linked_images():
        size = (REPORT / link).stat().st_size
        assert size < LARGEST_IMAGE, f'{link}: {size} bytes'


def test_each_benchmark_section_cites_the_committed_result_it_was_built_from():
    text = (REPORT / 'README.md').read_text()
    tracked = tracked_files('bench/results')
    for name in STORED:
        stored = read(name)
        assert stored is not None, f'{name}: no stored result (make bench ARGS=\'--only {name}\')'
        assert f'bench/results/{name}.json' in tracked, f'{name}: stored, but not tracked by git'
        assert describe(stored) in text, f'{name}: the report is not built from it (make report)'


def test_the_telerobotic_figure_is_the_stored_scans():
    stored = RESULTS / TELEOP_FIGURE
    assert f'bench/results/{TELEOP_FIGURE}' in tracked_files('bench/results')
    assert (REPORT / 'teleop_forces.png').read_bytes() == stored.read_bytes()
