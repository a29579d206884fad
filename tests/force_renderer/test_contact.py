"""Contact: the penetration vector and the checks at construction."""

import numpy as np
import pytest

from force_renderer.contact import Contact
from force_renderer.errors import ForceRendererError


def test_penetration_points_from_tip_to_surface_inside():
    contact = Contact(-0.002, (0.0, 0.0, 0.05), (0.0, 0.0, 1.0), (0.0, 0.0, 0.048), 'box', 3.0)
    assert contact.in_contact
    np.testing.assert_allclose(contact.penetration, [0.0, 0.0, 0.002], atol=1e-15)
    assert np.linalg.norm(contact.penetration) == pytest.approx(-contact.distance)


@pytest.mark.parametrize('distance', [0.0, 0.003])
def test_penetration_is_zero_on_and_outside_the_surface(distance):
    contact = Contact(distance, (0.0, 0.0, 0.05), (0.0, 0.0, 1.0), (0.0, 0.0, 0.05 + distance))
    assert not contact.in_contact
    np.testing.assert_array_equal(contact.penetration, np.zeros(3))


def test_fields_are_read_only_float_arrays():
    contact = Contact(-1, [0, 0, 0], [1, 0, 0], [-1, 0, 0], 'cube', 2)
    assert contact.point.dtype == np.float64 and contact.stamp == 2.0
    with pytest.raises(ValueError):
        contact.tip[0] = 5.0
    with pytest.raises(AttributeError):
        contact.distance = 1.0


def test_from_floats_is_the_contact_the_constructor_builds():
    values = (-0.002, (0.1, 0.2, 0.05), (0.0, 0.6, 0.8), (0.1, 0.2, 0.048), 'box', 3.5, 1, None)
    fast, checked = Contact.from_floats(*values), Contact(*values)
    for name in ('distance', 'object', 'stamp', 'status', 'face'):
        assert getattr(fast, name) == getattr(checked, name)
    for name in ('point', 'normal', 'tip'):
        vector = getattr(fast, name)
        np.testing.assert_array_equal(vector, getattr(checked, name))
        assert vector.dtype == np.float64 and not vector.flags.writeable
    np.testing.assert_array_equal(fast.penetration, checked.penetration)
    with pytest.raises(AttributeError):
        fast.distance = 1.0


def test_nan_is_carried_not_rejected():
    contact = Contact(float('nan'), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, np.nan, 0.0))
    assert np.isnan(contact.distance) and np.isnan(contact.tip[1])


@pytest.mark.parametrize('field, value', [('point', (0.0, 0.0)), ('normal', 'abc'),
                                          ('tip', np.zeros((3, 1)))])
def test_wrong_shape_names_the_field(field, value):
    arguments = {'distance': 0.0, 'point': np.zeros(3), 'normal': np.zeros(3), 'tip': np.zeros(3)}
    arguments[field] = value
    with pytest.raises(ForceRendererError, match=f'Contact.{field}'):
        Contact(**arguments)
