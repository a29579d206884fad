"""The report's probe section without its runs (its analytic face: tests/test_ground_truth.py)."""

import numpy as np
from report_generator.report_probe import probe_section, ProbeFindings


def test_without_the_runs_the_section_says_how_to_make_them():
    empty = np.zeros(0)
    text = probe_section(ProbeFindings(False, None, None, empty, empty, empty, empty))
    assert 'demo --experiments probe-flat probe-phantom' in text
