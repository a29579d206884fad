"""The probe's face law: force and torque of a point shell on a plane, against analytic values.

The ground truth here builds its own face grid and measures its own plane: it shares no code with
the collision engine's face shell or the law. The discrete sums are written as sums over the
points; the continuous face's values are the closed-form integrals over the pressed part
(``ground_truth.probe_face``).
"""

import math

from fuzzing import examples
from ground_truth.probe_face import continuous_face
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from force_renderer.contact import Contact, FaceContact
from force_renderer.pipeline import ForcePipeline, PipelineConfig
from force_renderer.probe import equivalent_points, ProbeSpringDamper
from force_renderer.watchdog import Reason

K, C = 1000.0, 2.0
WIDTH, LENGTH = 0.01, 0.04  # m: the face along x and along y


def grid(columns: int, rows: int, width: float = WIDTH, length: float = LENGTH) -> np.ndarray:
    """Cell centres of a face of ``columns`` x ``rows`` cells, at z = 0 of the tip frame."""
    xs = [(i + 0.5) * width / columns - 0.5 * width for i in range(columns)]
    ys = [(j + 0.5) * length / rows - 0.5 * length for j in range(rows)]
    return np.array([[x, y, 0.0] for x in xs for y in ys])


def roll_yaw(roll: float, yaw: float = 0.0) -> np.ndarray:
    """Rz(yaw) Rx(roll): the wand's orientation."""
    c, s = math.cos(roll), math.sin(roll)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def on_plane(face: np.ndarray, rotation: np.ndarray, tip, height: float = 0.0,
             normal=(0.0, 0.0, 1.0)) -> Contact:
    """The face at ``tip`` turned by ``rotation`` over the plane n·x = height."""
    normal = np.asarray(normal, dtype=float)
    points = np.asarray(tip) + face @ rotation.T
    distance = points @ normal - height
    face_contact = FaceContact(distance, points, np.tile(normal, (len(face), 1)), rotation)
    return Contact(distance.min(), points[distance.argmin()] - distance.min() * normal, normal,
                   tip, 'plane', face=face_contact)


def point_sum(face: np.ndarray, rotation: np.ndarray, tip, height: float = 0.0):
    """The shell's force and torque on the plane z = height, point by point (no velocity)."""
    force, torque = np.zeros(3), np.zeros(3)
    for local in face:
        arm = rotation @ local
        depth = height - (tip[2] + arm[2])
        if depth > 0.0:
            f = np.array([0.0, 0.0, K * depth / len(face)])
            force += f
            torque += np.cross(arm, f)
    return force, torque


@pytest.mark.parametrize('cells', [(1, 1), (2, 8), (4, 16), (10, 40)])
def test_a_flush_face_pushes_k_depth_and_no_torque_at_any_point_count(cells):
    law = ProbeSpringDamper(K, C)
    force = law.force(on_plane(grid(*cells), np.eye(3), (0.0, 0.0, -0.002)), (0.0, 0.0, 0.0))
    np.testing.assert_allclose(force, [0.0, 0.0, K * 0.002], rtol=1e-12)
    np.testing.assert_allclose(law.torque(None), [0.0, 0.0, 0.0], atol=1e-15)


@pytest.mark.parametrize('theta', [0.05, 0.2, -0.2, 0.35])
def test_a_rolled_face_fully_pressed_gets_minus_k_cos_sin_mean_y2(theta):
    face = grid(2, 8)
    law = ProbeSpringDamper(K, C)
    depth = 0.5 * LENGTH * abs(math.sin(theta)) + 0.001  # every point pressed
    force = law.force(on_plane(face, roll_yaw(theta), (0.0, 0.0, -depth)), (0.0, 0.0, 0.0))
    mean_y2 = np.mean(face[:, 1] ** 2)
    assert mean_y2 == pytest.approx(LENGTH ** 2 / 12 * (1 - 1 / 8 ** 2), rel=1e-12)
    np.testing.assert_allclose(force, [0.0, 0.0, K * depth], rtol=1e-12)
    expected = -K * math.cos(theta) * math.sin(theta) * mean_y2
    np.testing.assert_allclose(law.torque(None), [expected, 0.0, 0.0], rtol=1e-12, atol=1e-15)


