"""The servo step: watchdog, law, passivity and saturation together, open and closed loop."""

import math

from analytic_fields import Box
from fuzzing import examples
from ground_truth.virtual_wall import Device, HalfSpace, OperatorHand, ServoTiming, simulate
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from force_renderer.contact import (Contact, STATUS_INVALID_INPUT, STATUS_NO_OBJECT,
                                    STATUS_NOT_CONVERGED)
from force_renderer.errors import ForceRendererError
from force_renderer.pipeline import ForcePipeline, PipelineConfig
from force_renderer.spring_damper import SpringDamper
from force_renderer.watchdog import Reason

UP = (0.0, 0.0, 1.0)


def wall_contact(height, stamp, x=0.0):
    """Collision state of a tip at `height` (m) over the wall z < 0."""
    return Contact(height, (x, 0.0, 0.0), UP, (x, 0.0, height), 'wall', stamp)


def test_in_contact_the_force_is_the_law_s():
    pipeline = ForcePipeline(SpringDamper(1000.0, 2.0), PipelineConfig(passivity=False))
    force = pipeline.step(wall_contact(-0.003, 1.0), (0.01, 0.0, -0.05), 1.0005)
    np.testing.assert_allclose(force, [-0.02, 0.0, 3.1], rtol=1e-12)
    assert pipeline.last_reason is Reason.OK and pipeline.last_stamp == 1.0


@pytest.mark.parametrize('passivity', [False, True])
def test_no_force_and_no_damping_work_out_of_contact(passivity):
    pipeline = ForcePipeline(SpringDamper(1000.0, 50.0), PipelineConfig(passivity=passivity))
    for step in range(5):
        force = pipeline.step(wall_contact(0.001 + 0.001 * step, step * 1e-3),
                              (3.0, -2.0, 1.0), step * 1e-3)
        np.testing.assert_array_equal(force, np.zeros(3))


def test_saturates_along_the_normal():
    pipeline = ForcePipeline(SpringDamper(5000.0, 0.0), PipelineConfig(force_limit=4.0))
    normal = np.array([0.0, 0.6, 0.8])
    contact = Contact(-0.01, 0.01 * normal, normal, (0.0, 0.0, 0.0), 'box', 0.0)
    np.testing.assert_allclose(pipeline.step(contact, (0.0, 0.0, 0.0), 0.0), 4.0 * normal)


@pytest.mark.parametrize('contact, velocity, now, reason', [
    (wall_contact(-0.002, 1.000), UP, 1.0101, Reason.STALE),
    (wall_contact(-0.002, 1.000), (0.0, math.nan, 0.0), 1.0, Reason.NON_FINITE),
    (Contact(-0.002, (0, 0, 0), (0, 0, math.inf), (0, 0, -0.002), 'wall', 1.0), UP, 1.0,
     Reason.NON_FINITE),
    (wall_contact(-0.002, 1.05), UP, 1.0, Reason.FUTURE),
    (None, UP, 1.0, Reason.NO_STATE),
])
def test_rejected_input_gives_zero_and_a_reason(contact, velocity, now, reason):
    pipeline = ForcePipeline(SpringDamper(1000.0, 0.8))
    force = pipeline.step(contact, velocity, now)
    np.testing.assert_array_equal(force, np.zeros(3))
    assert pipeline.last_reason is reason
    assert (pipeline.last_stamp == contact.stamp) if contact else math.isnan(pipeline.last_stamp)


def test_out_of_order_input_is_dropped_and_fresh_input_recovers():
    pipeline = ForcePipeline(SpringDamper(1000.0, 0.0), PipelineConfig(passivity=False))
    assert pipeline.step(wall_contact(-0.002, 2.000), None, 2.000)[2] == pytest.approx(2.0)
    np.testing.assert_array_equal(pipeline.step(wall_contact(-0.003, 1.999), None, 2.001),
                                  np.zeros(3))
    assert pipeline.last_reason is Reason.OUT_OF_ORDER
    assert pipeline.step(wall_contact(-0.001, 2.002), None, 2.002)[2] == pytest.approx(1.0)
    assert pipeline.last_reason is Reason.OK


def test_without_a_twist_the_velocity_is_estimated_from_the_tips():
    damping = 4.0
    pipeline = ForcePipeline(SpringDamper(0.0, damping), PipelineConfig(passivity=False))
    for step in range(4):
        force = pipeline.step(wall_contact(-0.001 - 0.0001 * step, step * 1e-3), None,
                              step * 1e-3)
    np.testing.assert_allclose(force, [0.0, 0.0, damping * 0.1], rtol=1e-9)


anything = st.one_of(st.floats(-1.0, 1.0), st.sampled_from([np.nan, np.inf, -np.inf, 1e300]))
inputs = st.one_of(st.none(), st.tuples(anything, st.tuples(anything, anything, anything),
                                        st.tuples(anything, anything, anything),
                                        st.floats(-0.01, 0.02)))


@settings(max_examples=examples(60), deadline=None)
@given(st.lists(inputs, min_size=1, max_size=40), st.booleans())
def test_whatever_arrives_the_force_is_finite_and_within_the_limit(sequence, passivity):
    pipeline = ForcePipeline(SpringDamper(1e5, 5.0),
                             PipelineConfig(force_limit=3.0, passivity=passivity))
    for step, item in enumerate(sequence):
        now = step * 1e-3
        contact = velocity = None
        if item is not None:
            height, tip, velocity, lag = item
            contact = Contact(height, (tip[0], tip[1], tip[2] + height), UP, tip, 'wall',
                              now - lag)
        force = pipeline.step(contact, velocity, now)
        assert np.all(np.isfinite(force)) and np.linalg.norm(force) <= 3.0 * (1 + 1e-12)
        if pipeline.last_reason is not Reason.OK:
            np.testing.assert_array_equal(force, np.zeros(3))


