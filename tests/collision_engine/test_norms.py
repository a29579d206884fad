"""Scale-safe norms and unit vectors, against 60-digit decimal arithmetic."""

from decimal import Decimal
import math

from ground_truth.distances import exact_norm, exact_unit
from hypothesis import example, given
from hypothesis import strategies as st
import numpy as np
import pytest

from collision_engine.norms import norm2, norm3, scaled3, unit2, unit3

EPS = float(np.finfo(np.float64).eps)
# Every finite float64, subnormals and the largest included.
components = st.floats(allow_nan=False, allow_infinity=False)


@given(components, components, components)
@example(3.07e-161, 3.07e-161, 1.0)
@example(5e-324, -5e-324, 5e-324)
@example(1e300, -1e300, 1e300)
@example(1e-300, 5e-324, -1e300)
def test_norm3_is_exact_to_rounding_at_any_magnitude(x, y, z):
    exact = exact_norm((x, y, z))
    found = norm3(x, y, z)
    if math.isinf(float(exact)):  # beyond the largest float64, after rounding
        assert found == math.inf
        return
    # Two roundings in the scaled path (division and square root) and one in the result; a
    # subnormal result can be no closer than its spacing, 5e-324.
    assert abs(Decimal(found) - exact) <= Decimal(3 * EPS) * exact + Decimal(5e-324)


@given(components, components, components)
@example(3.07e-161, 3.07e-161, 1.0)
@example(5e-324, 0.0, 0.0)
@example(-5e-324, 5e-324, 0.0)
@example(1e300, 1e300, -1e300)
@example(1e-300, -1e-300, 1e300)
def test_unit3_is_the_unit_vector_at_any_magnitude(x, y, z):
    unit = np.array(unit3(x, y, z))
    if x == y == z == 0.0:
        np.testing.assert_array_equal(unit, 0.0)
        return
    np.testing.assert_allclose(unit, exact_unit((x, y, z)), rtol=0, atol=4 * EPS)
    assert float(exact_norm(unit)) == pytest.approx(1.0, abs=4 * EPS)


@given(components, components)
@example(3.07e-161, 3.07e-161)
@example(1e300, -1e300)
def test_two_dimensional_forms_agree_with_the_three_dimensional_ones(x, y):
    assert norm2(x, y) == norm3(x, y, 0.0)
    assert unit2(x, y) == unit3(x, y, 0.0)[:2]


@given(components, components, components)
def test_scaled3_keeps_the_direction_and_a_largest_component_of_one(x, y, z):
    scaled = np.array(scaled3(x, y, z))
    if x == y == z == 0.0:
        np.testing.assert_array_equal(scaled, 0.0)
        return
    assert np.max(np.abs(scaled)) == 1.0
    np.testing.assert_allclose(exact_unit(scaled), exact_unit((x, y, z)), rtol=0,
                               atol=4 * EPS)


@pytest.mark.parametrize('vector, direction', [
    ((math.inf, 1.0, 0.0), (1.0, 0.0, 0.0)),
    ((-math.inf, math.inf, 1e300), (-1.0, 1.0, 0.0)),
    ((5e-324, 0.0, -math.inf), (0.0, 0.0, -1.0)),
])
def test_infinite_components_give_their_limit_direction(vector, direction):
    assert scaled3(*vector) == direction
    np.testing.assert_allclose(unit3(*vector), np.array(direction) / np.linalg.norm(direction),
                               rtol=0, atol=EPS)
    assert norm3(*vector) == math.inf


@pytest.mark.parametrize('vector', [(math.nan, 1.0, 0.0), (0.0, 0.0, math.nan),
                                    (math.nan, math.inf, 1.0)])
def test_nan_has_no_direction_and_no_norm(vector):
    assert scaled3(*vector) == (0.0, 0.0, 0.0)
    assert unit3(*vector) == (0.0, 0.0, 0.0)
    assert math.isnan(norm3(*vector))
