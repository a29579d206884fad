"""Time-domain passivity over a delayed link: the link never delivers more than it received.

The energy figures here are recomputed from the forces and velocities the controllers returned,
not read from their books. The closed loop is a 1-DOF position-force teleoperation over a 100 ms
one-way link: an operator's hand pushes a wand 1 cm into a stiff wall at the robot and back out,
the robot's probe follows the wand's delayed velocity and the wall's force comes back delayed.
Reflected directly, the link creates energy; with the controllers at both ends it does not.
"""
from collections import deque
import math

import numpy as np
import pytest

from teleop_protocol.tdpa import EnergyBooks, OperatorPassivity, RobotPassivity

DT = 1e-3  # [s] servo period of both sites
DELAY = 100  # [periods] one-way: 100 ms
X = np.array([1.0, 0.0, 0.0])


def delayed(values, steps: int):
    """Give back, per call, what was put in ``steps`` calls earlier (the initial value first)."""
    queue = deque(values for _ in range(steps))

    def exchange(value):
        queue.append(value)
        return queue.popleft()
    return exchange


def hand_path(t: float) -> float:
    """The hand's target (m): from 1 cm out to 1 cm into the wall over 1 s, held, back out."""
    return float(np.interp(t, [0.0, 1.0, 3.0, 4.0], [-0.01, 0.01, 0.01, -0.01]))


def teleoperate(passive: bool, seconds: float = 6.0, drift_rate: float = 0.0) -> dict:
    """Run the 1-DOF loop; return the energy the link delivered, net, and the wall's depths."""
    operator, robot = OperatorPassivity(), RobotPassivity(drift_rate)
    to_robot = delayed((0.0, 0.0, 0.0), DELAY)  # (wand position, velocity, operator's energy in)
    to_operator = delayed((0.0, 0.0), DELAY)  # (wall force, robot's energy in)
    wand = probe = wand_velocity = 0.0
    wall_force, link_energy, depths = 0.0, 0.0, []
    for k in range(int(seconds / DT)):
        hand_target = hand_path(k * DT)
        target, commanded, operator_in = to_robot((wand, wand_velocity,
                                                   operator.books.energy_in))
        reflected, robot_in = to_operator((wall_force, robot.books.energy_in))
        if passive:
            operator.books.receive(robot_in)
            robot.books.receive(operator_in)
            display = operator.control(reflected * X, wand_velocity * X, DT)[0]
            probe_velocity = robot.control(commanded * X, wall_force * X, DT,
                                           (target - probe) * X)[0]
        else:
            display, probe_velocity = reflected, commanded
        link_energy += (display * wand_velocity - wall_force * probe_velocity) * DT
        hand = 200.0 * (hand_target - wand) - 2.0 * wand_velocity
        wand_velocity += DT * (hand + display) / 0.15
        wand += DT * wand_velocity
        probe += DT * probe_velocity
        wall_force = -5000.0 * max(probe, 0.0)
        depths.append(max(probe, 0.0))
    return {'link_energy': link_energy, 'depths': np.array(depths), 'wand': wand,
            'probe': probe}


def test_reflected_directly_over_100_ms_the_link_creates_energy():
    direct = teleoperate(passive=False)
    assert direct['link_energy'] > 0.01, direct['link_energy']  # the baseline fails visibly


@pytest.mark.parametrize('drift_rate', [0.0, 5.0])
def test_with_passivity_at_both_ends_the_link_creates_no_energy(drift_rate):
    passive = teleoperate(passive=True, drift_rate=drift_rate)
    assert passive['link_energy'] <= 1e-12, passive['link_energy']
    assert passive['depths'].max() > 0.0  # the probe reached the wall


def test_drift_compensation_brings_the_probe_back_to_the_wand_once_clear_of_the_wall():
    yielded = teleoperate(passive=True)
    compensated = teleoperate(passive=True, drift_rate=5.0)
    assert max(yielded['wand'], compensated['wand']) < 0.0  # both wands back out of the wall
    assert abs(yielded['probe'] - yielded['wand']) > 0.002  # left behind by the yielding
    assert abs(compensated['probe'] - compensated['wand']) < 0.1 * abs(
        yielded['probe'] - yielded['wand'])


def test_the_operator_side_delivers_no_more_than_it_received_and_only_damps():
    rng = np.random.default_rng(7)
    side, delivered, received = OperatorPassivity(), 0.0, 0.0
    for _ in range(2000):
        received += rng.uniform(0.0, 1e-3)
        side.books.receive(received)
        force, velocity = rng.normal(size=3), rng.normal(size=3)
        shown = side.control(force, velocity, DT)
        change = shown - force
        along = float(change @ velocity)
        assert np.allclose(change, along / float(velocity @ velocity) * velocity)
        assert along <= 1e-15  # a damper along the velocity, never a push
        delivered += max(float(shown @ velocity), 0.0) * DT
        assert delivered <= received + 1e-12


def test_the_robot_side_delivers_no_more_work_into_the_patient_than_it_received_and_yields():
    rng = np.random.default_rng(8)
    side, delivered, received = RobotPassivity(), 0.0, 0.0
    for _ in range(2000):
        received += rng.uniform(0.0, 1e-3)
        side.books.receive(received)
        velocity, force = rng.normal(size=3), rng.normal(size=3)
        commanded = side.control(velocity, force, DT)
        change = commanded - velocity
        along = float(change @ force)
        assert np.allclose(change, along / float(force @ force) * force)
        assert along >= -1e-15  # it yields along the patient's force, never presses harder
        delivered += max(-float(force @ commanded), 0.0) * DT
        assert delivered <= received + 1e-12


def test_with_energy_to_spare_nothing_changes():
    side = OperatorPassivity()
    side.books.receive(1.0)
    assert side.control([1.0, 2.0, 3.0], [0.1, 0.0, 0.0], DT).tolist() == [1.0, 2.0, 3.0]


def test_an_older_energy_total_arriving_late_is_ignored():
    books = EnergyBooks()
    books.receive(0.5)
    books.receive(0.2)  # reordered by the link
    assert books.far_in == 0.5


@pytest.mark.parametrize('bad', [math.nan, -1.0])
def test_a_bad_energy_total_is_refused(bad):
    with pytest.raises(ValueError, match='far_in'):
        EnergyBooks().receive(bad)
