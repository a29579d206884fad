"""OperatorHand: a spring-damper on the joints toward the script's target."""

import numpy as np
import pytest

from simulated_operator.hand import OperatorHand
from simulated_operator.scripts import Target, WaypointScript

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


def test_gains_are_read_only_arrays():
    operator = hand(stiffness=40.0, rotational_stiffness=0.5, damping=2.0,
                    rotational_damping=0.01)
    np.testing.assert_array_equal(operator.stiffness, [40.0, 40.0, 40.0, 0.5, 0.5])
    np.testing.assert_array_equal(operator.damping, [2.0, 2.0, 2.0, 0.01, 0.01])
    with pytest.raises(ValueError):
        operator.stiffness[0] = 1.0


def test_target_components_are_the_script_target_as_floats():
    operator = hand()
    for t in (-1.0, 0.25, 0.5, 0.9, 2.0):
        coordinates, rates = operator.target_components(t)
        target = operator.script.target(t)
        np.testing.assert_array_equal(coordinates, target.coordinates)
        np.testing.assert_array_equal(rates, target.rates)


class _Broken:
    """A script that offers only ``target`` and answers with an infinite rate."""

    duration = 1.0

    def target(self, t):
        return Target(np.zeros(5), np.array([0.0, np.inf, 0.0, 0.0, 0.0]))


def test_a_script_with_only_target_is_checked_naming_it():
    with pytest.raises(ValueError, match=r'_Broken\.target\(0\.5\)\.rates must be 5 finite'):
        OperatorHand(_Broken()).target_components(0.5)
