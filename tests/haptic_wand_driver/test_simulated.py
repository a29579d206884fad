"""SimulatedWand: free motion, resting on a wall, energy, workspace stops, determinism, clock."""

from ground_truth.wand import HalfSpace, rotation_z, wall_force
import numpy as np
import pytest

from haptic_wand_driver.device import DeviceClosedError, DeviceLimits, Workspace
from haptic_wand_driver.simulated import SimulatedWand, SimulatedWandConfig
from simulated_operator.hand import OperatorHand
from simulated_operator.scripts import WaypointScript

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
    # Implicit damping: each substep divides the speed by 1 + step c / m (exp(-c t / m) as the
    # step goes to zero).
    substeps = np.round(elapsed / config.step)
    per_substep = 1.0 + config.step * config.damping[0] / config.mass[0]
    np.testing.assert_allclose(speeds, speeds[0] * per_substep ** -substeps, rtol=1e-9)


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


# A reference integration written from the module docstring with numpy, sharing no code with the
# module: semi-implicit Euler, device damping implicit, inelastic stops, the hand a spring-damper
# to a minimum-jerk target, the held wrench saturated and reaching the joints through the roll
# axis and z.

REFERENCE_WAYPOINTS = np.array([  # t, x, y, z, roll, yaw
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [0.6, 0.02, -0.01, -0.065, 0.1, -0.03],
    [1.2, 0.02, -0.01, -0.065, 0.1, -0.03],
    [2.0, -0.03, 0.02, 0.0, -0.25, 0.03],
    [2.5, -0.03, 0.02, 0.0, -0.25, 0.03],
])
REFERENCE_HAND = dict(stiffness=60.0, damping=3.0, rotational_stiffness=0.25,
                      rotational_damping=0.02)
REFERENCE_FORCE_LIMIT = 1.0
REFERENCE_TORQUE_LIMIT = 0.02


def reference_target(t):
    """Minimum-jerk target and its rate at ``t``, as 10 t^3 - 15 t^4 + 6 t^5 per leg."""
    times, points = REFERENCE_WAYPOINTS[:, 0], REFERENCE_WAYPOINTS[:, 1:]
    if t <= times[0]:
        return points[0], np.zeros(5)
    if t >= times[-1]:
        return points[-1], np.zeros(5)
    leg = np.flatnonzero(times <= t)[-1]
    span = times[leg + 1] - times[leg]
    tau = (t - times[leg]) / span
    shape = 10 * tau ** 3 - 15 * tau ** 4 + 6 * tau ** 5
    slope = (30 * tau ** 2 - 60 * tau ** 3 + 30 * tau ** 4) / span
    change = points[leg + 1] - points[leg]
    return points[leg] + shape * change, slope * change


def reference_wrench(position, velocity, yaw, t):
    """A wall below, a push up into the top stop for a while, and a torque with a pitch part."""
    wall = HalfSpace([0.0, 0.0, SURFACE_HEIGHT], [0.0, 0.0, 1.0])
    force = wall_force(wall, position, velocity) + ([0.0, 0.0, 3.0] if 1.9 < t < 2.2 else 0.0)
    torque = rotation_z(yaw) @ [0.03 * np.sin(4.0 * t), 0.01, 0.015]
    return force, torque


def reference_run(config, times):
    """States (coordinates, rates) at each of ``times``, the wrench applied after each read."""
    stiffness = np.array([REFERENCE_HAND['stiffness']] * 3
                         + [REFERENCE_HAND['rotational_stiffness']] * 2)
    damping = np.array([REFERENCE_HAND['damping']] * 3
                       + [REFERENCE_HAND['rotational_damping']] * 2)
    mass = np.array([*config.mass, config.roll_inertia, config.yaw_inertia])
    device_damping = np.array([*config.damping, config.roll_damping, config.yaw_damping])
    workspace = config.limits.workspace
    lower = np.array([*workspace.lower, -workspace.roll_limit, -workspace.yaw_limit])
    upper = np.array([*workspace.upper, workspace.roll_limit, workspace.yaw_limit])
    q, v = np.zeros(5), np.zeros(5)
    force, torque = np.zeros(3), np.zeros(3)
    substeps, states = 0, []
    for now in times:
        while (substeps + 1) * config.step <= now - times[0] + 1e-9:
            t = substeps * config.step
            goal, goal_rate = reference_target(t)
            roll_axis = np.array([np.cos(q[4]), np.sin(q[4]), 0.0])
            effort = (np.concatenate([force, [roll_axis @ torque, torque[2]]])
                      + stiffness * (goal - q) + damping * (goal_rate - v))
            v = (v + config.step * effort / mass) / (1.0 + config.step * device_damping / mass)
            q = q + config.step * v
            v[((q < lower) & (v < 0.0)) | ((q > upper) & (v > 0.0))] = 0.0
            q = np.minimum(np.maximum(q, lower), upper)
            substeps += 1
        states.append((q.copy(), v.copy()))
        force, torque = reference_wrench(q[:3], v[:3], q[4], substeps * config.step)
        for name, limit in (('force', REFERENCE_FORCE_LIMIT), ('torque', REFERENCE_TORQUE_LIMIT)):
            vector = force if name == 'force' else torque
            length = np.sqrt(np.sum(vector ** 2))
            scaled = vector * (limit / length) if length > limit else vector
            force, torque = (scaled, torque) if name == 'force' else (force, scaled)
    return states


