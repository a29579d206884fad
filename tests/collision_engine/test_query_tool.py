"""``Scene.query_tool``: a convex tool against the scene, against ground truth sharing no code.

Against a mesh, apart: the least over its triangles of the polytope distance of the tool to the
triangle (scipy's hull of their Minkowski difference, ``ground_truth.polytope_pair_distance``).
In overlap, the stated method: the least exact signed distance (brute force over every triangle,
sign by winding number) over the tool's point shell. Against primitives: closed forms and the
polytope truth. Every case within 1e-9 m.
"""

from itertools import product

from ground_truth.distances import (box_signed_distance, cylinder_signed_distance,
                                    mesh_signed_distance, outward_hull, polytope_pair_distance,
                                    scene_path, tool_poses_near_surface)
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from collision_engine import (Box, Capsule, ConvexMesh, Cylinder, MeshError, Pose, Sphere,
                              STATUS_OK, TriangleMesh)
from collision_engine.scene import load_scene, Scene, SceneObject
from collision_engine.tool import load_tool, point_shell

TOLERANCE = 1e-9  # m
PROBE = Box([0.04, 0.01, 0.02])


@pytest.fixture(scope='module')
def hand():
    return load_scene(scene_path('hand'))


def corners(size) -> np.ndarray:
    return np.array(list(product(*[(-0.5 * s, 0.5 * s) for s in size])))


def tool_vertices(tool) -> np.ndarray:
    return corners(tool.size) if isinstance(tool, Box) else tool.vertices


def quaternion_pose(rotation, position) -> tuple:
    return tuple(position), tuple(Rotation.from_matrix(rotation).as_quat())


def mesh_truth(tool, rotation, position, vertices, faces, spacing, reported) -> float:
    """Signed distance of a polytope tool to the mesh by the stated method, mesh frame.

    Overlap (a shell point inside): the least signed distance over the shell. Apart: the least
    polytope distance over the triangles, among those that can be within ``reported`` + 1 mm
    of the tool (their bounding spheres against its own): a wrong report either includes the
    true nearest triangle or leaves every candidate more than 1 mm from it.
    """
    shell = point_shell(tool, spacing) @ rotation.T + position
    deepest = float(mesh_signed_distance(shell, vertices, faces)[0].min())
    if deepest < 0.0:
        return deepest
    tool_points = tool_vertices(tool) @ rotation.T + position
    centre = tool_points.mean(axis=0)
    reach = np.linalg.norm(tool_points - centre, axis=1).max()
    triangles = vertices[faces]
    centroids = triangles.mean(axis=1)
    spans = np.linalg.norm(triangles - centroids[:, None], axis=2).max(axis=1)
    near = np.linalg.norm(centroids - centre, axis=1) - spans - reach <= max(reported, 0) + 1e-3
    return max(0.0, min(polytope_pair_distance(triangle, tool_points)
                        for triangle in triangles[near]))


def check_witnesses(result, tolerance=1e-12):
    assert np.linalg.norm(result.normal) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(result.tool_point - result.point,
                               result.distance * result.normal, rtol=0, atol=tolerance)


def test_probe_near_the_hand_matches_the_triangle_truth(hand):
    mesh, pose = hand.objects[0].shape, hand.objects[0].pose
    rotations, positions = tool_poses_near_surface(mesh.vertices, mesh.faces, PROBE.size, 24,
                                                   0.002, np.random.default_rng(31))
    apart = overlapping = 0
    for rotation, position in zip(rotations, positions):
        world = Pose(pose.rotation @ rotation, pose.to_world(position))
        result = hand.query_tool(PROBE, quaternion_pose(world.rotation, world.translation))
        truth = mesh_truth(PROBE, rotation, position, mesh.vertices, mesh.faces,
                           hand.shell_spacing, result.distance)
        assert result.status == STATUS_OK and result.object == 'hand'
        assert result.distance == pytest.approx(truth, abs=TOLERANCE)
        check_witnesses(result)
        # The object's witness is on the hand's surface.
        surface = mesh_signed_distance(pose.to_local(result.point), mesh.vertices, mesh.faces)
        assert abs(surface[0]) <= 1e-12
        apart += truth > 0.0
        overlapping += truth < 0.0
    assert apart >= 5 and overlapping >= 5


