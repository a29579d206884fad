"""A sphere tip (the scene's ``tip_radius``): every law pushes back its depth r - d_centre.

The truth here is worked from the geometry of the paper's cuboid alone: a sphere of radius r
whose centre is d above the top face penetrates r - d, and a spring K pushes it back by
K (r - d) along +z. Issue: with K = 160 N/m and r = 1 mm, depths of 0.5, 1 and 1.5 mm gave
0, 0 and 0.08 N instead of 0.08, 0.16 and 0.24 N.
"""
from analytic_fields import Box, contact_with, inflated
import numpy as np
import pytest

from force_renderer.proxy import GodObjectProxy
from force_renderer.spring_damper import CentroidSpringDamper, SpringDamper

K = 160.0  # [N/m]
RADIUS = 0.001  # [m]
CENTRE = np.array([0.0, 0.0, -0.075])
HALF = np.array([0.05, 0.05, 0.1])
CUBOID = Box(CENTRE - HALF, CENTRE + HALF)
TOP = CENTRE[2] + HALF[2]
DEPTHS = [0.0005, 0.001, 0.0015]  # [m] of the sphere; the centre is outside for the first two


def tip_at_depth(depth: float) -> np.ndarray:
    """The sphere's centre above (or below) the top face so that it penetrates ``depth``."""
    return np.array([0.01, -0.02, TOP + RADIUS - depth])


@pytest.mark.parametrize('depth', DEPTHS)
def test_the_normal_law_pushes_back_the_sphere_s_depth(depth):
    contact = contact_with(CUBOID, tip_at_depth(depth), radius=RADIUS)
    np.testing.assert_allclose(SpringDamper(K, 0.0).force(contact, np.zeros(3)),
                               [0.0, 0.0, K * depth], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(contact.penetration, [0.0, 0.0, depth], rtol=1e-9, atol=1e-15)


@pytest.mark.parametrize('depth', DEPTHS)
def test_the_paper_law_scales_its_direction_by_the_sphere_s_depth(depth):
    tip = tip_at_depth(depth)
    radial = (tip - CENTRE) / np.linalg.norm(tip - CENTRE)
    contact = contact_with(CUBOID, tip, radius=RADIUS)
    force = CentroidSpringDamper(K, 0.0, CENTRE).force(contact, np.zeros(3))
    np.testing.assert_allclose(force, K * depth * radial, rtol=1e-9)


@pytest.mark.parametrize('depth', DEPTHS)
def test_the_proxy_holds_the_sphere_s_centre_on_the_inflated_surface(depth):
    proxy = GodObjectProxy(K, 0.0, inflated(CUBOID, RADIUS))
    above = tip_at_depth(0.0) + np.array([0.0, 0.0, 0.01])
    proxy.update(above)  # the tip comes down from free space
    tip = tip_at_depth(depth)
    for _ in range(5):
        force = proxy.force(contact_with(CUBOID, tip, radius=RADIUS), np.zeros(3))
    np.testing.assert_allclose(force, [0.0, 0.0, K * depth], rtol=1e-6, atol=1e-9)