def test_simulation_matches_a_reference_integration():
    workspace = Workspace(lower=[-0.15, -0.15, -0.15], upper=[0.15, 0.15, 0.01],
                          roll_limit=0.25, yaw_limit=0.04)
    config = SimulatedWandConfig(limits=DeviceLimits(REFERENCE_FORCE_LIMIT,
                                                     REFERENCE_TORQUE_LIMIT, workspace))
    script = WaypointScript(REFERENCE_WAYPOINTS[:, 0], REFERENCE_WAYPOINTS[:, 1:],
                            workspace=workspace)
    wand = SimulatedWand(config, operator=OperatorHand(script, **REFERENCE_HAND))
    times = np.arange(0.0, 3.0, TICK) + np.random.default_rng(3).uniform(0.0, 0.3 * TICK, 3000)
    times[0] = 0.0
    states = run(wand, 0.0, lambda s: reference_wrench(s.position, s.linear_velocity, s.yaw,
                                                       s.time), times=times)
    expected = reference_run(config, times)
    coordinates = np.array([s.coordinates for s in states])
    rates = np.array([s.rates for s in states])
    np.testing.assert_allclose(coordinates, [q for q, _ in expected], rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(rates, [v for _, v in expected], rtol=0.0, atol=1e-12)
    # The run exercises what it claims to: the wall, and stops at both ends.
    assert coordinates[:, 2].min() < SURFACE_HEIGHT
    assert coordinates[:, 2].max() == workspace.upper[2]
    assert coordinates[:, 3].min() == -workspace.roll_limit
    assert coordinates[:, 4].max() == workspace.yaw_limit


class _TargetOnly:
    """A script that offers only ``target(t)``, as a third-party script may."""

    def __init__(self, script, spoil_after=np.inf):
        self._script, self._spoil_after = script, spoil_after
        self.duration = script.duration

    def target(self, t):
        target = self._script.target(t)
        if t > self._spoil_after:
            return type(target)(target.coordinates * np.nan, target.rates)
        return target


def wall_contact(state):
    wall = HalfSpace([0.0, 0.0, SURFACE_HEIGHT], [0.0, 0.0, 1.0])
    return wall_force(wall, state.position, state.linear_velocity), np.zeros(3)


def test_a_script_with_only_target_moves_the_hand_the_same_way():
    waypoints = pressing_hand().script
    expected = run(SimulatedWand(operator=OperatorHand(waypoints)), 1.0, wall_contact)
    states = run(SimulatedWand(operator=OperatorHand(_TargetOnly(waypoints))), 1.0, wall_contact)
    for a, b in zip(expected, states):
        np.testing.assert_array_equal(a.coordinates, b.coordinates)
        np.testing.assert_array_equal(a.rates, b.rates)


def test_a_script_giving_nan_stops_the_wand_with_an_error_naming_it():
    wand = SimulatedWand(operator=OperatorHand(_TargetOnly(pressing_hand().script, 0.2)))
    wand.read(0.0)
    with pytest.raises(ValueError, match=r'_TargetOnly\.target\(.*coordinates must be 5 finite'):
        wand.read(0.5)


def test_states_are_read_only():
    state = SimulatedWand(operator=pressing_hand()).read(0.0)
    for vector in (state.position, state.linear_velocity):
        with pytest.raises(ValueError):
            vector[0] = 1.0


def held_and_freed(until: float, freed_at: float) -> tuple:
    """Two wands pushed alike from 0 s: one held ``until``, one given zero at ``freed_at``."""
    config = SimulatedWandConfig(step=5e-4)
    held, freed = SimulatedWand(config), SimulatedWand(config)
    for wand in (held, freed):
        wand.read(0.0)
    held.apply([2.0, 0.0, 0.0], [0.0, 0.0, 0.0], until=until)
    freed.apply([2.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    freed.read(freed_at)
    freed.apply([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    return held, freed


def test_a_held_force_drops_to_zero_at_its_deadline_without_another_call():
    """The device-level watchdog: past ``until`` the wand moves as if no force were applied."""
    held, freed = held_and_freed(until=0.0035, freed_at=0.0035)
    for t in (0.0035, 0.01, 0.05):
        assert held.read(t).position.tolist() == freed.read(t).position.tolist()
    assert held.read(0.05).linear_velocity[0] > 0.0  # the force did act before the deadline


def test_a_servo_period_that_would_end_after_the_deadline_renders_no_force():
    """Nothing is rendered past ``until``: the period it falls inside is zero already."""
    held, freed = held_and_freed(until=0.0033, freed_at=0.003)
    assert held.read(0.01).position.tolist() == freed.read(0.01).position.tolist()
    assert held.force_edges == [(0.0, True), (0.003, False)]


def test_a_deadline_already_past_renders_no_force():
    wand = SimulatedWand(SimulatedWandConfig())
    wand.read(1.0)
    wand.apply([5.0, 0.0, 0.0], [0.0, 0.0, 0.0], until=0.5)
    assert wand.read(1.1).linear_velocity.tolist() == [0.0, 0.0, 0.0]


def test_a_tick_inside_one_servo_period_reports_the_force_the_hand_still_feels():
    """Two reads within one substep: nothing rendered in between, the force still held."""
    wand = SimulatedWand(SimulatedWandConfig(step=0.00025))
    wand.read(0.0)
    wand.apply(np.array([0.0, 0.0, 2.0]), np.zeros(3))
    wand.read(0.001)
    assert wand.applied()[0][2] == pytest.approx(2.0)
    wand.read(0.0011)  # no substep since
    assert wand.applied()[0][2] == pytest.approx(2.0)
    wand.apply(np.zeros(3), np.zeros(3))
    wand.read(0.002)
    assert wand.applied()[0][2] == 0.0
