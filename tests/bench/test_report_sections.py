"""The report's Markdown sections that decide what to say, on rows made by hand."""
from pathlib import Path

from bench.stiffness_sweep import SweepRow
from report_generator.report_sections import force_effect_section, identical_modes


def sweep_row(stiffness, mode, energy):
    return SweepRow(stiffness=stiffness, mode=mode, generated_energy=energy,
                    early_amplitude=1e-3, late_amplitude=1e-4, decay_ratio=0.1, max_force=2.0,
                    max_penetration=5e-3)


def test_identical_modes_counts_the_stiffnesses_where_two_modes_agree_exactly():
    rows = [sweep_row(100.0, 'off', -1.0), sweep_row(100.0, 'on', -1.0),
            sweep_row(100.0, 'hannaford-ryu', -2.0),
            sweep_row(1000.0, 'off', 0.5), sweep_row(1000.0, 'on', -0.5),
            sweep_row(1000.0, 'hannaford-ryu', -0.5)]
    assert identical_modes(rows) == (
        '`off` and `on` give exactly the same numbers at 1 of 2 stiffnesses. '
        '`on` and `hannaford-ryu` give exactly the same numbers at 1 of 2 stiffnesses.')
    assert identical_modes(rows[3:]) == (
        '`on` and `hannaford-ryu` give exactly the same numbers at 1 of 1 stiffnesses.')
    assert identical_modes([sweep_row(100.0, mode, energy) for mode, energy in (
        ('off', 1.0), ('on', 2.0), ('hannaford-ryu', 3.0))]) == ''


def test_without_the_control_run_the_force_section_says_where_it_looked():
    text = force_effect_section(None, None, Path('/nowhere/demo'))
    assert text == '*The demo\'s control run (cuboid-no-force) was not found in /nowhere/demo.*'
