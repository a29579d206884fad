"""The scan's smoothness and force-rise figures on series whose answer is known by construction."""
import math

from bench import teleop_scan
import numpy as np
import pytest

from haptic_bringup.bag import BagWriter, typestore_with
from haptic_bringup.recorder import custom_definitions

GRID = teleop_scan.GRID


def press(seconds: float = 4.0, rise: float = 10.0, level: float = 8.0) -> np.ndarray:
    """A patient force along z: zero for 1 s, rising at ``rise`` N/s to ``level``, then held."""
    t = np.arange(0.0, seconds, GRID)
    return np.stack([0 * t, 0 * t, np.clip(rise * (t - 1.0), 0.0, level)], axis=1)


def test_a_felt_force_that_follows_the_patients_is_smooth():
    patient = press()
    figures = teleop_scan.felt_steps(patient.copy(), patient)
    assert figures['step_ratio_max'] == pytest.approx(1.0)
    assert figures['jumps'] == 0 and figures['smooth']


def test_one_step_in_the_felt_force_is_a_jolt_the_measure_names():
    patient = press()
    felt = patient.copy()
    felt[3000:, 2] += 1.5  # a model update at once, in steady contact
    figures = teleop_scan.felt_steps(felt, patient)
    assert figures['jumps'] == 1
    assert figures['felt_step_max_n'] == pytest.approx(1.5)
    assert figures['step_ratio_max'] > 100.0 and not figures['smooth']


def test_steps_out_of_steady_contact_do_not_count():
    patient = press(level=2.5)  # never above 3 N
    felt = patient.copy()
    felt[3000:, 2] += 1.5
    assert teleop_scan.felt_steps(felt, patient)['jumps'] == 0


def test_the_force_rise_is_read_from_the_patients_force():
    figures = teleop_scan.force_rise(press(rise=10.0, level=8.0), 8.0)
    assert figures['peak_rise_n_per_s'] == pytest.approx(10.0)
    # From 1 N (contact) to 7.2 N (90 % of 8 N) at 10 N/s.
    assert figures['time_to_force_s'] == pytest.approx(0.62, abs=2 * GRID)


def write_requests(folder, requests) -> None:
    """The remote site's bag with ``requests``: (receive time s, force N) on its hold topic."""
    typestore = typestore_with(custom_definitions())
    writer = BagWriter(folder / 'remote', typestore)
    writer.add_topic(teleop_scan.REMOTE_HOLD, 'std_msgs/msg/Float64')
    for at, force in requests:
        data = typestore.serialize_cdr(typestore.types['std_msgs/msg/Float64'](data=force),
                                       'std_msgs/msg/Float64')
        writer.write(teleop_scan.REMOTE_HOLD, round(at * 1e9), data)
    writer.close()


def test_a_hold_s_window_runs_from_its_arrival_at_the_remote_site_to_its_release_s(tmp_path):
    write_requests(tmp_path, [(100.0, 0.0), (105.5, 8.0), (105.6, 8.0), (116.25, 0.0)])
    assert teleop_scan.held_window(tmp_path) == pytest.approx((105.5, 116.25))
    write_requests(tmp_path / 'never released', [(105.5, 8.0)])
    assert teleop_scan.held_window(tmp_path / 'never released') == (pytest.approx(105.5), math.inf)
    write_requests(tmp_path / 'none', [(100.0, 0.0)])
    with pytest.raises(RuntimeError, match='no hold reached the remote site'):
        teleop_scan.held_window(tmp_path / 'none')