def test_flat_face_pressed_on_a_flat_mesh_is_the_box_plane_depth():
    # A slab as a triangle mesh; the tilted probe's deepest point is its lowest corner, which
    # the shell holds: the depth is box-plane's closed form, in overlap and apart.
    slab = TriangleMesh(corners([0.3, 0.3, 0.05]), _box_faces(), name='slab')
    scene = Scene([SceneObject('slab', slab, Pose(translation=[0.0, 0.0, -0.025]))])
    rng = np.random.default_rng(32)
    for height in np.concatenate((rng.uniform(-0.004, 0.004, 30), [0.0])):
        rotation = Rotation.from_rotvec(rng.uniform(-0.3, 0.3, 3)).as_matrix()
        lowest = (corners(PROBE.size) @ rotation.T)[:, 2].min()
        position = np.array([rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05),
                             height - lowest])
        result = scene.query_tool(PROBE, quaternion_pose(rotation, position))
        assert result.distance == pytest.approx(height, abs=TOLERANCE)
        np.testing.assert_allclose(result.normal, [0.0, 0.0, 1.0], atol=1e-12)
        check_witnesses(result)


def _box_faces() -> np.ndarray:
    """The 12 outward triangles over ``corners``' order (index = 4 x + 2 y + z)."""
    return np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                     [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


def test_a_sphere_tool_is_the_point_query_minus_its_radius(hand):
    rng = np.random.default_rng(33)
    mesh, pose = hand.objects[0].shape, hand.objects[0].pose
    points = pose.to_world(mesh.vertices[rng.choice(len(mesh.vertices), 50)]
                           + rng.normal(0.0, 0.004, (50, 3)))
    tool = Sphere(0.003)
    for point in points:
        result = hand.query_tool(tool, (tuple(point), (0.0, 0.0, 0.0, 1.0)))
        truth = mesh_signed_distance(pose.to_local(point), mesh.vertices, mesh.faces)[0]
        assert result.distance == pytest.approx(truth - 0.003, abs=TOLERANCE)
        check_witnesses(result)


def test_primitives_and_the_nearest_of_several_objects():
    objects = [SceneObject('box', Box([0.05, 0.04, 0.03]), Pose.from_rpy([0.0, 0.0, -0.05],
                                                                         [0.1, 0.2, 0.3])),
               SceneObject('ball', Sphere(0.02), Pose(translation=[0.08, 0.0, 0.0])),
               SceneObject('rod', Capsule(0.01, 0.06), Pose.from_rpy([-0.08, 0.0, 0.0],
                                                                     [1.0, 0.0, 0.0]))]
    scene = Scene(objects)
    rng = np.random.default_rng(34)
    tool = ConvexMesh(rng.normal(size=(20, 3)) * 0.008)
    box_points = objects[0].pose.to_world(corners(objects[0].shape.size))
    rod = objects[2].pose.to_world([[0.0, 0.0, -0.03], [0.0, 0.0, 0.03]])
    for _ in range(150):
        rotation = Rotation.random(random_state=rng).as_matrix()
        position = rng.uniform(-0.1, 0.1, 3)
        points = tool.vertices @ rotation.T + position
        # A sphere is its centre and a capsule its segment, dilated: their polytope truths
        # (a point's or a segment's Minkowski difference with the tool), minus the radius.
        truths = [polytope_pair_distance(box_points, points),
                  polytope_pair_distance([[0.08, 0.0, 0.0]], points) - 0.02,
                  polytope_pair_distance(rod, points) - 0.01]
        result = scene.query_tool(tool, quaternion_pose(rotation, position))
        best = int(np.argmin(truths))
        assert result.distance == pytest.approx(truths[best], abs=TOLERANCE)
        if sorted(truths)[1] - truths[best] > 1e-6:
            assert result.object == objects[best].name
        check_witnesses(result)


def test_fcl_agrees_with_the_probe_apart_from_the_hand(hand):
    fcl = pytest.importorskip('fcl')
    mesh, pose = hand.objects[0].shape, hand.objects[0].pose
    model = fcl.BVHModel()
    model.beginModel(len(mesh.vertices), len(mesh.faces))
    model.addSubModel(mesh.vertices, mesh.faces)
    model.endModel()
    target = fcl.CollisionObject(model, fcl.Transform(pose.rotation, pose.translation))
    rotations, positions = tool_poses_near_surface(mesh.vertices, mesh.faces, PROBE.size, 200,
                                                   0.01, np.random.default_rng(35))
    compared = 0
    for rotation, position in zip(rotations, positions):
        world = Pose(pose.rotation @ rotation, pose.to_world(position))
        ours = hand.query_tool(PROBE, quaternion_pose(world.rotation, world.translation))
        if ours.distance < 1e-4:
            continue  # FCL is trusted apart only
        probe = fcl.CollisionObject(fcl.Box(*PROBE.size),
                                    fcl.Transform(world.rotation, world.translation))
        theirs = fcl.distance(target, probe, fcl.DistanceRequest(), fcl.DistanceResult())
        # FCL's GJK stops at a relative gap (cross_validation: up to ~3 % of the distance),
        # from above: its distance is between two points of the shapes, never below ours.
        assert ours.distance - 1e-9 <= theirs <= ours.distance * 1.03 + 1e-9
        compared += 1
    assert compared > 50


def test_a_non_convex_tool_is_refused_with_its_file_named(hand, tmp_path):
    with pytest.raises(MeshError, match='hand.stl: the tool mesh is not convex'):
        load_tool(scene_path('hand').parent / 'meshes' / 'hand.stl', scale=0.001)
    with pytest.raises(ValueError, match='hand.stl: the tool must be convex'):
        hand.query_tool(hand.objects[0].shape, ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))
    cuboid = load_tool(scene_path('hand').parent / 'meshes' / 'cuboid.stl')
    assert isinstance(cuboid, ConvexMesh)


