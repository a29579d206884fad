"""Safety at the patient: the force bound in closed loop, the link watchdog's hold and retreat."""
import math

import numpy as np
import pytest

from robot_site.ft_sensor import ForceTorqueSensor
from robot_site.impedance_robot import ImpedanceRobot, ImpedanceRobotConfig
from robot_site.safety import LinkWatchdog, PatientSafety, SafetyConfig, within_force_bound
from robot_site.tissue import ABDOMEN, Tissue

TICK = 1e-3  # s, the robot's control period


class RemoteSite:
    """The robot pressing the abdomen (skin at z = 0), its sensor and its safety, at 1 kHz."""

    def __init__(self, start, **safety):
        config = ImpedanceRobotConfig(initial_position=start)
        self.robot = ImpedanceRobot(config, environment=Tissue(ABDOMEN))
        self.sensor = ForceTorqueSensor()
        self.safety = PatientSafety(SafetyConfig(robot_stiffness=config.stiffness, **safety))
        self.time = 0.0
        self.state = self.robot.read(0.0)

    def run(self, duration, target, *, link_up=True):
        """Follow ``target`` (a function of time) for ``duration`` s; return the patient forces."""
        forces = []
        for _ in range(round(duration / TICK)):
            self.time += TICK
            self.state = self.robot.read(self.time)
            measured = self.sensor.measure(self.time, self.state.external_force).force
            if link_up:
                self.safety.heard(self.time)
            self.robot.command(self.safety.safe_target(self.time, target(self.time),
                                                       self.state.position, measured))
            forces.append(self.state.external_force[2])
        return np.array(forces)


def test_the_target_is_kept_within_the_spring_reach_of_the_tcp():
    tcp = np.array([0.1, 0.0, 0.0])
    near = tcp + [0.0, 0.005, 0.0]
    np.testing.assert_array_equal(within_force_bound(near, tcp, 0.01), near)
    np.testing.assert_allclose(within_force_bound(tcp + [0.0, 0.0, -0.3], tcp, 0.01),
                               tcp + [0.0, 0.0, -0.01])
    assert SafetyConfig(robot_stiffness=1000.0, max_patient_force=20.0,
                        force_margin=1.0).spring_reach == pytest.approx(0.019)


@pytest.mark.parametrize('start_height', [0.0, 0.01, 0.05, 0.2])
def test_a_target_deep_in_the_patient_never_presses_past_the_limit(start_height):
    site = RemoteSite([0.0, 0.0, start_height], force_margin=0.0)
    forces = site.run(3.0, lambda t: [0.0, 0.0, -0.3])  # 0.8 s to come down, 1 s of ramp
    assert forces.max() <= 20.0
    assert forces[-1] == pytest.approx(20.0, rel=1e-3)  # and it does press up to the limit


def test_a_target_shaking_in_and_out_never_presses_past_the_limit():
    site = RemoteSite([0.0, 0.0, 0.0], max_patient_force=15.0)
    forces = site.run(3.0, lambda t: [0.05 * math.sin(9 * t), 0.0,
                                      -0.1 + 0.12 * math.sin(2 * math.pi * 3 * t)])
    assert 10.0 < forces.max() <= 15.0


def test_a_silent_link_holds_the_pose_then_retracts_until_the_force_is_released():
    site = RemoteSite([0.0, 0.0, 0.0])
    press = site.run(2.0, lambda t: [0.0, 0.0, -0.025])
    assert press[-1] == pytest.approx(10.0, abs=1.0)
    pressed_at = site.state.position.copy()
    timeout = site.safety.config.link_timeout
    # The link goes silent: for the timeout the robot follows its last target, then holds.
    waiting = site.run(timeout, lambda t: [0.0, 0.0, -0.025], link_up=False)
    assert not site.safety.holding
    assert np.ptp(waiting) < 0.05
    retreat = site.run(3.0, lambda t: [0.0, 0.0, -0.3], link_up=False)
    assert site.safety.holding
    # Holding the TCP lets the spring go: the force falls from where it was, never rising.
    assert np.all(np.diff(retreat) <= 1e-3)
    assert retreat[0] == pytest.approx(press[-1], abs=0.1)
    assert retreat[-1] < site.safety.config.release_force
    # Along the measured force: its noise (0.05 N on up to 10 N) tilts the way out a little.
    np.testing.assert_allclose(site.state.position[:2], pressed_at[:2], atol=1e-4)
    assert site.state.position[2] > pressed_at[2]  # drawn back, out of the patient
    # Once released, it stays where it is.
    still = site.state.position.copy()
    site.run(0.5, lambda t: [0.0, 0.0, -0.3], link_up=False)
    np.testing.assert_allclose(site.state.position, still, atol=2e-4)
    # The link comes back: the operator's target is followed again.
    site.run(2.0, lambda t: [0.0, 0.0, -0.025])
    assert not site.safety.holding
    assert site.state.external_force[2] == pytest.approx(10.0, abs=1.0)