@pytest.mark.parametrize('field, value', [('force_limit', -1.0), ('max_damping', math.nan),
                                          ('servo_period', 0.0), ('timeout', -0.01)])
def test_bad_config_names_the_field(field, value):
    with pytest.raises(ForceRendererError, match=f'PipelineConfig.{field}'):
        PipelineConfig(**{field: value})


# Extreme cases in closed loop (virtual wall, 1 kHz zero-order hold unless stated).
CORNER = np.array([0.05, 0.05, 0.05])
DIAGONAL = np.ones(3) / np.sqrt(3.0)


def press(depth, start_height=0.005):
    """Hand target: from `start_height` to `depth` below z = 0 in 0.1 s, hold, lift at 0.8 s."""
    def target(t):
        height = start_height - (start_height + depth) * min(t / 0.1, 1.0)
        if t > 0.8:
            height = -depth + (depth + 0.03) * min((t - 0.8) / 0.2, 1.0)
        return np.array([0.0, 0.0, height])
    return target


def into_corner(t):
    """Hand target: 20 mm into a cube's corner along its diagonal, where the nearest face flips."""
    reach = 0.005 - 0.025 * min(t / 0.1, 1.0)
    if t > 0.8:
        reach = -0.020 + 0.050 * min((t - 0.8) / 0.2, 1.0)
    return CORNER + reach * DIAGONAL


SCENARIOS = {
    'fast approach, 1 m/s': dict(target=press(0.010), start=(0.0, 0.0, 0.02),
                                 start_velocity=(0.0, 0.0, -1.0)),
    'deep penetration, > 5 cm': dict(target=press(0.20)),
    'grazing contact': dict(target=lambda t: np.array([0.2 * t, 0.0, -0.0002]),
                            start=(0.0, 0.0, 0.0005), start_velocity=(0.2, 0.0, 0.0)),
    'normal flips at a corner': dict(wall=Box(-CORNER, CORNER), target=into_corner,
                                     start=CORNER + 0.005 * DIAGONAL),
    'jitter, 1-5 ms periods': dict(target=press(0.010), timing=ServoTiming(jitter=0.004)),
    'missing messages, 30 %': dict(target=press(0.010),
                                   timing=ServoTiming(drop_probability=0.3)),
}


def run_scenario(stiffness, wall=HalfSpace(), target=None, start=(0.0, 0.0, 0.005),
                 start_velocity=(0.0, 0.0, 0.0), timing=ServoTiming()):
    pipeline = ForcePipeline(SpringDamper(stiffness, 0.8), PipelineConfig(force_limit=10.0))
    return simulate(pipeline.step, wall, Device(0.15, 1.0), OperatorHand(300.0, 1.0, target),
                    duration=1.2, start=np.array(start), start_velocity=np.array(start_velocity),
                    timing=timing, seed=7)


@pytest.mark.parametrize('stiffness', [5000.0, 1e5])
@pytest.mark.parametrize('name', SCENARIOS)
def test_extreme_cases_stay_bounded_and_finite(name, stiffness):
    run = run_scenario(stiffness, **SCENARIOS[name])
    assert np.all(np.isfinite(run.force)) and np.all(np.isfinite(run.position))
    assert np.linalg.norm(run.force, axis=1).max() <= 10.0 * (1 + 1e-12)
    if name == 'deep penetration, > 5 cm':
        assert run.position[:, 2].min() < -0.05
    if stiffness == 5000.0:
        # Passive too, 12 times over the 400 N/m bound. At 1e5 N/m only boundedness is claimed;
        # measured there: 13 mJ generated with 5 ms periods (they would need K·T/2 = 250 N·s/m,
        # max_damping is 100), 2.6 mJ leaving deep penetration, 1.5 mJ with dropped messages.
        assert -run.port_energy[-1] <= 0.0


@pytest.mark.parametrize('status, reason', [
    (STATUS_NO_OBJECT, Reason.NO_OBJECT),
    (STATUS_INVALID_INPUT, Reason.REFUSED),
])
def test_a_state_the_engine_could_not_answer_gives_zero_force(status, reason):
    pipeline = ForcePipeline(SpringDamper(1000.0, 0.0))
    pipeline.step(wall_contact(-0.003, 1.0), None, 1.0)
    contact = Contact(-0.003, (0.0, 0.0, 0.0), UP, (0.0, 0.0, -0.003), 'wall', 1.001, status)
    np.testing.assert_array_equal(pipeline.step(contact, None, 1.001), np.zeros(3))
    assert pipeline.last_reason is reason
    np.testing.assert_allclose(pipeline.step(wall_contact(-0.003, 1.002), None, 1.002),
                               [0.0, 0.0, 3.0], rtol=1e-9)  # the next answered state renders


def test_an_unconverged_distance_is_rendered_as_the_upper_bound_it_is():
    """The bound is above the true distance, so the depth and the force are never larger."""
    pipeline = ForcePipeline(SpringDamper(1000.0, 0.0), PipelineConfig(passivity=False))
    contact = Contact(-0.002, (0.0, 0.0, 0.0), UP, (0.0, 0.0, -0.002), 'wall', 1.0,
                      STATUS_NOT_CONVERGED)
    np.testing.assert_allclose(pipeline.step(contact, None, 1.0), [0.0, 0.0, 2.0], rtol=1e-9)
    assert pipeline.last_reason is Reason.OK