def test_zero_size_and_oversized_tools_are_refused(hand):
    with pytest.raises(ValueError, match=r'Box.size\[1\] must be a positive'):
        Box([0.04, 0.0, 0.02])
    with pytest.raises(ValueError, match='no convex hull with a volume'):
        ConvexMesh([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0], [0.01, 0.01, 0]])
    with pytest.raises(ValueError, match='larger than the workspace'):
        hand.query_tool(Box([0.5, 0.01, 0.02]), ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))


@pytest.mark.parametrize('pose', [
    ((np.nan, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
    ((0.0, 0.0, np.inf), (0.0, 0.0, 0.0, 1.0)),
    ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.1)),
    ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0)),
    ((0.0, 0.0, 0.0), (np.nan, 0.0, 0.0, 1.0)),
    ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ((0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
    ((0.0, 'x', 0.0), (0.0, 0.0, 0.0, 1.0)),
    None,
])
def test_bad_poses_are_refused(hand, pose):
    with pytest.raises(ValueError, match='tool pose'):
        hand.query_tool(PROBE, pose)


def test_a_quaternion_off_unit_by_rounding_is_taken(hand):
    exact = hand.query_tool(PROBE, ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))
    rounded = hand.query_tool(PROBE, ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0 + 5e-7)))
    assert rounded.distance == pytest.approx(exact.distance, abs=1e-15)


def test_the_shell_lies_on_the_probe_within_its_spacing():
    for spacing in (0.005, 0.01, 0.003):
        shell = point_shell(PROBE, spacing)
        assert np.all(np.abs(box_signed_distance(shell, PROBE.size)) <= 1e-15)
        assert len(np.unique(shell, axis=0)) == len(shell)
        # Every corner is in it, and every point of the surface is within a spacing of it.
        for corner in corners(PROBE.size):
            assert np.min(np.linalg.norm(shell - corner, axis=1)) <= 1e-15
        rng = np.random.default_rng(36)
        surface = rng.uniform(-0.5, 0.5, (2000, 3)) * PROBE.size
        axis = rng.integers(0, 3, 2000)
        surface[np.arange(2000), axis] = np.sign(surface[np.arange(2000), axis]) * 0.5 * \
            np.asarray(PROBE.size)[axis]
        gaps = np.min(np.linalg.norm(surface[:, None] - shell[None], axis=2), axis=1)
        assert gaps.max() <= spacing


