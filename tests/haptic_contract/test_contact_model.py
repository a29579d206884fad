"""The contact model as the device receives it: checked field by field, rendered per plane.

The expected forces are worked here from the plane's geometry (depth along the normal times the
stiffness), not by the toolkit's law.
"""
import math

from contact_model_fields import fields, plane
import numpy as np
import pytest

from haptic_contract.contact_model import ContactModel, Kind, ModelRefused


@pytest.mark.parametrize('change, field', [
    (dict(frame='map'), 'header.frame_id'),
    (dict(kind=7), 'kind'),
    (dict(count=4), 'plane_count'),
    (dict(planes=[plane(normal=(0.0, 0.0, 0.9))]), 'planes[0].normal'),
    (dict(planes=[plane(point=(0.0, math.nan, 0.0))]), 'planes[0].point'),
    (dict(planes=[plane(), plane(stiffness=-1.0)]), 'planes[1].stiffness'),
    (dict(planes=[plane(damping=math.inf)]), 'planes[0].damping'),
    (dict(valid_for=-0.01), 'valid_for'),
    (dict(radius=math.nan), 'valid_radius'),
    (dict(limit=-1.0), 'force_limit'),
    (dict(tip=(0.0, 0.0, math.inf)), 'tip'),
    (dict(wrench=(0.0, math.nan, 0.0, 0.0, 0.0, 0.0)), 'wrench'),
])
def test_a_bad_model_is_refused_naming_the_field(change, field):
    with pytest.raises(ModelRefused) as refused:
        ContactModel.from_fields(fields(**{'planes': [plane()], **change}), 'world')
    assert refused.value.field == field and field in str(refused.value)


def test_a_plane_pushes_its_depth_times_k_along_its_normal_and_never_pulls():
    model = ContactModel.from_fields(fields([plane(damping=2.0)]), 'world')
    force, torque = model.wrench((0.01, 0.0, -0.003), (0.0, 0.0, 0.0), 0.0, 0.0, (0, 0, 0))
    np.testing.assert_allclose(force, [0.0, 0.0, 3.0], rtol=1e-12)
    assert torque == (0.0, 0.0, 0.0)
    leaving, _ = model.wrench((0.0, 0.0, -0.001), (0.0, 0.0, 5.0), 0.0, 0.0, (0, 0, 0))
    assert leaving == (0.0, 0.0, 0.0)  # 1 N of spring, -10 N of damper: clipped, no pull
    outside, _ = model.wrench((0.0, 0.0, 0.001), (0.0, 0.0, -1.0), 0.0, 0.0, (0, 0, 0))
    assert outside == (0.0, 0.0, 0.0)


def test_a_tool_point_off_the_tip_is_pushed_and_gives_a_torque_about_the_tip():
    """A probe face corner 20 mm along x from the tip, yawed 90 degrees: it sits on +y."""
    corner = (0.02, 0.0, 0.0)
    model = ContactModel.from_fields(fields([plane(tool_point=corner)]), 'world')
    force, torque = model.wrench((0.0, 0.0, -0.001), (0.0, 0.0, 0.0), 0.0, math.pi / 2,
                                 (0.0, 0.0, 0.0))
    np.testing.assert_allclose(force, [0.0, 0.0, 1.0], atol=1e-12)
    lever = np.array([0.0, 0.02, 0.0])  # the corner, yawed onto +y
    np.testing.assert_allclose(torque, np.cross(lever, [0.0, 0.0, 1.0]), atol=1e-12)


def test_the_model_holds_within_its_radius_of_the_tip_it_was_made_for():
    model = ContactModel.from_fields(fields([plane()], radius=0.002, tip=(0.1, 0.0, 0.0)),
                                     'world')
    assert model.valid((0.1015, 0.0, 0.001)) and not model.valid((0.1, 0.0021, 0.0))
    assert model.stamp == 5.0 and model.kind is Kind.PLANES


def test_a_free_model_carries_no_planes():
    model = ContactModel.from_fields(fields([plane()], kind=Kind.FREE), 'world')
    assert model.planes == ()
