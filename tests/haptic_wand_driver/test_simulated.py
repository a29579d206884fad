"""SimulatedWand: free motion, resting on a wall, energy, workspace stops, determinism, clock."""

import numpy as np
import pytest
from wand_ground_truth import HalfSpace, rotation_z, wall_force

from haptic_wand_driver.device import DeviceClosedError, DeviceLimits, Workspace
from haptic_wand_driver.operator import OperatorHand
from haptic_wand_driver.scripts import WaypointScript
from haptic_wand_driver.simulated import SimulatedWand, SimulatedWandConfig

TICK = 1e-3
HAND_STIFFNESS = 50.0
WALL_STIFFNESS = 160.0
SURFACE_HEIGHT = -0.05
TARGET_DEPTH = 0.01


def pressing_hand():
    """A hand moving the tip from the origin to 1 cm below the surface z = -0.05 in 0.5 s."""
    script = WaypointScript.from_rows([(0.0, 0.0, 0.0, 0.0),
                                       (0.5, 0.0, 0.0, SURFACE_HEIGHT - TARGET_DEPTH)])
    return OperatorHand(script, stiffness=HAND_STIFFNESS)


def run(wand, seconds, wrench=None, times=None):
    """Read every tick (or at ``times``), apply ``wrench(state)``; return the states."""
    times = np.arange(0.0, seconds, TICK) if times is None else times
    states = []
    for now in times:
        state = wand.read(now)
        states.append(state)
        if wrench is not None:
            force, torque = wrench(state)
            wand.apply(force, torque)
    return states


def test_without_force_the_tip_passes_through_the_wall_to_the_target():
    states = run(SimulatedWand(operator=pressing_hand()), 3.0)
    assert states[-1].position[2] == pytest.approx(SURFACE_HEIGHT - TARGET_DEPTH, abs=1e-4)


def test_with_a_160_newton_per_metre_wall_the_tip_rests_on_the_surface():
    wall = HalfSpace([0.0, 0.0, SURFACE_HEIGHT], [0.0, 0.0, 1.0])
    states = run(SimulatedWand(operator=pressing_hand()), 3.0,
                 lambda s: (wall_force(wall, s.position, s.linear_velocity), np.zeros(3)))
    resting = SURFACE_HEIGHT - states[-1].position[2]
    expected = HAND_STIFFNESS * TARGET_DEPTH / (HAND_STIFFNESS + WALL_STIFFNESS)
    assert resting == pytest.approx(expected, abs=5e-5)
    assert 0.0 < resting < 0.005
    assert np.linalg.norm(states[-1].linear_velocity) < 1e-4
    deepest = SURFACE_HEIGHT - min(s.position[2] for s in states)
    assert deepest < TARGET_DEPTH


def test_free_wand_velocity_decays_as_its_damping_says():
    config = SimulatedWandConfig()
    wand = SimulatedWand(config)
    wand.read(0.0)
    wand.apply([0.2, 0.0, -0.1], np.zeros(3))
    wand.read(0.1)
    wand.apply(np.zeros(3), np.zeros(3))
    states = run(wand, 0.0, times=np.arange(0.1, 1.0, TICK))
    speeds = np.array([np.linalg.norm(s.linear_velocity) for s in states])
    assert np.all(np.diff(speeds) <= 0.0)
    elapsed = np.array([s.time for s in states]) - states[0].time
    decay_rate = config.damping[0] / config.mass[0]
    np.testing.assert_allclose(speeds, speeds[0] * np.exp(-decay_rate * elapsed), rtol=1e-3)


def test_free_wand_yaw_rate_decays():
    wand = SimulatedWand()
    wand.read(0.0)
    wand.apply(np.zeros(3), [0.0, 0.0, 0.01])
    wand.read(0.05)
    wand.apply(np.zeros(3), np.zeros(3))
    rates = [abs(s.yaw_rate) for s in run(wand, 0.0, times=np.arange(0.05, 0.5, TICK))]
    assert rates[0] > 0.0 and np.all(np.diff(rates) <= 0.0) and rates[-1] < rates[0]


@pytest.mark.parametrize('axis', [0, 1, 2])
@pytest.mark.parametrize('sign', [1.0, -1.0])
def test_workspace_stops_hold_and_never_give_energy_back(axis, sign):
    workspace = Workspace()
    wand = SimulatedWand(SimulatedWandConfig(limits=DeviceLimits(10.0, 0.5, workspace)))
    push = np.zeros(3)
    push[axis] = 2.0 * sign
    states = run(wand, 1.0, lambda s: (push if s.time < 0.3 else np.zeros(3), np.zeros(3)))
    limit = workspace.upper[axis] if sign > 0 else workspace.lower[axis]
    positions = np.array([s.position[axis] for s in states])
    assert np.all(sign * positions <= sign * limit)
    assert positions[-1] == limit
    speeds = [np.linalg.norm(s.linear_velocity) for s in states if s.time >= 0.3]
    assert np.all(np.diff(speeds) <= 0.0)