@pytest.mark.parametrize('tool, truth', [
    (Cylinder(0.008, 0.03), lambda p: cylinder_signed_distance(p, 0.008, 0.03)),
    (Capsule(0.004, 0.03), lambda p: np.hypot(p[:, 0], p[:, 1])),
    (Sphere(0.01), lambda p: np.linalg.norm(p, axis=1)),
    (ConvexMesh(np.random.default_rng(37).normal(size=(40, 3)) * 0.01), None),
])
def test_every_shell_lies_on_its_core(tool, truth):
    # The core: a sphere's centre, a capsule's axis, else the surface itself.
    shell = point_shell(tool, 0.004)
    if truth is None:
        faces, _ = outward_hull(tool.vertices)
        truth = (lambda p: mesh_signed_distance(p, tool.vertices, faces)[0])
    assert np.all(np.abs(truth(shell)) <= 1e-15)
    assert len(np.unique(shell, axis=0)) == len(shell)


def test_a_capsule_tool_apart_from_the_hand_is_its_segment_minus_the_radius(hand):
    mesh, pose = hand.objects[0].shape, hand.objects[0].pose
    tool = Capsule(0.004, 0.03)
    rotations, positions = tool_poses_near_surface(mesh.vertices, mesh.faces,
                                                   (0.008, 0.008, 0.038), 30, 0.004,
                                                   np.random.default_rng(38))
    checked = 0
    for rotation, position in zip(rotations, positions):
        world = Pose(pose.rotation @ rotation, pose.to_world(position))
        result = hand.query_tool(tool, quaternion_pose(world.rotation, world.translation))
        if result.distance <= 0.0:
            continue
        ends = np.array([[0.0, 0.0, -0.015], [0.0, 0.0, 0.015]]) @ rotation.T + position
        triangles = mesh.vertices[mesh.faces]
        near = np.linalg.norm(triangles.mean(axis=1) - position, axis=1) <= 0.04
        truth = min(polytope_pair_distance(t, ends) for t in triangles[near]) - 0.004
        assert result.distance == pytest.approx(truth, abs=TOLERANCE)
        check_witnesses(result)
        checked += 1
    assert checked >= 5


def test_a_tool_wholly_inside_a_mesh_reports_its_deepest_shell_point():
    # No triangle touches the tool: the sign of its witness says it is inside.
    slab = TriangleMesh(corners([0.3, 0.3, 0.05]), _box_faces(), name='slab')
    scene = Scene([SceneObject('slab', slab, Pose())])
    tool = Box([0.02, 0.01, 0.01])
    rng = np.random.default_rng(39)
    for _ in range(10):
        rotation = Rotation.from_rotvec(rng.uniform(-1.0, 1.0, 3)).as_matrix()
        position = rng.uniform(-0.005, 0.005, 3)
        result = scene.query_tool(tool, quaternion_pose(rotation, position))
        shell = point_shell(tool, scene.shell_spacing) @ rotation.T + position
        truth = mesh_signed_distance(shell, slab.vertices, slab.faces)[0].min()
        assert truth < -0.005
        assert result.distance == pytest.approx(truth, abs=TOLERANCE)
        check_witnesses(result)


def test_a_pose_object_gives_the_quaternion_form_s_answer(hand):
    pose = Pose.from_rpy([0.01, 0.02, -0.05], [0.2, -0.1, 0.4])
    quaternion = Rotation.from_matrix(pose.rotation).as_quat()
    by_pose = hand.query_tool(PROBE, pose)
    by_pair = hand.query_tool(PROBE, (tuple(pose.translation), tuple(quaternion)))
    assert by_pose.distance == by_pair.distance