@given(theta=st.floats(-0.4, 0.4), depth=st.floats(0.0, 0.01), yaw=st.floats(-3.0, 3.0),
       x=st.floats(-0.1, 0.1))
@settings(max_examples=examples(100), deadline=None)
def test_the_law_is_the_sum_over_the_points(theta, depth, yaw, x):
    face = grid(2, 8)
    rotation = roll_yaw(theta, yaw)
    tip = (x, 0.0, -depth)
    law = ProbeSpringDamper(K, C)
    force = law.force(on_plane(face, rotation, tip), (0.0, 0.0, 0.0))
    expected_force, expected_torque = point_sum(face, rotation, tip)
    np.testing.assert_allclose(force, expected_force, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(law.torque(None), expected_torque, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize(('theta', 'depth'), [(0.2, 0.01), (0.35, 0.002), (0.1, 0.0005)])
def test_a_fine_face_converges_to_the_continuous_integral(theta, depth):
    """Fully and partly pressed; the midpoint sum's error is a cell's share at the kink."""
    face = grid(1, 2000)
    law = ProbeSpringDamper(K, C)
    force = law.force(on_plane(face, roll_yaw(theta), (0.0, 0.0, -depth)), (0.0, 0.0, 0.0))
    expected_force, expected_torque = continuous_face(depth, theta, LENGTH, K)
    assert force[2] == pytest.approx(expected_force, rel=1e-3)
    assert law.torque(None)[0] == pytest.approx(expected_torque, rel=1e-3)
    assert law.torque(None)[0] < 0.0  # restoring: the pressed low side turns the face back


def test_mirror_tilts_give_mirror_torques():
    law = ProbeSpringDamper(K, C)
    torques = []
    for theta in (0.25, -0.25):
        law.force(on_plane(grid(2, 8), roll_yaw(theta), (0.0, 0.0, -0.003)), (0.0, 0.0, 0.0))
        torques.append(law.torque(None))
    np.testing.assert_allclose(torques[0], -np.array(torques[1]), rtol=1e-12, atol=1e-15)


def test_yaw_on_a_flat_surface_gives_no_torque_about_z():
    law = ProbeSpringDamper(K, C)
    law.force(on_plane(grid(2, 8), roll_yaw(0.0, 0.7), (0.01, -0.02, -0.003)), (0.0, 0.0, 0.0))
    assert law.torque(None)[2] == pytest.approx(0.0, abs=1e-15)


def test_a_face_off_the_surface_pushes_nothing():
    law = ProbeSpringDamper(K, C)
    contact = on_plane(grid(2, 8), roll_yaw(0.3), (0.0, 0.0, 0.02))
    np.testing.assert_array_equal(law.force(contact, (0.0, 0.0, 1.0)), [0.0, 0.0, 0.0])
    assert law.torque(contact) == (0.0, 0.0, 0.0) and law.axis(contact) is None


def test_each_point_has_1_over_n_of_the_damping_and_never_pulls():
    law = ProbeSpringDamper(K, C)
    contact = on_plane(grid(2, 8), np.eye(3), (0.0, 0.0, -0.001))
    np.testing.assert_allclose(law.force(contact, (0.0, 0.0, -0.1)), [0.0, 0.0, 1.0 + C * 0.1],
                               rtol=1e-12)
    np.testing.assert_allclose(law.force(contact, (0.0, 0.0, 10.0)), [0.0, 0.0, 0.0], atol=1e-15)


def test_per_axis_stiffness_acts_along_the_plane_normal():
    law = ProbeSpringDamper((300.0, 200.0, 100.0), 0.0)
    rotation = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # face to +x
    contact = on_plane(grid(2, 8), rotation, (0.002, 0.0, 0.0), normal=(-1.0, 0.0, 0.0))
    np.testing.assert_allclose(law.force(contact, (0.0, 0.0, 0.0)), [-300.0 * 0.002, 0.0, 0.0],
                               rtol=1e-12)


def test_without_a_face_it_is_the_normal_law():
    law = ProbeSpringDamper(K, C)
    contact = Contact(-0.002, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, -0.002))
    np.testing.assert_allclose(law.force(contact, (0.0, 0.0, 0.0)), [0.0, 0.0, 2.0])
    assert law.torque(contact) == (0.0, 0.0, 0.0)


def test_equivalent_points_keep_the_mean_and_covariance():
    arms = np.random.default_rng(1).normal(size=(16, 3)) * [0.01, 0.02, 0.0] + [0.0, 0.0, 0.03]
    points = equivalent_points(arms)
    np.testing.assert_allclose(points.mean(axis=0), arms.mean(axis=0), atol=1e-15)
    centred, spread = points - points.mean(axis=0), arms - arms.mean(axis=0)
    np.testing.assert_allclose(centred.T @ centred / 3, spread.T @ spread / 16, atol=1e-15)


def test_the_pipeline_scales_the_torque_with_the_saturated_force_and_zeroes_it_with_it():
    pipeline = ForcePipeline(ProbeSpringDamper(K, C),
                             PipelineConfig(force_limit=2.0, passivity=False))
    contact = on_plane(grid(2, 8), roll_yaw(0.2), (0.0, 0.0, -0.006))
    raw_force, raw_torque = point_sum(grid(2, 8), roll_yaw(0.2), (0.0, 0.0, -0.006))
    force = pipeline.step(contact, (0.0, 0.0, 0.0), 0.0)
    np.testing.assert_allclose(force, [0.0, 0.0, 2.0], rtol=1e-12)
    np.testing.assert_allclose(pipeline.last_torque, raw_torque * 2.0 / raw_force[2], rtol=1e-12)
    pipeline.step(contact, (0.0, 0.0, 0.0), 1.0)  # a second old: stale
    assert pipeline.last_reason is not Reason.OK and pipeline.last_torque == (0.0, 0.0, 0.0)


def device_wrench(planes, tip, roll: float):
    """The wand's own rendering of the model's planes (``haptic_contract.contact_model``)."""
    from haptic_contract.contact_model import ContactModel, Kind, Plane

    model = ContactModel(0.0, Kind.PLANES, tuple(Plane(*plane) for plane in planes), 10.0, 1.0,
                         1.0, tuple(tip), (0.0,) * 6)
    return model.wrench(tip, (0.0, 0.0, 0.0), roll, 0.0, (0.0, 0.0, 0.0))


@pytest.mark.parametrize(('theta', 'turn'), [(0.1, 0.0), (0.1, 0.03), (-0.2, -0.05),
                                             (0.0, 0.1)])
def test_the_three_plane_model_renders_the_face_s_wrench_while_the_same_points_press(theta,
                                                                                     turn):
    """Exact at the model's pose and after a turn that keeps every point pressed."""
    face, tip = grid(2, 8), (0.003, -0.001, -0.012)
    law = ProbeSpringDamper(K, C)
    planes = law.planes(on_plane(face, roll_yaw(theta), tip))
    assert len(planes) == 3
    force, torque = device_wrench(planes, tip, theta + turn)
    expected_force, expected_torque = point_sum(face, roll_yaw(theta + turn), tip)
    np.testing.assert_allclose(force, expected_force, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(torque, expected_torque, rtol=1e-9, atol=1e-12)


def test_a_face_off_the_surface_models_the_whole_face():
    face, tip = grid(2, 8), (0.0, 0.0, 0.0005)
    planes = ProbeSpringDamper(K, C).planes(on_plane(face, roll_yaw(0.0), tip))
    pressed = (0.0, 0.0, -0.001)  # the device moves 1.5 mm down before the next state
    force, torque = device_wrench(planes, pressed, 0.0)
    np.testing.assert_allclose(force, [0.0, 0.0, K * 0.001], rtol=1e-9)
    np.testing.assert_allclose(torque, [0.0, 0.0, 0.0], atol=1e-12)