def test_a_stall_while_pressing_in_holds_the_tcp_not_the_target_ahead_of_it():
    """The operator presses in at 20 mm/s; the link stalls for 0.5 s. The last target lies
    ahead of the TCP (up to the force bound's reach); holding it, the robot would press on."""
    site = RemoteSite([0.0, 0.0, 0.0])
    pressing = site.run(0.7, lambda t: [0.0, 0.0, -0.005 - 0.02 * t])
    before = site.state
    stalled = site.run(0.5, lambda t: [0.0, 0.0, -0.005 - 0.02 * t], link_up=False)
    timeout = round(site.safety.config.link_timeout / TICK)
    assert pressing[-1] > 5.0
    # Within the watchdog's timeout it followed the last target; from then on it yields.
    assert stalled[timeout:].max() <= stalled[timeout] + 0.05
    assert stalled[-1] < stalled[timeout]
    assert site.state.position[2] >= before.position[2] - 0.002  # 2 mm more in at most


def test_when_the_link_returns_the_target_goes_back_to_the_operators_without_a_jump():
    site = RemoteSite([0.0, 0.0, 0.0])
    site.run(1.0, lambda t: [0.0, 0.0, -0.025])
    site.run(2.0, lambda t: [0.0, 0.0, -0.025], link_up=False)  # retracted meanwhile
    targets = []
    command = site.robot.command
    site.robot.command = lambda target: (targets.append(np.array(target)), command(target))
    site.run(2.0, lambda t: [0.0, 0.0, -0.025])
    steps = np.linalg.norm(np.diff(targets, axis=0), axis=1)
    assert steps.max() <= site.safety.config.rejoin_speed * TICK * (1 + 1e-9) + 1e-12
    assert site.state.external_force[2] == pytest.approx(10.0, abs=1.0)  # and they met


def test_the_watchdog_counts_silence_from_the_latest_message():
    watchdog = LinkWatchdog(0.1)
    assert watchdog.silent(0.0)  # never heard
    watchdog.heard(1.0)
    watchdog.heard(0.5)  # a late, stale message does not move the time back
    assert not watchdog.silent(1.0999)
    assert watchdog.silent(1.1001)


@pytest.mark.parametrize('fields, message', [
    (dict(robot_stiffness=0.0), 'robot_stiffness must be finite > 0'),
    (dict(max_patient_force=math.nan), 'max_patient_force must be finite > 0'),
    (dict(force_margin=25.0), 'force_margin must be finite >= 0 <= 20'),
    (dict(release_force=-1.0), 'release_force must be finite >= 0'),
    (dict(link_timeout=-0.1), 'link_timeout must be finite > 0'),
    (dict(retract_speed=math.inf), 'retract_speed must be finite > 0'),
    (dict(rejoin_speed=0.0), 'rejoin_speed must be finite > 0'),
])
def test_bad_configurations_are_refused(fields, message):
    with pytest.raises(ValueError, match=message):
        SafetyConfig(**{'robot_stiffness': 1000.0, **fields})


def test_nan_inputs_are_refused():
    safety = PatientSafety(SafetyConfig(robot_stiffness=1000.0))
    with pytest.raises(ValueError, match='force must be 3 finite numbers'):
        safety.safe_target(0.0, np.zeros(3), np.zeros(3), [0.0, math.nan, 0.0])
    with pytest.raises(ValueError, match='target must be 3 finite numbers'):
        safety.safe_target(0.0, [math.inf, 0.0, 0.0], np.zeros(3), np.zeros(3))
    with pytest.raises(ValueError, match='heard time must be finite'):
        safety.heard(math.nan)
