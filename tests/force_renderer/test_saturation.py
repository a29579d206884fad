"""Saturation keeps the direction, respects the limit, and lets nothing non-finite through."""

from fuzzing import examples
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from force_renderer.errors import ForceRendererError, saturate

# Forces from a nanonewton to a meganewton: squares stay far from underflow and overflow.
components = st.one_of(st.just(0.0), st.floats(1e-9, 1e6), st.floats(-1e6, -1e-9))
limits = st.one_of(st.just(0.0), st.floats(1e-6, 50.0))


@settings(max_examples=examples(200), deadline=None)
@given(st.tuples(components, components, components), limits)
def test_saturated_force_keeps_direction_and_respects_limit(force, limit):
    force = np.array(force)
    result = saturate(force, limit)
    magnitude = np.sqrt(np.sum(force ** 2))
    if magnitude <= limit:
        np.testing.assert_array_equal(result, force)
        return
    assert np.sqrt(np.sum(result ** 2)) == pytest.approx(limit, rel=1e-12, abs=1e-300)
    np.testing.assert_allclose(result, force * (limit / magnitude), rtol=1e-12, atol=1e-300)


def test_worked_example():
    np.testing.assert_allclose(saturate([30.0, 0.0, 40.0], 10.0), [6.0, 0.0, 8.0])


@pytest.mark.parametrize('bad', [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize('axis', [0, 1, 2])
def test_non_finite_component_gives_zero(bad, axis):
    force = np.array([1.0, 2.0, 3.0])
    force[axis] = bad
    np.testing.assert_array_equal(saturate(force, 10.0), np.zeros(3))


def test_huge_finite_force_is_scaled_not_zeroed():
    np.testing.assert_allclose(saturate([1e300, 0.0, 1e300], 2.0), [np.sqrt(2), 0, np.sqrt(2)])


@pytest.mark.parametrize('limit', [-1.0, np.nan, np.inf])
def test_bad_limit_is_rejected(limit):
    with pytest.raises(ForceRendererError, match='limit'):
        saturate([1.0, 0.0, 0.0], limit)


def test_wrong_shape_is_rejected():
    with pytest.raises(ForceRendererError, match='force'):
        saturate([1.0, 0.0], 1.0)
