"""The plane force law and saturation: one NaN rule, and the compiled servo loop held to them.

``haptic_wand_driver.servo_loop`` repeats the law in compiled code (a kernel there may not call
one elsewhere); the Python functions here are its reference, float for float.
"""
import math

from fuzzing import examples
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from haptic_contract.plane_law import saturate, saturate_components, unilateral_spring_damper
from haptic_wand_driver import servo_loop
from haptic_wand_driver.local_rendering import LAW_SIZE, PLANES_AT

anything = st.floats(allow_nan=True, allow_infinity=True)
component = st.floats(-1e3, 1e3)
gain = st.floats(0.0, 1e5)
vectors = st.tuples(component, component, component)


@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf])
def test_a_force_that_is_not_finite_saturates_to_zero(bad):
    for axis in range(3):
        force = [1.0, 2.0, 3.0]
        force[axis] = bad
        assert saturate_components(force, 10.0) == (0.0, 0.0, 0.0)
        assert saturate_components(force, math.inf) == (0.0, 0.0, 0.0)


def test_a_finite_force_whose_squares_overflow_is_scaled_to_the_limit():
    x, y, z = saturate_components((3e200, 0.0, -4e200), 10.0)
    assert (x, y, z) == pytest.approx((6.0, 0.0, -8.0), rel=1e-15)


def test_the_checked_form_names_what_is_wrong():
    with pytest.raises(ValueError, match='limit must be finite >= 0'):
        saturate([1.0, 0.0, 0.0], -1.0)
    with pytest.raises(ValueError, match=r'force must have shape \(3,\)'):
        saturate([1.0, 0.0], 1.0)


@settings(max_examples=examples(300), deadline=None)
@given(st.tuples(anything, anything, anything), st.floats(0.0, 1e300))
def test_the_compiled_saturation_is_the_python_one(force, limit):
    assert servo_loop._saturate(*force, limit) == saturate_components(force, limit)


@settings(max_examples=examples(300), deadline=None)
@given(st.floats(0.0, 0.05), st.tuples(component, component, component).filter(
    lambda n: math.hypot(*n) > 1e-3), vectors, st.tuples(gain, gain, gain),
    st.tuples(gain, gain, gain))
def test_the_compiled_plane_force_is_the_python_law(depth, direction, velocity, stiffness,
                                                    damping):
    """Without the device's own damping (ratio 0), one plane's force is the law's."""
    length = math.hypot(*direction)
    normal = tuple(c / length for c in direction)
    law = np.zeros(LAW_SIZE)  # law[2], the device's damping ratio, stays 0
    law[PLANES_AT + 3:PLANES_AT + 12] = (*normal, *stiffness, *damping)
    compiled = servo_loop._plane_force(law, PLANES_AT, depth, *velocity, math.inf, 0.001)
    reference = unilateral_spring_damper(tuple(depth * n for n in normal), normal, velocity,
                                         stiffness, damping)
    assert compiled == reference
