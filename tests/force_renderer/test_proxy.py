"""God-object proxy: it stays on the surface it entered, so the force never flips."""

from analytic_fields import Box, contact_with, Sphere, Union
from ground_truth.distances import angle_between
from ground_truth.virtual_wall import Device, OperatorHand, simulate
import numpy as np
import pytest

from force_renderer.errors import ForceRendererError
from force_renderer.pipeline import ForcePipeline
from force_renderer.proxy import GodObjectProxy
from force_renderer.spring_damper import SpringDamper

STIFFNESS = 1000.0
PLATE = Box([-0.05, -0.05, -0.001], [0.05, 0.05, 0.001])              # 2 mm thick, top z = 1 mm
FINGER_A = Box([-0.011, -0.05, -0.010], [-0.001, 0.05, 0.0])           # 10 mm wide, 10 mm tall
FINGER_B = Box([0.001, -0.05, -0.010], [0.011, 0.05, 0.0])             # 2 mm gap between them
FINGERS = Union(FINGER_A, FINGER_B)


def forces_along(field, path, law):
    return np.array([law.force(contact_with(field, tip), np.zeros(3)) for tip in path])


def line(start, end, count):
    return [np.asarray(start) + (np.asarray(end) - np.asarray(start)) * s
            for s in np.linspace(0.0, 1.0, count)]


def test_free_space_follows_the_tip_with_no_force():
    proxy = GodObjectProxy(STIFFNESS, 0.0, PLATE)
    for tip in line([0.0, 0.0, 0.05], [0.02, -0.01, 0.003], 20):
        np.testing.assert_array_equal(proxy.force(contact_with(PLATE, tip), np.zeros(3)),
                                      np.zeros(3))
        np.testing.assert_array_equal(proxy.proxy, tip)
    assert not proxy.touching


@pytest.mark.parametrize('count', [121, 9])   # 0.1 mm steps, and 1.5 mm jumps
def test_pushing_through_a_thin_plate_never_flips_the_force(count):
    path = line([0.0, 0.0, 0.005], [0.001, 0.0, -0.007], count)
    forces = forces_along(PLATE, path, GodObjectProxy(STIFFNESS, 0.0, PLATE))
    heights = np.array([tip[2] for tip in path])
    below_top = heights < 0.001
    np.testing.assert_array_equal(forces[~below_top], 0.0)
    # Always up, and exactly K times the depth below the top face, even past the plate.
    np.testing.assert_allclose(forces[below_top, 2], STIFFNESS * (0.001 - heights[below_top]),
                               rtol=1e-9)
    np.testing.assert_allclose(forces[:, :2], 0.0, atol=1e-9)


def test_penetration_rendering_flips_on_the_same_plate():
    path = line([0.0, 0.0, 0.005], [0.001, 0.0, -0.0009], 60)
    forces = forces_along(PLATE, path, SpringDamper(STIFFNESS, 0.0))
    assert forces[:, 2].max() > 0.0 and forces[:, 2].min() < 0.0


def test_pressing_into_a_finger_beside_the_gap_keeps_pushing_up():
    path = line([-0.002, 0.0, 0.003], [-0.002, 0.0, -0.008], 111)
    forces = forces_along(FINGERS, path, GodObjectProxy(STIFFNESS, 0.0, FINGERS))
    heights = np.array([tip[2] for tip in path])
    inside = heights < 0.0
    np.testing.assert_allclose(forces[inside, 2], -STIFFNESS * heights[inside], rtol=1e-9)
    np.testing.assert_allclose(forces[:, :2], 0.0, atol=1e-9)
    sideways = forces_along(FINGERS, path, SpringDamper(STIFFNESS, 0.0))
    assert sideways[inside, 0].max() > 0.0       # penetration rendering pushes into the gap


def test_sweeping_from_the_gap_into_a_finger_keeps_pushing_back_to_the_gap():
    path = line([0.0, 0.0, 0.003], [0.0, 0.0, -0.005], 81)[:-1] \
        + line([0.0, 0.0, -0.005], [0.0095, 0.0, -0.005], 96)
    forces = forces_along(FINGERS, path, GodObjectProxy(STIFFNESS, 0.0, FINGERS))
    lateral = np.array([tip[0] for tip in path])
    inside = lateral > 0.001
    np.testing.assert_allclose(forces[inside, 0], -STIFFNESS * (lateral[inside] - 0.001),
                               rtol=1e-9)
    np.testing.assert_array_equal(forces[~inside], 0.0)
    np.testing.assert_allclose(forces[:, 1:], 0.0, atol=1e-9)
    sideways = forces_along(FINGERS, path, SpringDamper(STIFFNESS, 0.0))
    assert sideways[inside, 0].max() > 0.0       # penetration rendering flips past mid-finger


