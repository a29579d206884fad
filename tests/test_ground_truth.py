"""The ground truth itself, checked against closed forms and hand-worked points."""

import ast
import math
from pathlib import Path

from fuzzing import examples
import ground_truth
from ground_truth.distances import (
    box_signed_distance,
    capsule_signed_distance,
    cylinder_signed_distance,
    hand_mesh_path,
    mesh_signed_distance,
    sample_near_surface,
    scene_path,
    sphere_signed_distance,
    winding_number,
)
from ground_truth.probe_face import continuous_face
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest
from scipy.spatial.transform import Rotation
import trimesh

# A cube of edge 1 centred at the origin, each face counter-clockwise seen from outside.
CUBE_VERTICES = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5)
                          for z in (-0.5, 0.5)])
CUBE_FACES = np.array([
    [0, 1, 3], [0, 3, 2],  # x = -0.5
    [4, 6, 7], [4, 7, 5],  # x = +0.5
    [0, 4, 5], [0, 5, 1],  # y = -0.5
    [2, 3, 7], [2, 7, 6],  # y = +0.5
    [0, 2, 6], [0, 6, 4],  # z = -0.5
    [1, 5, 7], [1, 7, 3],  # z = +0.5
])
UNIT = np.ones(3)
ROOT = Path(__file__).resolve().parents[1]
EXACT = 1e-15  # m: rounding in coordinates of order 1 m


