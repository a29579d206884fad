"""The report's entry point and the benchmarks' part of it: stored results, never measured here."""
from pathlib import Path

from bench.result_files import describe, missing, write
from bench.run_all import BENCHMARKS
from bench.stiffness_sweep import SweepRow
from report_generator.report import main
from report_generator.report_benchmarks import STORED, stored_results
from report_generator.report_document import (_image_chapter, _stability_chapter, _teleop_chapter,
                                              _timing_chapter, Findings)


def findings(benchmarks: dict, results: Path, teleop=None) -> Findings:
    """Findings with only what the benchmarks' chapters read."""
    return Findings(recordings={}, truths={}, replays={}, measures={}, control_contacts=None,
                    probe=None, teleop=teleop, benchmarks=benchmarks, results=results)


def benchmark_chapters(f: Findings) -> str:
    return '\n'.join(_timing_chapter(f) + _stability_chapter(f) + _teleop_chapter(f)
                     + _image_chapter(f))


def test_a_demo_folder_without_bags_fails_and_names_the_missing_bag(tmp_path, capsys):
    demo, out = tmp_path / 'demo', tmp_path / 'report'
    demo.mkdir()
    assert main(['--demo-dir', str(demo), '--out', str(out)]) == 1
    assert f'{demo / "hand" / "bag"}: no bag' in capsys.readouterr().err
    assert not (out / 'README.md').exists()


def test_the_report_reads_every_benchmark_run_all_stores():
    assert set(STORED) == {b.name for b in BENCHMARKS if b.stored}
    assert {'loop', 'stiff_wall', 'teleop_scan'} <= set(STORED)


def test_every_stored_benchmark_has_its_section_saying_how_to_measure_it_when_missing(
        tmp_path: Path):
    text = benchmark_chapters(findings(stored_results(tmp_path), tmp_path))
    for name in STORED:
        assert text.count(missing(name, tmp_path)) == 1, name
    assert '*The demo recorded no telerobotic scan.*' in text
    assert '*The demo recorded no probe image.*' in text


def test_a_stored_result_is_shown_with_where_and_when_it_was_measured(tmp_path: Path):
    rows = [SweepRow(stiffness=100.0, mode=mode, generated_energy=-1e-3, early_amplitude=1e-3,
                     late_amplitude=1e-4, decay_ratio=0.1, max_force=2.0,
                     max_penetration=5e-3) for mode in ('off', 'on')]
    write(tmp_path / 'stiffness_sweep.json', {'colgate_bound': 4321.0, 'rows': rows},
          ['bench/stiffness_sweep.py', '--json', str(tmp_path / 'stiffness_sweep.json')])
    stored = stored_results(tmp_path)
    assert stored['stiffness_sweep'].results['rows'] == rows
    text = benchmark_chapters(findings(stored, tmp_path))
    assert describe(stored['stiffness_sweep']) in text
    assert 'Colgate passivity bound here is K = 4321 N/m' in text
    assert '| 100 | on | -1.000e-03 |' in text
    assert missing('stiffness_sweep', tmp_path) not in text
