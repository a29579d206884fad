"""The shared argument checks: what they accept, what they refuse, and the arrays they return."""
import math

import numpy as np
import pytest

from haptic_contract.checks import (finite_components, finite_number, finite_vector,
                                    read_only_vector, within_box)


@pytest.mark.parametrize('value', [np.array([1.0, -2.0, 3.5]), (1.0, -2.0, 3.5), [1, -2, 3.5],
                                   np.array([1, -2, 3.5], dtype=np.float32),
                                   np.array([1.0, -2.0, 3.5, 9.0])[:3]])
def test_finite_components_and_vector_take_any_three_numbers(value):
    components = finite_components(value, 3, 'force')
    assert components == (1.0, -2.0, 3.5) and all(type(c) is float for c in components)
    vector = finite_vector(value, 3, 'force')
    assert vector.dtype == np.float64 and not vector.flags.writeable
    np.testing.assert_array_equal(vector, [1.0, -2.0, 3.5])


@pytest.mark.parametrize('value', [np.array([1.0, np.nan, 0.0]), (np.inf, 0.0, 0.0),
                                   np.zeros(2), np.zeros((3, 1)), np.zeros((1, 3)), [[1.0], 2, 3],
                                   'abc', None, 3.0, [1.0, 'x', 2.0]])
def test_finite_components_and_vector_refuse_naming_the_field(value):
    for check in (finite_components, finite_vector):
        with pytest.raises(ValueError, match='torque must be 3 finite numbers'):
            check(value, 3, 'torque')


def test_the_vector_is_a_copy():
    source = np.array([1.0, 2.0, 3.0])
    vector = finite_vector(source, 3, 'v')
    source[0] = 9.0
    assert vector[0] == 1.0


def test_read_only_vector_holds_the_floats_and_refuses_writes():
    vector = read_only_vector([0.5, -1.0, 2.0, 4.0, 8.0])
    np.testing.assert_array_equal(vector, [0.5, -1.0, 2.0, 4.0, 8.0])
    assert vector.dtype == np.float64
    with pytest.raises(ValueError):
        vector[0] = 0.0


@pytest.mark.parametrize('value, options', [(np.nan, {}), ('x', {}), (-1.0, dict(minimum=0.0)),
                                            (0.0, dict(minimum=0.0, strict=True))])
def test_checked_number_refuses_naming_the_field(value, options):
    with pytest.raises(ValueError, match='rate must be finite'):
        finite_number(value, 'rate', **options)


def test_checked_number_returns_a_float():
    assert finite_number(np.float32(0.5), 'rate', minimum=0.0) == 0.5
    assert type(finite_number(3, 'rate')) is float


@pytest.mark.parametrize('point, margin, inside', [
    ((0.0, 0.0, 0.0), 0.0, True),
    ((0.1, -0.1, 0.05), 0.0, True),  # on the walls
    ((0.1001, 0.0, 0.0), 0.0, False),
    ((0.1001, 0.0, 0.0), 2e-3, True),
    ((0.0, -0.1021, 0.0), 2e-3, False),
    ((0.0, 0.0, math.nan), 1.0, False),
    (np.array([0.0, 0.0, 0.06]), 0.0, False),
])
def test_within_box_takes_the_walls_and_the_margin_and_refuses_nan(point, margin, inside):
    assert within_box(point, (-0.1, -0.1, -0.05), (0.1, 0.1, 0.05), margin) is inside
