"""The local model the renderer sends: per law, and its error on a curved surface.

The cylinder is analytic here (its side, radius R about the z axis): a tip at depth d whose
model is the tangent plane, then moved s along the surface's tangent, is truly
R - sqrt((R - d)² + s²) deep, while the plane still says d: an error of at most s²/(2(R - d)),
the bound ``docs/local_rendering.md`` states and ``valid_radius`` limits.
"""
import math

import numpy as np
import pytest

from force_renderer.contact import Contact
from force_renderer.local_model import FREE, local_model, PLANES, UNAVAILABLE
from force_renderer.spring_damper import CentroidSpringDamper, SpringDamper

R = 0.025  # [m]


def cylinder_contact(tip) -> Contact:
    """The contact of a tip with the side of an infinite cylinder of radius R about z."""
    tip = np.asarray(tip, dtype=float)
    radial = np.array([tip[0], tip[1], 0.0])
    normal = radial / np.linalg.norm(radial)
    return Contact(np.linalg.norm(radial) - R, R * normal + [0.0, 0.0, tip[2]], normal, tip)


@pytest.mark.parametrize('depth', [0.0005, 0.001, 0.003])
@pytest.mark.parametrize('move', [1e-4, 5e-4, 1e-3, 2e-3])
def test_the_plane_s_error_on_a_cylinder_is_the_sagitta(depth, move):
    tip = np.array([R - depth, 0.0, 0.0])
    model = local_model(SpringDamper(1000.0, 0.0), cylinder_contact(tip), True, 0.005)
    (point, normal, _, _), = model.planes
    moved = tip + [0.0, move, 0.0]  # along the tangent
    plane_depth = np.dot(normal, np.subtract(point, moved))
    true_depth = R - math.hypot(R - depth, move)
    assert plane_depth == pytest.approx(depth, abs=1e-15)
    error = plane_depth - true_depth
    assert 0.0 < error <= move ** 2 / (2.0 * (R - depth)) * (1.0 + 1e-9)


def test_each_law_sends_what_it_can():
    near = cylinder_contact([R + 0.0002, 0.0, 0.0])  # outside by 0.2 mm
    assert local_model(SpringDamper(1e3, 1.0), near, True, 5e-4).kind == PLANES
    far = local_model(SpringDamper(1e3, 1.0), cylinder_contact([R + 0.003, 0.0, 0.0]), True,
                      5e-4)
    assert far.kind == FREE and far.valid_radius == pytest.approx(0.003)
    centroid = CentroidSpringDamper(1e3, 1.0, (0.0, 0.0, 0.0))
    assert local_model(centroid, near, True, 5e-4).kind == UNAVAILABLE
    refused = local_model(SpringDamper(1e3, 1.0), near, False, 5e-4)
    assert refused.kind == FREE and refused.valid_radius == 0.0