def two_cubes(gap: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two unit cubes side by side along x with `gap` between them: non-convex across the gap."""
    shift = np.array([0.5 + 0.5 * gap, 0.0, 0.0])
    vertices = np.vstack([CUBE_VERTICES - shift, CUBE_VERTICES + shift])
    faces = np.vstack([CUBE_FACES, CUBE_FACES + len(CUBE_VERTICES)])
    return vertices, faces, shift


def test_cube_fixture_is_wound_outward():
    corners = CUBE_VERTICES[CUBE_FACES]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    assert np.all(np.sum(normals * corners.mean(axis=1), axis=1) > 0.0)


@pytest.mark.parametrize(('point', 'expected'), [
    ((0.0, 0.0, 0.0), -0.5),
    ((0.4, 0.0, 0.0), -0.1),
    ((0.5, 0.2, -0.3), 0.0),
    ((0.8, 0.0, 0.0), 0.3),
    ((0.8, 0.9, 0.0), 0.5),
    ((-0.8, 0.9, 1.1), np.sqrt(0.09 + 0.16 + 0.36)),
])
def test_box_known_points(point, expected):
    assert box_signed_distance(np.array(point), UNIT) == pytest.approx(expected, abs=EXACT)


def test_box_uses_full_edge_lengths():
    size = np.array([0.1, 0.1, 0.2])
    points = np.array([[0.0, 0.0, 0.1], [0.05, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.3]])
    np.testing.assert_allclose(box_signed_distance(points, size), [0.0, 0.0, -0.05, 0.2],
                               atol=EXACT)


def test_sphere_known_points():
    points = np.array([[0.0, 0.0, 0.0], [0.3, 0.4, 0.0], [0.0, 0.0, -2.0]])
    np.testing.assert_allclose(sphere_signed_distance(points, 0.5), [-0.5, 0.0, 1.5], atol=EXACT)


@pytest.mark.parametrize(('point', 'expected'), [
    ((0.0, 0.0, 0.0), -0.025),            # centre: the side is nearer than the caps
    ((0.0, 0.0, 0.045), -0.005),          # near the top cap
    ((0.0, 0.02, 0.0), -0.005),           # near the side
    ((0.0, 0.0, 0.08), 0.03),             # above the cap
    ((0.03, 0.04, 0.0), 0.025),           # beside the side
    ((0.0, 0.028, -0.054), 0.005),        # off the bottom rim: hypot(3 mm, 4 mm)
])
def test_cylinder_known_points(point, expected):
    assert cylinder_signed_distance(np.array(point), 0.025, 0.1) == pytest.approx(
        expected, abs=EXACT)


@pytest.mark.parametrize(('point', 'expected'), [
    ((0.0, 0.0, 0.0), -0.1),
    ((0.0, 0.3, 0.2), 0.2),               # beside the segment
    ((0.0, 0.0, 0.6), 0.2),               # above the end cap (segment end at z = 0.3)
    ((0.3, 0.4, -0.3), 0.4),              # off the bottom end, radially
])
def test_capsule_known_points(point, expected):
    assert capsule_signed_distance(np.array(point), 0.1, 0.6) == pytest.approx(
        expected, abs=EXACT)


def test_primitives_keep_leading_shape():
    points = np.zeros((4, 5, 3))
    assert box_signed_distance(points, UNIT).shape == (4, 5)
    assert cylinder_signed_distance(points, 1.0, 1.0).shape == (4, 5)
    assert mesh_signed_distance(points, CUBE_VERTICES, CUBE_FACES)[1].shape == (4, 5, 3)


@pytest.mark.parametrize('call', [
    lambda: box_signed_distance(np.zeros((2, 2)), UNIT),
    lambda: box_signed_distance(np.zeros(3), [1.0, 1.0]),
    lambda: box_signed_distance(np.zeros(3), [1.0, 0.0, 1.0]),
    lambda: sphere_signed_distance(np.zeros(3), -1.0),
    lambda: cylinder_signed_distance(np.zeros(3), 1.0, np.nan),
    lambda: mesh_signed_distance(np.zeros(3), CUBE_VERTICES, CUBE_FACES + 1),
    lambda: mesh_signed_distance(np.zeros(3), CUBE_VERTICES, np.array([[0, 1, 1]])),
    lambda: mesh_signed_distance(np.zeros(3), CUBE_VERTICES, CUBE_FACES.astype(float)),
])
def test_bad_input_is_a_value_error(call):
    with pytest.raises(ValueError):
        call()


def test_cube_mesh_matches_box_formula():
    points = np.random.default_rng(1).uniform(-1.5, 1.5, (3000, 3))
    distance, closest = mesh_signed_distance(points, CUBE_VERTICES, CUBE_FACES)
    np.testing.assert_allclose(distance, box_signed_distance(points, UNIT), rtol=0, atol=EXACT)
    np.testing.assert_allclose(np.linalg.norm(points - closest, axis=1), np.abs(distance),
                               rtol=0, atol=EXACT)
    np.testing.assert_allclose(box_signed_distance(closest, UNIT), 0.0, rtol=0, atol=EXACT)


@settings(max_examples=examples(40), deadline=None)
@given(rotation=st.integers(0, 2**32 - 1), size=st.tuples(*[st.floats(0.01, 0.3)] * 3),
       point=st.tuples(*[st.floats(-0.4, 0.4)] * 3))
def test_rotated_scaled_cube_mesh_matches_box_formula(rotation, size, point):
    turn = Rotation.random(random_state=rotation)
    vertices = turn.apply(CUBE_VERTICES * np.array(size))
    distance, closest = mesh_signed_distance(turn.apply(np.array(point)), vertices, CUBE_FACES)
    assert distance == pytest.approx(box_signed_distance(np.array(point), size), abs=1e-15)
    assert np.linalg.norm(closest - turn.apply(np.array(point))) == pytest.approx(
        abs(distance), abs=1e-15)


def test_icosphere_within_its_tessellation_error():
    # An inscribed convex mesh lies between the ball of its least face-plane distance and the
    # sphere through its vertices, and signed distance is monotone under inclusion.
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=1.0)
    corners = sphere.vertices[sphere.faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    inradius = np.min(np.sum(normals * corners[:, 0], axis=1))
    assert 0.998 < inradius < 1.0
    points = np.random.default_rng(2).uniform(-1.6, 1.6, (800, 3))
    distance, _ = mesh_signed_distance(points, sphere.vertices, sphere.faces)
    assert np.all(distance >= sphere_signed_distance(points, 1.0) - EXACT)
    assert np.all(distance <= sphere_signed_distance(points, inradius) + EXACT)


def test_winding_number_inside_and_outside():
    points = np.array([[0.0, 0.0, 0.0], [0.3, -0.2, 0.45], [2.0, 0.0, 0.0], [0.5, 3.0, 0.2]])
    winding = winding_number(points, CUBE_VERTICES, CUBE_FACES)
    np.testing.assert_allclose(winding, [1.0, 1.0, 0.0, 0.0], atol=1e-12)
    flipped = winding_number(points, CUBE_VERTICES, CUBE_FACES[:, ::-1])
    np.testing.assert_allclose(flipped, [-1.0, -1.0, 0.0, 0.0], atol=1e-12)


@pytest.mark.parametrize('surface_point', [
    (0.5, 0.1, -0.2),        # on a face
    (0.5, 0.25, 0.25),       # on the diagonal shared by a face's two triangles
    (0.5, 0.5, 0.3),         # on an edge
    (0.5, -0.5, 0.5),        # on a vertex
])
def test_winding_number_a_nanometre_off_the_surface(surface_point):
    outward = np.sign(surface_point) * (np.abs(surface_point) == 0.5)
    outward /= np.linalg.norm(outward)
    points = np.array(surface_point) + np.outer([-1e-9, 1e-9], outward)
    winding = winding_number(points, CUBE_VERTICES, CUBE_FACES)
    np.testing.assert_allclose(winding, [1.0, 0.0], atol=1e-6)
    distance, _ = mesh_signed_distance(points, CUBE_VERTICES, CUBE_FACES)
    np.testing.assert_allclose(distance, box_signed_distance(points, UNIT), rtol=1e-6)
    assert distance[0] < 0.0 < distance[1]


def test_inward_wound_mesh_keeps_negative_inside():
    points = np.array([[0.1, 0.0, 0.0], [0.0, 0.0, 0.9]])
    distance, _ = mesh_signed_distance(points, CUBE_VERTICES, CUBE_FACES[:, ::-1])
    np.testing.assert_allclose(distance, [-0.4, 0.4], atol=EXACT)


@pytest.mark.parametrize('point', [
    (0.5, 0.1, -0.2),        # on a face
    (0.5, 0.25, 0.25),       # on a face, on the diagonal shared by its two triangles
    (0.5, 0.5, 0.3),         # on an edge between faces
    (-0.5, 0.5, -0.5),       # on a vertex
])
def test_points_on_the_surface_have_zero_distance(point):
    distance, closest = mesh_signed_distance(np.array(point), CUBE_VERTICES, CUBE_FACES)
    assert abs(distance) <= EXACT
    np.testing.assert_allclose(closest, point, atol=EXACT)


def test_icosphere_vertices_are_on_its_surface():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.05)
    distance, closest = mesh_signed_distance(sphere.vertices, sphere.vertices, sphere.faces)
    np.testing.assert_allclose(distance, 0.0, atol=1e-17)
    np.testing.assert_allclose(closest, sphere.vertices, atol=1e-17)


@pytest.mark.parametrize(('point', 'expected_closest'), [
    ((0.2, 0.1, 0.9), (0.2, 0.1, 0.5)),       # above a face
    ((0.9, 0.9, 0.0), (0.5, 0.5, 0.0)),       # beside an edge
    ((0.7, -0.6, 1.0), (0.5, -0.5, 0.5)),     # beyond a vertex
    ((0.1, 0.05, 0.4), (0.1, 0.05, 0.5)),     # inside, under the top face
])
def test_closest_points_by_region(point, expected_closest):
    _, closest = mesh_signed_distance(np.array(point), CUBE_VERTICES, CUBE_FACES)
    np.testing.assert_allclose(closest, expected_closest, atol=EXACT)


def test_non_convex_mesh_matches_union_of_boxes():
    vertices, faces, shift = two_cubes(gap=0.2)
    points = np.random.default_rng(3).uniform(-1.5, 1.5, (2000, 3))
    expected = np.minimum(box_signed_distance(points + shift, UNIT),
                          box_signed_distance(points - shift, UNIT))
    distance, _ = mesh_signed_distance(points, vertices, faces)
    np.testing.assert_allclose(distance, expected, rtol=0, atol=EXACT)
    gap_centre = np.zeros(3)
    assert mesh_signed_distance(gap_centre, vertices, faces)[0] == pytest.approx(0.1, abs=EXACT)


def test_sample_near_surface_of_cube():
    points, distance = sample_near_surface(CUBE_VERTICES, CUBE_FACES, 401, 0.05,
                                           np.random.default_rng(4))
    assert points.shape == (401, 3) and distance.shape == (401,)
    assert np.all(distance[:200] < 0.0) and np.all(distance[200:] > 0.0)
    assert np.all(np.abs(distance) <= 0.05)
    np.testing.assert_allclose(distance, box_signed_distance(points, UNIT), rtol=0, atol=EXACT)


def test_sample_near_surface_returns_truth_not_offset_across_a_gap():
    # A 0.1 gap and a 0.3 band: outward offsets into the gap land nearer the other cube, and
    # inward offsets near edges land nearer an adjacent face, so truth < offset for many points.
    vertices, faces, shift = two_cubes(gap=0.1)
    points, distance = sample_near_surface(vertices, faces, 600, 0.3, np.random.default_rng(5))
    expected = np.minimum(box_signed_distance(points + shift, UNIT),
                          box_signed_distance(points - shift, UNIT))
    np.testing.assert_allclose(distance, expected, rtol=0, atol=EXACT)
    assert np.all(distance[:300] < 0.0) and np.all(distance[300:] > 0.0)
    assert np.all(np.abs(distance) <= 0.3)
    in_gap = (np.abs(points[:, 0]) < 0.05) & np.all(np.abs(points[:, 1:]) < 0.5, axis=1)
    assert np.any(in_gap)
    assert np.all(distance[in_gap] <= 0.05 + EXACT)


def test_shipped_hand_is_closed_outward_and_non_convex():
    hand = trimesh.load_mesh(hand_mesh_path(), process=False)
    hand.merge_vertices()
    vertices = hand.vertices * 0.001
    palm, finger_gap = np.array([0.0, -0.044, 0.005]), np.array([-0.0078, 0.03, 0.0])
    winding = winding_number(np.stack([palm, finger_gap]), vertices, hand.faces)
    np.testing.assert_allclose(winding, [1.0, 0.0], atol=1e-9)
    distance, closest = mesh_signed_distance(finger_gap, vertices, hand.faces)
    assert 0.002 < distance < 0.005 and abs(closest[1] - finger_gap[1]) < 0.005
    points, distance = sample_near_surface(vertices, hand.faces, 40, 0.002,
                                           np.random.default_rng(6))
    assert np.all(distance[:20] < 0.0) and np.all(distance[20:] > 0.0)
    assert np.all(np.abs(distance) <= 0.002)


def test_shipped_files_are_found():
    assert hand_mesh_path().is_file()
    assert hand_mesh_path().suffix == '.stl'
    for name in ('cuboid', 'cylinder', 'hand', 'paper_cuboid_stl', 'paper_cylinder_stl'):
        assert scene_path(name).is_file()
    assert scene_path('cuboid.yaml') == scene_path('cuboid')


def test_unknown_scene_names_the_shipped_ones():
    with pytest.raises(FileNotFoundError, match='cuboid'):
        scene_path('no_such_scene')


def midpoint_sum(depth: float, roll: float, length: float, stiffness: float, cells=200_000):
    """Force and roll torque of the face cut in ``cells`` strips, each pushing at its middle."""
    y = (np.arange(cells) + 0.5) * length / cells - 0.5 * length
    pressed = np.maximum(depth - y * math.sin(roll), 0.0) * stiffness / cells
    return pressed.sum(), math.cos(roll) * (y * pressed).sum()


@pytest.mark.parametrize(('depth', 'roll'), [
    (0.01, 0.2),     # fully pressed
    (0.002, 0.35),   # one edge lifted
    (0.002, -0.35),  # the other edge lifted
    (0.003, 0.0),    # flush
    (-0.001, 0.0),   # above the plane
    (-0.001, 0.3),   # a corner still above
    (-0.002, 0.3),   # rolled, one edge pressed while the tip is above
])
def test_the_probe_face_closed_form_is_the_integral(depth, roll):
    force, torque = continuous_face(depth, roll, 0.04, 1000.0)
    expected_force, expected_torque = midpoint_sum(depth, roll, 0.04, 1000.0)
    assert force == pytest.approx(expected_force, rel=1e-6, abs=1e-12)
    assert torque == pytest.approx(expected_torque, rel=1e-6, abs=1e-12)


def test_a_fully_pressed_probe_face_torque_is_minus_k_l2_over_12_sin_cos():
    _, torque = continuous_face(0.01, 0.2, 0.04, 1000.0)
    assert torque == pytest.approx(-1000.0 * 0.04 ** 2 / 12 * math.sin(0.2) * math.cos(0.2),
                                   rel=1e-12)


# The toolkit's own packages: what the references must not compute their answers with.
TOOLKIT = ({path.parent.name for path in (ROOT / 'src').glob('*/package.xml')}
           | {'haptic_msgs', 'rclpy'})
# The two harnesses that drive a toolkit package, and the one each drives.
DRIVES = {'virtual_wall': {'force_renderer'}, 'psf_reference': {'ultrasound_sim'}}


def imported_roots(path: Path) -> set:
    """Return the top-level names a module's code imports (every statement, at any depth)."""
    roots = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            roots.update(alias.name.split('.')[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            roots.add(node.module.split('.')[0])
    return roots


def test_the_references_import_no_toolkit_package_and_the_harnesses_only_theirs():
    modules = sorted(Path(ground_truth.__file__).parent.glob('*.py'))
    assert {path.stem for path in modules} >= {'distances', 'wand', 'virtual_wall'}
    found = {path.stem: imported_roots(path) & TOOLKIT for path in modules}
    assert found == {path.stem: DRIVES.get(path.stem, set()) for path in modules}


def test_the_ground_truth_is_no_ros_package():
    folder = Path(ground_truth.__file__).parent
    assert folder.parent == ROOT and not (folder / 'package.xml').exists()
