"""Passivity: the Colgate bound, the observer's bookkeeping, and the closed-loop guarantee."""

from ground_truth.virtual_wall import Device, HalfSpace, OperatorHand, simulate
import numpy as np
import pytest

from force_renderer.contact import Contact
from force_renderer.errors import ForceRendererError
from force_renderer.passivity import (BOOKS_CLOSE_AFTER, passivity_bound, passivity_warning,
                                      PassivityController)
from force_renderer.pipeline import ForcePipeline, PipelineConfig
from force_renderer.spring_damper import SpringDamper

PERIOD = 0.001
UP = (0.0, 0.0, 1.0)  # the axis of a wall below z = 0


@pytest.mark.parametrize('b, period, c, expected', [
    (1.0, 0.001, 0.8, 400.0), (1.0, 0.001, 0.0, 2000.0), (2.0, 0.0005, -0.5, 6000.0),
    (0.5, 0.001, 0.8, 0.0)])
def test_colgate_bound(b, period, c, expected):
    assert passivity_bound(b, period, c) == pytest.approx(expected)


@pytest.mark.parametrize('b, period, name', [(-1.0, 0.001, 'device_damping'),
                                             (1.0, 0.0, 'servo_period'),
                                             (np.nan, 0.001, 'device_damping')])
def test_bound_rejects_bad_input(b, period, name):
    with pytest.raises(ForceRendererError, match=name):
        passivity_bound(b, period)


def test_warning_names_the_axes_over_the_bound():
    assert passivity_warning(300.0, 1.0, PERIOD, 0.8) is None
    message = passivity_warning([300.0, 300.0, 5000.0], 1.0, PERIOD, 0.8)
    assert 'z: K = 5000 N/m > K_max = 400 N/m' in message
    assert 'x:' not in message and 'passivity controller' in message


def spring_force(height, stiffness):
    """Force of a wall below z = 0 on a tip at `height` (m), zero above it."""
    return (0.0, 0.0, stiffness * max(0.0, -height))


def test_observer_books_the_held_force_times_the_displacement():
    controller = PassivityController(max_damping=0.0)
    heights = [-0.001, -0.0015, -0.0012, -0.0020, 0.0005, 0.0010]
    applied = [(0.3, -0.1, 2.0), (0.0, 0.0, 3.0), (1.0, 1.0, 1.0), (0.0, 0.0, 4.0), (0, 0, 0)]
    for step, height in enumerate(heights):
        controller.control((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, height), step * PERIOD,
                           UP)
        if step < len(applied):
            controller.record(applied[step])
    expected = -sum(force[2] * (after - before)
                    for force, before, after in zip(applied, heights, heights[1:]))
    assert controller.energy == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize('speed', [0.05, -0.05])
def test_sampled_spring_generates_half_k_dx_squared_per_interval(speed):
    """With no damping allowed, the deficit grows by K·Δz²/2 per interval, in or out."""
    stiffness, steps = 2000.0, 8
    controller = PassivityController(max_damping=0.0)
    heights = -0.005 + speed * PERIOD * np.arange(steps + 1)
    for step, height in enumerate(heights):
        force = spring_force(height, stiffness)
        controller.record(controller.control(force, (0.0, 0.0, speed), (0.0, 0.0, height),
                                             step * PERIOD, UP))
    assert controller.deficit == pytest.approx(steps * 0.5 * stiffness * (speed * PERIOD) ** 2,
                                               rel=1e-9)


@pytest.mark.parametrize('speed', [0.05, -0.05])
def test_controller_adds_exactly_the_damping_the_hold_removes(speed):
    """On a sampled spring at constant speed: α = K·T/2, and the deficit stays zero.

    From the third step on: the first has no earlier force to extrapolate from."""
    stiffness = 2000.0
    controller = PassivityController(max_damping=1e3, servo_period=PERIOD)
    for step, height in enumerate(-0.005 + speed * PERIOD * np.arange(10)):
        force = spring_force(height, stiffness)
        sent = controller.control(force, (0.0, 0.0, speed), (0.0, 0.0, height), step * PERIOD,
                                  UP)
        controller.record(sent)
        if step >= 2:
            assert controller.damping == pytest.approx(stiffness * PERIOD / 2, rel=1e-9)
            assert sent[2] == pytest.approx(force[2] - controller.damping * speed, rel=1e-9)
            assert controller.deficit == pytest.approx(0.0, abs=1e-15)


def test_controller_never_reverses_the_force_and_respects_its_bound():
    controller = PassivityController(max_damping=5.0)
    controller.control((0.0, 0.0, 1.0), (0.0, 0.0, 2.0), (0.0, 0.0, -0.001), 0.0, UP)
    controller.record((0.0, 0.0, 10.0))   # 10 N held over 10 mm: far more than the law's 1 N
    sent = controller.control((0.0, 0.0, 0.9), (0.0, 0.0, 2.0), (0.0, 0.0, 0.009), PERIOD, UP)
    assert controller.damping == 5.0
    assert sent == (0.0, 0.0, 0.0)


