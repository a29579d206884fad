"""The report's analytic probe face: its closed form against a fine sum, and a missing run."""

import math

import numpy as np
import pytest
from report_generator.report_probe import continuous_face, probe_section, ProbeFindings


def midpoint_sum(depth: float, roll: float, length: float, stiffness: float, cells=200_000):
    """Force and roll torque of the face cut in ``cells`` strips, each pushing at its middle."""
    y = (np.arange(cells) + 0.5) * length / cells - 0.5 * length
    pressed = np.maximum(depth - y * math.sin(roll), 0.0) * stiffness / cells
    return pressed.sum(), math.cos(roll) * (y * pressed).sum()


@pytest.mark.parametrize(('depth', 'roll'), [
    (0.01, 0.2),     # fully pressed
    (0.002, 0.35),   # one edge lifted
    (0.002, -0.35),  # the other edge lifted
    (0.003, 0.0),    # flush
    (-0.001, 0.0),   # above the plane
    (-0.001, 0.3),   # a corner still above
    (-0.002, 0.3),   # rolled, one edge pressed while the tip is above
])
def test_the_closed_form_is_the_integral(depth, roll):
    force, torque = continuous_face(depth, roll, 0.04, 1000.0)
    expected_force, expected_torque = midpoint_sum(depth, roll, 0.04, 1000.0)
    assert force == pytest.approx(expected_force, rel=1e-6, abs=1e-12)
    assert torque == pytest.approx(expected_torque, rel=1e-6, abs=1e-12)


def test_fully_pressed_it_is_minus_k_l2_over_12_sin_cos():
    _, torque = continuous_face(0.01, 0.2, 0.04, 1000.0)
    assert torque == pytest.approx(-1000.0 * 0.04 ** 2 / 12 * math.sin(0.2) * math.cos(0.2),
                                   rel=1e-12)


def test_without_the_runs_the_section_says_how_to_make_them():
    empty = np.zeros(0)
    text = probe_section(ProbeFindings(False, None, None, empty, empty, empty, empty))
    assert 'demo --experiments probe-flat probe-phantom' in text
