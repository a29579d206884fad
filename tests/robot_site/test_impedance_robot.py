"""The simulated impedance robot against closed forms of a mass-spring-damper."""
import math

import numpy as np
import pytest

from robot_site.impedance_robot import ImpedanceRobot, ImpedanceRobotConfig

FINE = dict(step=1e-4)  # fine enough that semi-implicit Euler sits within 0.1 % of the ODE


def critically_damped_step(time, amplitude, omega):
    """Position of a critically damped mass-spring released at rest, `amplitude` off target."""
    return amplitude * (1.0 - (1.0 + omega * time) * np.exp(-omega * time))


def test_step_response_is_that_of_a_critically_damped_mass_spring():
    config = ImpedanceRobotConfig(mass=2.0, stiffness=1500.0, max_speed=10.0, **FINE)
    robot = ImpedanceRobot(config)
    robot.read(0.0)
    robot.command([0.0, 0.0, 0.01])
    times = np.arange(1, 301) * 1e-3
    heights = np.array([robot.read(t).position[2] for t in times])
    expected = critically_damped_step(times, 0.01, math.sqrt(1500.0 / 2.0))
    assert np.max(np.abs(heights - expected)) < 1e-5  # 0.1 % of the 10 mm step
    assert np.all(np.diff(heights) >= 0.0)  # critical damping: no overshoot


def test_a_constant_external_force_shifts_the_rest_point_by_force_over_stiffness():
    config = ImpedanceRobotConfig(stiffness=1000.0)
    robot = ImpedanceRobot(config, environment=lambda position, velocity: np.array([0, 0, 5.0]))
    robot.read(0.0)
    state = robot.read(2.0)
    np.testing.assert_allclose(state.position, [0.0, 0.0, 5.0 / 1000.0], atol=1e-9)
    np.testing.assert_array_equal(state.external_force, [0.0, 0.0, 5.0])


def test_the_external_force_is_that_at_the_reported_position_and_velocity():
    def spring(position, velocity):
        return -400.0 * position - 3.0 * velocity

    robot = ImpedanceRobot(environment=spring)
    robot.read(0.0)
    robot.command([0.0, 0.01, 0.02])
    state = robot.read(0.0503)
    np.testing.assert_array_equal(state.external_force, spring(state.position, state.velocity))


def test_a_far_target_is_approached_at_the_speed_limit():
    robot = ImpedanceRobot(ImpedanceRobotConfig(max_speed=0.1))
    robot.read(0.0)
    robot.command([0.3, 0.0, 0.0])
    speeds = [np.linalg.norm(robot.read(t).velocity) for t in np.arange(1, 2001) * 1e-3]
    assert max(speeds) == pytest.approx(0.1, rel=1e-12)
    # Cruising at 0.1 m/s from about 0.2 s, the TCP covers 0.3 m in a little over 3 s.
    assert robot.read(2.0).position[0] == pytest.approx(0.2, abs=0.01)


def test_the_workspace_walls_stop_the_tcp_and_its_outward_speed():
    config = ImpedanceRobotConfig(workspace_lower=[-0.1, -0.1, -0.05],
                                  workspace_upper=[0.1, 0.1, 0.1])
    robot = ImpedanceRobot(config)
    robot.read(0.0)
    robot.command([0.0, 0.0, -0.5])
    state = robot.read(1.0)
    assert state.position[2] == -0.05
    assert state.velocity[2] == 0.0


def test_states_do_not_depend_on_when_read_is_called():
    def run(read_times):
        robot = ImpedanceRobot(environment=lambda p, v: -300.0 * p - 2.0 * v)
        robot.read(0.0)
        robot.command([0.02, -0.01, 0.03])
        for now in read_times:
            state = robot.read(now)
        return state

    regular = run(np.arange(1, 1001) * 1e-3)
    jittery = run(np.sort(np.r_[np.random.default_rng(3).uniform(0, 1, 300), 1.0]))
    np.testing.assert_array_equal(regular.position, jittery.position)
    np.testing.assert_array_equal(regular.velocity, jittery.velocity)
    assert regular.time == jittery.time == pytest.approx(1.0)


def test_advance_moves_the_robot_as_read_does():
    def run(catch_up):
        robot = ImpedanceRobot(environment=lambda p, v: -300.0 * p - 2.0 * v)
        robot.read(0.0)
        for now in np.arange(1, 301) * 1e-3:
            catch_up(robot, now)
            robot.command([0.02 * math.sin(now * 20.0), -0.01, 0.03])
        return robot.read(0.3005)

    advanced = run(ImpedanceRobot.advance)
    read = run(ImpedanceRobot.read)
    for name in ('time', 'position', 'velocity', 'external_force'):
        np.testing.assert_array_equal(getattr(advanced, name), getattr(read, name))
    robot = ImpedanceRobot()
    robot.advance(1.0)
    with pytest.raises(ValueError, match='must not go back'):
        robot.advance(0.5)


def test_orientation_is_held_and_the_pose_api_checks_the_quaternion():
    robot = ImpedanceRobot(ImpedanceRobotConfig(initial_orientation=[0, 0, 2.0, 0]))
    robot.command([0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0])
    np.testing.assert_array_equal(robot.read(0.5).orientation, [0.0, 0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match='orientation must not be zero'):
        robot.command([0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0])


@pytest.mark.parametrize('fields, message', [
    (dict(mass=0.0), 'mass must be finite > 0'),
    (dict(stiffness=-1.0), 'stiffness must be finite > 0'),
    (dict(damping=math.nan), 'damping must be finite >= 0'),
    (dict(step=math.inf), 'step must be finite > 0'),
    (dict(workspace_lower=[0.0, 0.0, 0.5]), 'must lie below workspace_upper'),
    (dict(initial_position=[0.0, 0.0, 1.0]), 'outside the workspace'),
    (dict(initial_position=[0.0, math.nan, 0.0]), 'initial_position must be 3 finite numbers'),
])
def test_bad_configurations_are_refused(fields, message):
    with pytest.raises(ValueError, match=message):
        ImpedanceRobotConfig(**fields)


def test_unknown_configuration_fields_are_refused():
    with pytest.raises(TypeError, match='stifness'):
        ImpedanceRobotConfig(stifness=1.0)


def test_bad_commands_and_clocks_are_refused():
    robot = ImpedanceRobot()
    with pytest.raises(ValueError, match='position must be 3 finite numbers'):
        robot.command([0.0, math.nan, 0.0])
    robot.read(1.0)
    with pytest.raises(ValueError, match='must not go back'):
        robot.read(0.5)
    with pytest.raises(ValueError, match='environment force must be 3 finite numbers'):
        ImpedanceRobot(environment=lambda p, v: np.full(3, math.nan))