def test_the_damping_acts_on_the_push_along_the_axis_and_leaves_a_residue_alone():
    """A contact ending: the tip leaves at 0.063 m/s while the law leaves a sideways residue.

    Damping along the whole force scaled that residue up into a sideways kick; along the axis,
    the residue passes unchanged and the push only drops.
    """
    controller = PassivityController(max_damping=100.0)
    controller.control((0.0, 0.0, 1.0), (0.0, 0.0, 0.063), (0.0, 0.0, -0.001), 0.0, UP)
    controller.record((0.0, 0.0, 3.0))  # more than the law: a deficit to pay
    residue = (-0.005, 0.0, 0.0002)
    sent = controller.control(residue, (0.03, 0.0, 0.063), (0.0, 0.0, 0.0), PERIOD, UP)
    assert controller.deficit > 0.0
    assert sent[:2] == residue[:2]
    assert 0.0 <= sent[2] <= residue[2]


def test_the_books_close_after_a_break_in_contact_not_at_a_bounce():
    controller = PassivityController()
    controller.control((0.0, 0.0, 5.0), (0.0, 0.0, 1.0), (0.0, 0.0, -0.002), 0.0, UP)
    controller.record((0.0, 0.0, 5.0))
    steps = round(BOOKS_CLOSE_AFTER / PERIOD)
    for step in range(1, steps + 2):
        controller.control((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, 0.001), step * PERIOD)
        if step == 1:
            assert controller.deficit > 0.0  # a bounce: carried
    assert controller.deficit == 0.0  # a break: the next touch is another contact


def test_nothing_is_added_in_free_space_or_without_velocity():
    controller = PassivityController()
    controller.control((0.0, 0.0, 5.0), (0.0, 0.0, 1.0), (0.0, 0.0, -0.002), 0.0, UP)
    controller.record((0.0, 0.0, 5.0))
    assert controller.control((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, 0.001), PERIOD) \
        == (0.0, 0.0, 0.0)
    assert controller.deficit > 0.0 and controller.damping == 0.0
    assert controller.control((0.0, 0.0, 2.0), None, None, 2 * PERIOD, UP) == (0.0, 0.0, 2.0)


# Closed loop: a 0.15 kg device with 1 N·s/m of damping, pressed by the hand 10 mm into the wall,
# held, and lifted clear. The Colgate bound for C = 0.8 N·s/m at 1 kHz is 400 N/m.
DEVICE = Device(0.15, 1.0, np.array([[0.0, 0.0, 1.0]]))


def hand_target(t):
    height = 0.005 - 0.015 * min(t / 0.1, 1.0)
    if t > 0.8:
        height = -0.010 + 0.030 * min((t - 0.8) / 0.2, 1.0)
    return np.array([0.0, 0.0, height])


def press_hold_release(stiffness, passivity):
    pipeline = ForcePipeline(SpringDamper(stiffness, 0.8), PipelineConfig(passivity=passivity))
    return simulate(pipeline.step, HalfSpace(), DEVICE, OperatorHand(300.0, 1.0, hand_target),
                    duration=1.2, start=np.array([0.0, 0.0, 0.005]))


def amplitude(run, start, end):
    """Peak-to-peak tip height between `start` and `end` (s), m."""
    return np.ptp(run.position[(run.time >= start) & (run.time < end), 2])


@pytest.mark.parametrize('stiffness', np.logspace(2, 5, 7))
def test_passive_and_settling_at_any_stiffness_with_the_controller(stiffness):
    run = press_hold_release(stiffness, passivity=True)
    assert run.position[-1, 2] > 0.0                  # released: the wall stores nothing now
    assert -run.port_energy[-1] <= 0.0                # net energy generated by the rendering
    assert amplitude(run, 0.7, 0.8) <= 0.1 * amplitude(run, 0.15, 0.25)
    assert np.all(np.linalg.norm(run.force, axis=1) <= 10.0 + 1e-9)


def test_without_the_controller_a_stiff_wall_generates_energy_and_buzzes():
    run = press_hold_release(1e4, passivity=False)
    energy_at = np.interp([0.3, 0.55, 0.8], run.time, -run.port_energy)
    assert energy_at[0] < energy_at[1] < energy_at[2]          # generation keeps growing
    assert energy_at[2] - energy_at[0] > 0.01                    # J, over half a second
    assert -run.port_energy[-1] > 0.0
    assert amplitude(run, 0.7, 0.8) > 0.5 * amplitude(run, 0.15, 0.25)


def test_observer_agrees_with_the_exact_port_energy_of_the_simulation():
    controller = PassivityController()
    pipeline = ForcePipeline(SpringDamper(5000.0, 0.8))
    pipeline.passivity = controller
    observed = []

    def render(contact: Contact, velocity, now):
        force = pipeline.step(contact, velocity, now)
        observed.append((now, controller.energy))
        return force

    run = simulate(render, HalfSpace(), DEVICE, OperatorHand(300.0, 1.0, hand_target),
                   duration=0.5, start=np.array([0.0, 0.0, 0.005]))
    times, energies = np.array(observed).T
    exact = np.interp(times, run.time, run.port_energy)
    # The observer drops its reserve in free space, so compare while it has only been in contact.
    in_contact = times < 0.4
    assert np.abs(energies - exact)[in_contact].max() < 1e-12
