"""The report's entry point: its command line, and a demo folder without bags."""
import pytest
from report import main, SKIPPABLE, STAGES


def test_every_skippable_stage_is_a_stage():
    assert set(SKIPPABLE) <= set(STAGES)


def test_a_demo_folder_without_bags_fails_and_names_the_missing_bag(tmp_path, capsys):
    demo, out = tmp_path / 'demo', tmp_path / 'report'
    demo.mkdir()
    assert main(['--demo-dir', str(demo), '--out', str(out)]) == 1
    assert f'{demo / "hand" / "bag"}: no bag' in capsys.readouterr().err
    assert not (out / 'README.md').exists()


def test_an_unknown_stage_cannot_be_skipped():
    with pytest.raises(SystemExit):
        main(['--skip', 'bags'])
