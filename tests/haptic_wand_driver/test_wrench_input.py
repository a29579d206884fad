"""WrenchCommand: staleness, NaN, order, saturation and the actuated-DOF projection."""

import math

from fuzzing import examples
from ground_truth.wand import rotation_z
from hypothesis import example, given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from haptic_contract.plane_law import saturate, saturate_components
from haptic_wand_driver.wrench_input import WrenchCommand

components = st.floats(-50.0, 50.0)
vectors = st.tuples(components, components, components).map(np.array)


def command(**changes):
    options = dict(force_limit=5.0, torque_limit=0.5, timeout=0.010)
    options.update(changes)
    return WrenchCommand(**options)


def test_zero_until_a_wrench_arrives():
    wrench = command()
    force, torque = wrench.current(now=1.0, yaw=0.0)
    np.testing.assert_array_equal(force, np.zeros(3))
    np.testing.assert_array_equal(torque, np.zeros(3))
    assert not wrench.is_fresh(1.0)


def test_fresh_wrench_is_applied_then_goes_stale():
    wrench = command()
    assert wrench.update([1.0, -2.0, 0.5], [0.0, 0.0, 0.1], stamp=2.000, now=2.001) is None
    np.testing.assert_array_equal(wrench.current(2.010, 0.0)[0], [1.0, -2.0, 0.5])
    np.testing.assert_array_equal(wrench.current(2.010, 0.0)[1], [0.0, 0.0, 0.1])
    np.testing.assert_array_equal(wrench.current(2.0101, 0.0)[0], np.zeros(3))
    np.testing.assert_array_equal(wrench.current(2.0101, 0.0)[1], np.zeros(3))


@pytest.mark.parametrize('force, torque', [([np.nan, 0.0, 0.0], [0.0, 0.0, 0.0]),
                                           ([1.0, 0.0, 0.0], [0.0, np.inf, 0.0]),
                                           ([1.0, 0.0], [0.0, 0.0, 0.0])])
def test_bad_wrench_is_ignored_with_a_reason_and_zeroes_the_force(force, torque):
    wrench = command()
    wrench.update([1.0, 0.0, 0.0], [0.0, 0.0, 0.0], stamp=1.0, now=1.0)
    reason = wrench.update(force, torque, stamp=1.001, now=1.001)
    assert 'ignored' in reason and 'finite' in reason
    np.testing.assert_array_equal(wrench.current(1.002, 0.0)[0], np.zeros(3))


def test_recovers_on_fresh_data_after_nan_and_after_staleness():
    wrench = command()
    wrench.update([np.nan] * 3, [0.0] * 3, stamp=1.0, now=1.0)
    assert wrench.update([0.0, 1.0, 0.0], [0.0] * 3, stamp=1.001, now=1.001) is None
    np.testing.assert_array_equal(wrench.current(1.002, 0.0)[0], [0.0, 1.0, 0.0])
    assert not wrench.is_fresh(2.0)
    assert wrench.update([0.0, 0.0, 2.0], [0.0] * 3, stamp=2.0, now=2.0) is None
    np.testing.assert_array_equal(wrench.current(2.001, 0.0)[0], [0.0, 0.0, 2.0])


def test_out_of_order_wrench_keeps_the_newer_one():
    wrench = command()
    wrench.update([1.0, 0.0, 0.0], [0.0] * 3, stamp=1.002, now=1.002)
    reason = wrench.update([9.0, 0.0, 0.0], [0.0] * 3, stamp=1.001, now=1.003)
    assert 'older' in reason
    np.testing.assert_array_equal(wrench.current(1.003, 0.0)[0], [1.0, 0.0, 0.0])


def test_wrench_from_the_future_is_ignored():
    wrench = command()
    assert 'ahead' in wrench.update([1.0, 0.0, 0.0], [0.0] * 3, stamp=5.0, now=1.0)
    np.testing.assert_array_equal(wrench.current(1.0, 0.0)[0], np.zeros(3))


# Limits are 0 (no force) or a force a device can render; a subnormal limit such as 5e-324 N
# cannot carry a direction at all (vector * limit / norm underflows to zero).
@settings(max_examples=examples(60), deadline=None)
@given(vectors, st.one_of(st.just(0.0), st.floats(1e-12, 20.0)))
@example(np.array([0.0, 0.0, 1.4487731358402805e-214]), 0.0)  # its square underflows to 0
def test_saturate_keeps_direction_and_bounds_the_norm(vector, limit):
    result = saturate(vector, limit)
    norm = np.linalg.norm(vector)
    assert np.linalg.norm(result) <= limit * (1 + 1e-12) + 1e-15
    if norm <= limit:
        np.testing.assert_array_equal(result, vector)
    else:
        assert np.linalg.norm(result) == pytest.approx(limit)
        if limit > 0.0:
            np.testing.assert_allclose(result / limit, vector / norm, atol=1e-12)


def test_force_saturates_to_the_limit_keeping_direction():
    wrench = command(force_limit=5.0)
    wrench.update([30.0, 40.0, 0.0], [0.0] * 3, stamp=0.0, now=0.0)
    np.testing.assert_allclose(wrench.current(0.0, 0.0)[0], [3.0, 4.0, 0.0])


@settings(max_examples=examples(60), deadline=None)
@given(st.floats(-0.5, 0.5), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_pitch_torque_is_dropped_and_roll_and_yaw_kept(yaw, about_roll, about_pitch, about_z):
    roll_axis = rotation_z(yaw) @ [1.0, 0.0, 0.0]
    pitch_axis = rotation_z(yaw) @ [0.0, 1.0, 0.0]
    torque = about_roll * roll_axis + about_pitch * pitch_axis + about_z * np.array([0, 0, 1.0])
    wrench = command(torque_limit=10.0)
    wrench.update([0.0] * 3, torque, stamp=0.0, now=0.0)
    expected = about_roll * roll_axis + np.array([0.0, 0.0, about_z])
    np.testing.assert_allclose(wrench.current(0.0, yaw)[1], expected, atol=1e-12)


def test_torque_saturates_after_projection():
    wrench = command(torque_limit=0.5)
    wrench.update([0.0] * 3, [3.0, 100.0, 4.0], stamp=0.0, now=0.0)
    np.testing.assert_allclose(wrench.current(0.0, 0.0)[1], [0.3, 0.0, 0.4])


@pytest.mark.parametrize('name', ['force_limit', 'torque_limit', 'timeout'])
def test_rejects_bad_settings_by_name(name):
    with pytest.raises(ValueError, match=name):
        command(**{name: -1.0})


# Limits are 0 (no force) or a force a device can render; a subnormal limit such as 5e-324 N
# cannot carry a direction at all (vector * limit / norm underflows to zero).
@settings(max_examples=examples(60), deadline=None)
@given(vectors, st.one_of(st.just(0.0), st.floats(1e-12, 20.0)))
def test_saturate_components_is_saturate_on_floats(vector, limit):
    components = saturate_components(tuple(vector.tolist()), limit)
    assert all(type(c) is float for c in components)
    np.testing.assert_array_equal(components, saturate(vector, limit))


def test_expiry_is_the_stamp_plus_the_timeout_and_minus_infinity_when_nothing_is_held():
    command = WrenchCommand(force_limit=10.0, torque_limit=1.0, timeout=0.010)
    assert command.expiry == -math.inf
    assert command.update([1.0, 0.0, 0.0], [0.0, 0.0, 0.0], stamp=2.0, now=2.001) is None
    assert command.expiry == pytest.approx(2.010)
    command.clear()
    assert command.expiry == -math.inf