def test_sliding_on_a_face_is_frictionless():
    proxy = GodObjectProxy(STIFFNESS, 0.0, PLATE)
    proxy.update([0.0, 0.0, 0.003])
    for tip in line([0.0, 0.0, 0.0005], [0.02, 0.01, 0.0002], 30):
        proxy.update(tip)
        np.testing.assert_allclose(proxy.proxy, [tip[0], tip[1], 0.001], atol=1e-12)


def test_on_a_sphere_the_proxy_settles_on_the_point_nearest_the_tip():
    sphere = Sphere([0.0, 0.0, 0.0], 0.03)
    proxy = GodObjectProxy(STIFFNESS, 0.0, sphere)
    proxy.update([0.0, 0.0, 0.05])
    tip = np.array([0.004, 0.003, 0.027])
    for _ in range(10):
        force = proxy.force(contact_with(sphere, tip), np.zeros(3))
    radial = tip / np.linalg.norm(tip)
    np.testing.assert_allclose(proxy.proxy, 0.03 * radial, atol=1e-7)
    assert angle_between(force, radial) < 0.01


def test_inside_corner_holds_the_proxy_on_both_faces():
    floor = Box([-0.05, -0.05, -0.02], [0.05, 0.05, 0.0])
    wall = Box([0.01, -0.05, 0.0], [0.03, 0.05, 0.05])
    corner = Union(floor, wall)
    proxy = GodObjectProxy(STIFFNESS, 0.0, corner)
    for tip in line([0.0, 0.0, 0.01], [0.012, 0.0, -0.002], 40):
        proxy.update(tip)
    np.testing.assert_allclose(proxy.proxy, [0.01, 0.0, 0.0], atol=1e-9)
    force = proxy.force(contact_with(corner, np.array([0.012, 0.0, -0.002])), np.zeros(3))
    np.testing.assert_allclose(force, [-2.0, 0.0, 2.0], rtol=1e-6)


def test_starts_on_the_surface_when_the_first_tip_is_inside_and_can_reset():
    proxy = GodObjectProxy(STIFFNESS, 0.0, PLATE)
    proxy.update([0.0, 0.0, 0.0004])
    np.testing.assert_allclose(proxy.proxy, [0.0, 0.0, 0.001])
    proxy.reset()
    assert proxy.proxy is None and not proxy.touching


def test_damping_never_pulls_the_tip_in():
    proxy = GodObjectProxy(STIFFNESS, 50.0, PLATE)
    proxy.update([0.0, 0.0, 0.003])
    tip = np.array([0.0, 0.0, 0.0009])
    force = proxy.force(contact_with(PLATE, tip), [0.3, 0.0, 2.0])
    assert force[2] == 0.0 and force[0] == pytest.approx(-50.0 * 0.3)
    force = proxy.force(contact_with(PLATE, tip), [0.0, 0.0, -0.01])
    assert force[2] == pytest.approx(STIFFNESS * 0.0001 + 50.0 * 0.01)


def test_a_proxy_lagging_in_free_space_exerts_no_force():
    proxy = GodObjectProxy(STIFFNESS, 0.0, PLATE, max_steps=1)
    proxy.update([0.0, 0.0, 0.05])
    tip = np.array([0.5, 0.0, 0.05])
    force = proxy.force(contact_with(PLATE, tip), np.zeros(3))
    assert np.linalg.norm(proxy.proxy - tip) > 0.1 and not proxy.touching
    np.testing.assert_array_equal(force, np.zeros(3))


def test_closed_loop_press_through_a_thin_plate_is_held_on_top_and_passive():
    """The hand pushes 20 mm below a 2 mm plate: past its middle, the force still points up."""
    def target(t):
        height = 0.005 - 0.025 * min(t / 0.1, 1.0)
        return np.array([0.0, 0.0, height if t < 0.5 else -0.020 + 0.08 * min(t - 0.5, 0.5)])

    pipeline = ForcePipeline(GodObjectProxy(5000.0, 0.8, PLATE))
    run = simulate(pipeline.step, PLATE, Device(0.15, 1.0), OperatorHand(300.0, 1.0, target),
                   duration=1.1, start=np.array([0.0, 0.0, 0.005]))
    assert run.position[:, 2].min() < 0.0    # past the middle, where penetration flips
    assert np.all(run.force[:, 2] >= 0.0)
    assert np.all(run.force[run.position[:, 2] < 0.0, 2] > 0.0)
    np.testing.assert_allclose(run.force[:, :2], 0.0, atol=1e-9)
    assert -run.port_energy[-1] <= 0.0


@pytest.mark.parametrize('option, value', [('min_step', 0.0), ('iterations', 0),
                                           ('max_steps', 2.5), ('tolerance', np.nan)])
def test_bad_options_name_the_argument(option, value):
    with pytest.raises(ForceRendererError, match=option):
        GodObjectProxy(STIFFNESS, 0.0, PLATE, **{option: value})
