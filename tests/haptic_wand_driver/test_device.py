"""The device contract: WandState, Workspace, DeviceLimits, the base class and the registry."""

import subprocess
import sys

from ground_truth.wand import matrix_from_quaternion, rotation_x, rotation_z
import numpy as np
import pytest

from haptic_wand_driver import device
from haptic_wand_driver.device import (
    available_devices, DeviceClosedError, DeviceLimits, DeviceUnavailableError, HapticDevice,
    make_device, register_device, WandState, Workspace)
from haptic_wand_driver.replay import ReplayDevice
from haptic_wand_driver.simulated import SimulatedWand


def make_state(**changes):
    fields = dict(time=1.5, position=[0.01, -0.02, 0.03], roll=0.2, yaw=-0.4,
                  linear_velocity=[0.1, 0.0, -0.2], roll_rate=0.5, yaw_rate=-1.0)
    fields.update(changes)
    return WandState(**fields)


def test_wand_state_orientation_is_yaw_then_roll():
    state = make_state()
    np.testing.assert_allclose(matrix_from_quaternion(state.orientation),
                               rotation_z(-0.4) @ rotation_x(0.2), atol=1e-12)


def test_wand_state_angular_velocity_is_world_frame():
    state = make_state()
    roll_axis = rotation_z(-0.4) @ [1.0, 0.0, 0.0]
    np.testing.assert_allclose(state.angular_velocity, 0.5 * roll_axis + [0.0, 0.0, -1.0])


def test_wand_state_coordinates_round_trip_and_are_read_only():
    state = make_state()
    np.testing.assert_array_equal(state.coordinates, [0.01, -0.02, 0.03, 0.2, -0.4])
    np.testing.assert_array_equal(state.rates, [0.1, 0.0, -0.2, 0.5, -1.0])
    again = WandState.from_coordinates(state.time, state.coordinates, state.rates)
    np.testing.assert_array_equal(again.coordinates, state.coordinates)
    with pytest.raises(ValueError):
        state.position[0] = 1.0


@pytest.mark.parametrize('field, value', [
    ('position', [0.0, 0.0]), ('linear_velocity', [0.0, np.nan, 0.0]), ('yaw', np.inf),
    ('time', np.nan)])
def test_wand_state_rejects_bad_fields_by_name(field, value):
    with pytest.raises(ValueError, match=f'WandState.{field}'):
        make_state(**{field: value})


def test_workspace_contains_and_bounds():
    workspace = Workspace(lower=[-0.1, -0.1, -0.2], upper=[0.1, 0.1, 0.0], roll_limit=0.5,
                          yaw_limit=0.4)
    lower, upper = workspace.coordinate_bounds
    np.testing.assert_array_equal(lower, [-0.1, -0.1, -0.2, -0.5, -0.4])
    np.testing.assert_array_equal(upper, [0.1, 0.1, 0.0, 0.5, 0.4])
    assert workspace.contains(np.array([0.0, 0.0, -0.1, 0.5, -0.4]))
    assert not workspace.contains(np.array([0.0, 0.0, 0.01, 0.0, 0.0]))
    assert not workspace.contains(np.array([0.0, 0.0, -0.1, 0.0, 0.41]))


def test_default_workspace_yaw_is_thirty_degrees():
    assert Workspace().yaw_limit == pytest.approx(np.radians(30.0))


@pytest.mark.parametrize('kwargs, name', [
    (dict(lower=[0.0, 0.0, 0.0], upper=[-1.0, 1.0, 1.0]), 'Workspace.lower'),
    (dict(upper=[1.0, 1.0]), 'Workspace.upper'),
    (dict(yaw_limit=-0.1), 'Workspace.yaw_limit'),
    (dict(roll_limit=4.0), 'Workspace.roll_limit'),
])
def test_workspace_rejects_bad_fields_by_name(kwargs, name):
    with pytest.raises(ValueError, match=name):
        Workspace(**kwargs)


def test_device_limits_reject_negative():
    with pytest.raises(ValueError, match='DeviceLimits.torque_limit'):
        DeviceLimits(force_limit=1.0, torque_limit=-1.0)


def test_make_device_for_missing_hardware_says_what_is_available():
    with pytest.raises(DeviceUnavailableError) as raised:
        make_device('quanser')
    message = str(raised.value)
    assert "'quanser'" in message and 'simulated' in message and 'replay' in message
    assert 'register_device' in message
    assert isinstance(raised.value, ValueError)


def test_make_device_builds_shipped_backends(tmp_path):
    assert isinstance(make_device('simulated'), SimulatedWand)
    recording = tmp_path / 'track.csv'
    recording.write_text('t,x,y,z\n0,0,0,0\n1,0.1,0,0\n')
    replay = make_device('replay', path=recording, loop=True)
    assert isinstance(replay, ReplayDevice)
    assert set(available_devices()) >= {'simulated', 'replay'}


class _Stationary(HapticDevice):
    """A minimal backend for the contract tests: always at the origin."""

    limits = DeviceLimits(force_limit=1.0, torque_limit=0.1)

    def read(self, now):
        self._raise_if_closed()
        return WandState(now, np.zeros(3), 0.0, 0.0, np.zeros(3), 0.0, 0.0)

    def apply(self, force, torque):
        self._raise_if_closed()

    def applied(self):
        return np.zeros(3), np.zeros(3)


def test_registered_backend_is_built_with_its_options(monkeypatch):
    monkeypatch.setattr(device, '_registered', {})
    built = []

    def factory(**options):
        built.append(options)
        return _Stationary()
    register_device('bench_wand', factory)
    assert 'bench_wand' in available_devices()
    assert isinstance(make_device('bench_wand', port=3), _Stationary)
    assert built == [{'port': 3}]
    with pytest.raises(ValueError, match='already registered'):
        register_device('simulated', factory)


def test_abstract_device_cannot_be_built():
    with pytest.raises(TypeError):
        HapticDevice()


def test_closed_device_refuses_use_and_closes_twice():
    with _Stationary() as wand:
        assert wand.read(0.5).time == 0.5
    assert wand.closed
    wand.close()
    with pytest.raises(DeviceClosedError):
        wand.read(1.0)
    with pytest.raises(DeviceClosedError):
        wand.apply(np.zeros(3), np.zeros(3))


def test_core_imports_no_ros_and_loads_file_readers_only_when_used():
    code = ('import sys, haptic_wand_driver; '
            'print(sorted(m for m in ("rclpy", "rosbags", "yaml", "geometry_msgs") '
            'if m in sys.modules))')
    result = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == '[]'


def test_package_exports_the_public_api():
    import haptic_wand_driver

    assert haptic_wand_driver.__file__ is not None, (
        'haptic_wand_driver resolved to a namespace package: a directory named like it (e.g. '
        'tests/haptic_wand_driver) is on sys.path before the editable install is consulted')
    for name in haptic_wand_driver.__all__:
        assert hasattr(haptic_wand_driver, name), name


@pytest.mark.parametrize('coordinates, rates, name', [
    ([0.0, 0.0, np.nan, 0.0, 0.0], np.zeros(5), 'WandState coordinates'),
    (np.zeros(5), np.zeros(4), 'WandState rates'),
    (np.zeros(6), np.zeros(5), 'WandState coordinates')])
def test_wand_state_from_coordinates_refuses_naming_the_argument(coordinates, rates, name):
    with pytest.raises(ValueError, match=name):
        WandState.from_coordinates(0.0, coordinates, rates)