def test_the_wand_leaves_a_stop_when_pulled_back():
    wand = SimulatedWand()
    run(wand, 0.5, lambda s: ([0.0, 0.0, 3.0], np.zeros(3)))
    later = run(wand, 0.0, lambda s: ([0.0, 0.0, -1.0], np.zeros(3)),
                times=np.arange(0.5, 0.7, TICK))
    assert later[-1].position[2] < Workspace().upper[2] - 1e-3


def test_yaw_and_roll_stop_at_thirty_degrees():
    wand = SimulatedWand()
    thirty = np.radians(30.0)
    states = run(wand, 1.0, lambda s: (np.zeros(3), rotation_z(s.yaw) @ [0.05, 0.0, -0.05]))
    assert max(s.yaw for s in states) <= thirty and min(s.yaw for s in states) >= -thirty
    assert states[-1].yaw == pytest.approx(-thirty) and states[-1].roll == pytest.approx(thirty)


def test_pitch_torque_moves_nothing():
    wand = SimulatedWand()
    states = run(wand, 0.3, lambda s: (np.zeros(3), rotation_z(s.yaw) @ [0.0, 0.3, 0.0]))
    assert states[-1].roll == 0.0 and states[-1].yaw == 0.0


def test_force_is_saturated_to_the_device_limit():
    config = SimulatedWandConfig(limits=DeviceLimits(force_limit=2.0, torque_limit=0.5))
    wand = SimulatedWand(config)
    wand.read(0.0)
    wand.apply([300.0, 400.0, 0.0], np.zeros(3))
    velocity = wand.read(config.step).linear_velocity
    decay = 1.0 + config.step * config.damping[0] / config.mass[0]
    expected = np.array([1.2, 1.6, 0.0]) * config.step / config.mass[0] / decay
    np.testing.assert_allclose(velocity, expected, rtol=1e-12)


def contact_trace(times):
    wall = HalfSpace([0.0, 0.0, SURFACE_HEIGHT], [0.0, 0.0, 1.0])
    wand = SimulatedWand(operator=pressing_hand())
    return {s.time: s for s in run(
        wand, 0.0, lambda s: (wall_force(wall, s.position, s.linear_velocity), np.zeros(3)),
        times=times)}


def test_same_calls_give_bit_identical_states():
    times = np.arange(0.0, 1.0, TICK)
    first, second = contact_trace(times), contact_trace(times)
    for time, state in first.items():
        np.testing.assert_array_equal(state.coordinates, second[time].coordinates)
        np.testing.assert_array_equal(state.rates, second[time].rates)


def test_jittery_reads_see_the_same_trajectory():
    step = SimulatedWandConfig().step
    regular = run(SimulatedWand(operator=pressing_hand()), 1.0)
    jitter = np.random.default_rng(7).uniform(0.0, 0.9 * step, size=len(regular))
    jitter[0] = 0.0  # the first read starts the clock
    jittery = run(SimulatedWand(operator=pressing_hand()), 0.0,
                  times=np.arange(0.0, 1.0, TICK) + jitter)
    for a, b in zip(regular, jittery):
        assert a.time == pytest.approx(b.time, abs=1e-12)
        np.testing.assert_array_equal(a.coordinates, b.coordinates)


def test_clock_starts_at_first_read_and_may_not_go_back():
    wand = SimulatedWand()
    assert wand.read(100.0).time == 100.0
    state = wand.read(100.00123)
    assert 100.00123 - SimulatedWandConfig().step < state.time <= 100.00123
    with pytest.raises(ValueError, match='must not go back'):
        wand.read(99.0)


def test_apply_rejects_non_finite_and_closed_wand_refuses():
    wand = SimulatedWand()
    with pytest.raises(ValueError, match='finite'):
        wand.apply([np.nan, 0.0, 0.0], np.zeros(3))
    wand.close()
    with pytest.raises(DeviceClosedError):
        wand.read(0.0)


@pytest.mark.parametrize('kwargs, name', [(dict(mass=[0.1, -0.1, 0.1]), 'mass'),
                                          (dict(damping=[0.1, 0.1]), 'damping'),
                                          (dict(step=0.0), 'step'),
                                          (dict(initial_position=[0.0, 0.0, 1.0]), 'initial')])
def test_config_rejects_bad_fields_by_name(kwargs, name):
    with pytest.raises(ValueError, match=name):
        SimulatedWandConfig(**kwargs)


def test_step_too_long_for_the_hand_is_refused():
    with pytest.raises(ValueError, match='step'):
        SimulatedWand(SimulatedWandConfig(step=0.05), operator=pressing_hand())
