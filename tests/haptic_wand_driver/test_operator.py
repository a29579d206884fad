"""OperatorHand: a spring-damper on the joints toward the script's target."""

import numpy as np
import pytest

from haptic_wand_driver.operator import OperatorHand
from haptic_wand_driver.scripts import WaypointScript

LEG = np.array([0.04, -0.02, 0.0, 0.1, -0.2])


def hand(**gains):
    script = WaypointScript.from_rows([(0.0, 0.0, 0.0, 0.0, 0.0, 0.0), (1.0, *LEG)])
    return OperatorHand(script, **gains)


def test_effort_is_stiffness_times_error_at_rest():
    operator = hand(stiffness=40.0, damping=2.0, rotational_stiffness=0.5,
                    rotational_damping=0.01)
    coordinates = np.array([0.05, -0.02, 0.01, 0.0, 0.0])
    rates = np.array([0.1, 0.0, 0.0, 1.0, 0.0])
    expected = np.array([40.0 * (0.04 - 0.05) - 2.0 * 0.1, 0.0, 40.0 * -0.01,
                         0.5 * 0.1 - 0.01 * 1.0, 0.5 * -0.2])
    np.testing.assert_allclose(operator.effort(5.0, coordinates, rates), expected, atol=1e-15)


def test_no_effort_when_the_tip_follows_a_moving_target():
    # Mid-leg, a minimum-jerk move is half-way at 15/8 of the mean speed.
    effort = hand().effort(0.5, 0.5 * LEG, 1.875 * LEG)
    np.testing.assert_allclose(effort, np.zeros(5), atol=1e-12)


@pytest.mark.parametrize('name', ['stiffness', 'damping', 'rotational_stiffness',
                                  'rotational_damping'])
def test_rejects_negative_gains_by_name(name):
    with pytest.raises(ValueError, match=name):
        hand(**{name: -1.0})
