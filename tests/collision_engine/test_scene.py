"""Scenes end to end: the shipped scene files against ground truth, and the query API."""

from itertools import product
import math
from pathlib import Path
import re
import subprocess
import sys
import textwrap

from ground_truth.distances import (box_signed_distance, capsule_signed_distance,
                                    cylinder_signed_distance, exact_norm, exact_unit,
                                    hand_mesh_path, mesh_signed_distance, sample_near_surface,
                                    scene_path, sphere_signed_distance)
import numpy as np
import pytest
from scipy.spatial.transform import Rotation
import yaml

from collision_engine.errors import MeshError
from collision_engine.gjk import STATUS_NO_OBJECT, STATUS_OK
from collision_engine.mesh_io import load_mesh
from collision_engine.scene import load_scene, Scene, SceneObject
from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere, TriangleMesh
from collision_engine.transforms import Pose

ATOL = 1e-12


def local_frame(name):
    """The first object's pose, read from the YAML here: (rotation, translation)."""
    pose = yaml.safe_load(scene_path(name).read_text())['objects'][0]['pose']
    return Rotation.from_euler('xyz', pose.get('rpy', [0, 0, 0])), np.array(pose['position'])


def truth_for(name):
    """Analytic or brute-force signed distance for points in the object's local frame."""
    if name == 'cuboid':
        return lambda p: box_signed_distance(p, [0.2, 0.1, 0.1])
    if name == 'cylinder':
        return lambda p: cylinder_signed_distance(p, 0.025, 0.1)
    file, scale = {'hand': ('hand.stl', 0.001), 'paper_cuboid_stl': ('cuboid.stl', 1.0),
                   'paper_cylinder_stl': ('cylinder.stl', 1.0)}[name]
    mesh = load_mesh(scene_path(name).parent / 'meshes' / file, scale=scale,
                     check_self_intersection=False)
    return lambda p: mesh_signed_distance(p, mesh.vertices, mesh.faces)[0]


@pytest.mark.parametrize('name', ['cuboid', 'cylinder', 'hand', 'paper_cuboid_stl',
                                  'paper_cylinder_stl'])
def test_shipped_scenes_match_ground_truth(name):
    scene = load_scene(scene_path(name))
    rotation, translation = local_frame(name)
    truth = truth_for(name)
    rng = np.random.default_rng(21)
    world = translation + rng.uniform(-0.15, 0.15, size=(600, 3))
    batch = scene.query_many(world)
    local = rotation.inv().apply(world - translation)
    expected = truth(local)
    np.testing.assert_allclose(batch.distance, expected, rtol=0, atol=ATOL)
    assert np.all(batch.status == STATUS_OK)
    assert set(batch.object) == {scene.objects[0].name}
    # The closest point lies on the surface, |d| from the query point.
    np.testing.assert_allclose(truth(rotation.inv().apply(batch.point - translation)), 0.0,
                               rtol=0, atol=ATOL)
    np.testing.assert_allclose(np.linalg.norm(batch.point - world, axis=1), np.abs(expected),
                               rtol=0, atol=ATOL)


def test_convex_mesh_scenes_skip_the_tree():
    assert isinstance(load_scene(scene_path('paper_cylinder_stl')).objects[0].shape, ConvexMesh)
    assert isinstance(load_scene(scene_path('hand')).objects[0].shape, TriangleMesh)


def test_near_the_hand_surface_with_a_tip_radius():
    plain = load_scene(scene_path('hand'))
    mesh = plain.objects[0].shape
    points, truth = sample_near_surface(mesh.vertices, mesh.faces, 300, 0.002,
                                        np.random.default_rng(22))
    world = plain.objects[0].pose.to_world(points)
    tipped = Scene(plain.objects, tip_radius=0.001)
    for p, expected in zip(world, truth):
        assert plain.query(p).distance == pytest.approx(expected, abs=ATOL)
        result = tipped.query(p)
        assert result.distance == pytest.approx(expected - 0.001, abs=ATOL)
        assert result.in_collision == (expected <= 0.001)


def test_query_and_query_many_agree():
    scene = load_scene(scene_path('cylinder'))
    points = np.random.default_rng(23).uniform(-0.1, 0.1, size=(200, 3)) + [0, 0, -0.075]
    batch = scene.query_many(points)
    for k, p in enumerate(points):
        one = scene.query(p)
        assert one.distance == batch.distance[k]
        np.testing.assert_array_equal(one.point, batch.point[k])
        np.testing.assert_array_equal(one.normal, batch.normal[k])
        np.testing.assert_array_equal(one.tip, p)
        assert one.object == batch.object[k] and one.iterations == batch.iterations[k]


OBJECTS = [
    SceneObject('box', Box([0.1, 0.2, 0.05]), Pose.from_rpy([0.2, 0.0, 0.0], [0.1, 0.2, 0.3])),
    SceneObject('ball', Sphere(0.05), Pose.from_rpy([-0.1, 0.05, 0.0])),
    SceneObject('can', Cylinder(0.03, 0.1), Pose.from_rpy([0.0, -0.15, 0.02], [1.0, 0.0, 0.0])),
    SceneObject('pill', Capsule(0.02, 0.1), Pose.from_rpy([0.0, 0.0, 0.1], [0.0, 1.2, 0.0])),
]
TRUTHS = [
    lambda p: box_signed_distance(p, [0.1, 0.2, 0.05]),
    lambda p: sphere_signed_distance(p, 0.05),
    lambda p: cylinder_signed_distance(p, 0.03, 0.1),
    lambda p: capsule_signed_distance(p, 0.02, 0.1),
]
RPY_AND_POSITION = [([0.1, 0.2, 0.3], [0.2, 0.0, 0.0]), ([0, 0, 0], [-0.1, 0.05, 0.0]),
                    ([1.0, 0.0, 0.0], [0.0, -0.15, 0.02]), ([0.0, 1.2, 0.0], [0.0, 0.0, 0.1])]


def every_distance(points):
    """Analytic distance to each object of OBJECTS, (n, 4)."""
    return np.column_stack([
        truth(Rotation.from_euler('xyz', rpy).inv().apply(points - position))
        for truth, (rpy, position) in zip(TRUTHS, RPY_AND_POSITION)])


def test_nearest_of_several_objects():
    scene = Scene(OBJECTS)
    points = np.random.default_rng(24).uniform(-0.3, 0.3, size=(2000, 3))
    expected = every_distance(points)
    batch = scene.query_many(points)
    np.testing.assert_allclose(batch.distance, expected.min(axis=1), rtol=0, atol=ATOL)
    clear = np.sort(expected, axis=1)[:, 1] - expected.min(axis=1) > 1e-9
    np.testing.assert_array_equal(batch.object_index[clear], expected.argmin(axis=1)[clear])


def test_query_within_lists_every_object_in_range_nearest_first():
    scene = Scene(OBJECTS)
    rng = np.random.default_rng(25)
    for p in rng.uniform(-0.3, 0.3, size=(100, 3)):
        expected = every_distance(p[None])[0]
        for radius in (-0.01, 0.0, 0.05, 1.0):
            results = scene.query_within(p, radius)
            inside = np.flatnonzero(expected <= radius)
            assert sorted(r.object_index for r in results) == sorted(inside.tolist())
            found = [r.distance for r in results]
            assert found == sorted(found)
            for r in results:
                assert r.distance == pytest.approx(expected[r.object_index], abs=ATOL)
                assert r.object == OBJECTS[r.object_index].name


def test_result_fields_inside_and_outside():
    scene = Scene([SceneObject('box', Box([0.2, 0.2, 0.2]), Pose.from_rpy([0, 0, -0.1]))])
    inside = scene.query((0.01, 0.02, -0.03))
    assert inside.in_collision and inside.distance == pytest.approx(-0.03, abs=ATOL)
    np.testing.assert_allclose(inside.point, [0.01, 0.02, 0.0], atol=ATOL)
    np.testing.assert_allclose(inside.normal, [0, 0, 1], atol=ATOL)
    np.testing.assert_allclose(inside.penetration, [0.0, 0.0, 0.03], atol=ATOL)
    np.testing.assert_array_equal(inside.tip, [0.01, 0.02, -0.03])
    assert inside.object == 'box' and inside.status == STATUS_OK and inside.triangle == -1
    outside = scene.query(np.array([0.3, 0.0, -0.1]))
    assert not outside.in_collision and outside.distance == pytest.approx(0.2, abs=ATOL)
    np.testing.assert_array_equal(outside.penetration, np.zeros(3))
    assert outside.lower_bound == pytest.approx(outside.distance, abs=ATOL)


@pytest.mark.parametrize('centre_height', [0.0005, 0.0, -0.0005])  # sphere depths 0.5, 1, 1.5 mm
def test_a_sphere_tip_s_penetration_is_its_depth_along_the_normal(centre_height):
    box = SceneObject('box', Box([0.2, 0.2, 0.2]), Pose.from_rpy([0, 0, -0.1]))
    result = Scene([box], tip_radius=0.001).query((0.01, 0.02, centre_height))
    depth = 0.001 - centre_height
    assert result.distance == pytest.approx(-depth, abs=ATOL)
    np.testing.assert_allclose(result.penetration, [0.0, 0.0, depth], atol=ATOL)
    np.testing.assert_allclose(result.point, [0.01, 0.02, 0.0], atol=ATOL)


def test_empty_scene_reports_no_object():
    scene = Scene([])
    result = scene.query((0.0, 0.0, 0.0))
    assert result.status == STATUS_NO_OBJECT and result.object is None
    assert result.distance == np.inf and not result.in_collision
    assert scene.query_within((0, 0, 0), 1.0) == []
    assert scene.query_many(np.zeros((2, 3))).status.tolist() == [STATUS_NO_OBJECT] * 2


@pytest.mark.parametrize('point', [(np.nan, 0.0, 0.0), (0.0, np.inf, 0.0), (0, 0, -np.inf)])
def test_nan_and_inf_raise(point):
    scene = Scene(OBJECTS)
    with pytest.raises(ValueError, match='finite'):
        scene.query(point)
    with pytest.raises(ValueError, match='finite'):
        scene.query_within(point, 0.1)
    with pytest.raises(ValueError, match=r'points\[1\] is not finite'):
        scene.query_many([(0.0, 0.0, 0.0), point])


@pytest.mark.parametrize('point', [(0.0, 0.0), 'xyz', None, (1, 2, 3, 4)])
def test_malformed_points_raise(point):
    with pytest.raises(ValueError, match='point must be 3 numbers'):
        Scene(OBJECTS).query(point)


def run_python(code: str) -> str:
    """Run code in a fresh interpreter (no test paths), return its stdout."""
    completed = subprocess.run([sys.executable, '-c', textwrap.dedent(code)],
                               capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr
    return completed.stdout.strip()


def test_only_what_a_scene_needs_is_imported(tmp_path):
    primitives = tmp_path / 'primitives.yaml'
    primitives.write_text('objects:\n  - {name: b, shape: {box: {size: [1, 1, 1]}}}\n'
                          '  - {name: c, shape: {cylinder: {radius: 1, height: 1}}}\n')
    mesh = tmp_path / 'mesh.yaml'
    hand = scene_path('hand').parent / 'meshes' / 'hand.stl'
    mesh.write_text('objects:\n  - {name: hand, shape: {mesh: {file: %s, scale: 0.001}}}\n'
                    % hand)
    output = run_python(f'''
        import sys
        from collision_engine import load_scene, read_scene
        def loaded():
            return sorted({{m.split('.')[0] for m in sys.modules}} & {{'trimesh', 'fcl'}})
        scene = load_scene({str(primitives)!r})
        scene.query((0.0, 0.0, 2.0))
        print(loaded())
        read_scene({str(scene_path('hand'))!r})
        print(loaded())
        load_scene({str(mesh)!r}).query((0.0, 0.0, 0.1))
        print(loaded())
        load_scene({str(scene_path('hand'))!r}).query((0.0, 0.0, 0.1))
        print(loaded())
    ''')
    assert output.splitlines() == ['[]', '[]', "['trimesh']", "['fcl', 'trimesh']"]


CUBE = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
CUBE_FACES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                       [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


def overlapping_cubes_scene(directory) -> Path:
    """Two overlapping cubes in one file (centimetres) and a scene of it: closed, wound,
    manifold, and wrong signs wherever they overlap."""
    vertices = np.vstack([CUBE, CUBE + [0.5, 0.3, 0.2]])
    faces = np.vstack([CUBE_FACES, CUBE_FACES + 8])
    lines = [f'v {x} {y} {z}' for x, y, z in vertices]
    lines += [f'f {a} {b} {c}' for a, b, c in faces + 1]
    directory.mkdir(parents=True, exist_ok=True)
    (directory / 'overlap.obj').write_text('\n'.join(lines) + '\n')
    scene = directory / 'overlap.yaml'
    scene.write_text('objects:\n'
                     '  - {name: two, shape: {mesh: {file: overlap.obj, scale: 0.01}}}\n')
    return scene


def test_a_self_intersecting_mesh_is_refused_with_fcl_off(tmp_path):
    # The check used to need FCL and ran only with cross-validation on.
    scene = overlapping_cubes_scene(tmp_path)
    output = run_python(f'''
        import sys
        from collision_engine import load_scene, MeshError
        try:
            load_scene({str(scene)!r})
        except MeshError as error:
            print(error)
        print('fcl' in sys.modules)
    ''')
    message, fcl_loaded = output.splitlines()
    assert message.startswith(f'{scene}: objects[0].shape.mesh.file: ')
    assert 'overlap.obj' in message and 'self-intersecting' in message
    assert re.search(r'triangles \d+ and \d+ \(0-based, as read\)', message)
    assert fcl_loaded == 'False'


def test_mesh_errors_name_the_scene_by_the_path_as_given(tmp_path, monkeypatch):
    overlapping_cubes_scene(tmp_path / 'site')
    monkeypatch.chdir(tmp_path)
    with pytest.raises(MeshError) as raised:
        load_scene('site/overlap.yaml')
    assert str(raised.value).startswith('site/overlap.yaml: objects[0].shape.mesh.file: ')
    assert f'{tmp_path}/site/overlap.obj: self-intersecting' in str(raised.value)


def test_public_api():
    output = run_python('''
        from collision_engine import (load_scene, read_scene, Scene, QueryResult, SceneError,
                                      MeshError, Box, Sphere, Cylinder, Capsule, ConvexMesh,
                                      TriangleMesh, distance, DistanceRequest, DistanceResult,
                                      Pose)
        print(issubclass(SceneError, ValueError), issubclass(MeshError, ValueError))
    ''')
    assert output == 'True True'


EPS = float(np.finfo(np.float64).eps)
TINY_OFFSETS = [tuple(sign * m for sign, m in zip(signs, magnitudes))
                for magnitudes in product((5e-324, 1e-300), repeat=3)
                for signs in product((1.0, -1.0), repeat=3)]


def assert_unit(normal):
    assert float(exact_norm(normal)) == pytest.approx(1.0, abs=4 * EPS)


@pytest.mark.parametrize('offset', TINY_OFFSETS)
def test_tiny_offsets_from_a_centre_or_an_axis_give_the_exact_depth_and_normal(offset):
    x, y, z = offset
    r = 0.025
    cases = [  # (shape, expected outward normal, depth)
        (Sphere(r), exact_unit(offset), r),
        (Cylinder(r, 0.1), [*exact_unit((x, y)), 0.0], r),
        (Capsule(r, 0.1), [*exact_unit((x, y)), 0.0], r),
        (Box([0.2, 2 * r, 0.3]), [0.0, math.copysign(1.0, y), 0.0], r),
    ]
    for shape, normal, depth in cases:
        result = Scene([SceneObject('shape', shape, Pose())]).query(offset)
        assert result.distance == -depth, shape
        np.testing.assert_allclose(result.normal, normal, rtol=0, atol=4 * EPS)
        assert_unit(result.normal)
        # The surface point is the depth along the normal from the (practically central) point.
        np.testing.assert_allclose(result.point, depth * np.array(normal), rtol=0,
                                   atol=4 * EPS * depth)


TETRAHEDRON = np.array([[0.0, 0.0, 0.0], [0.05, 0.0, 0.0], [0.0, 0.05, 0.0], [0.0, 0.0, 0.05]])
TETRAHEDRON_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


@pytest.mark.parametrize('magnitudes', list(product((5e-324, 1e-300), repeat=3)))
def test_tiny_offsets_from_a_mesh_vertex_give_the_exact_distance(magnitudes):
    # Just outside the tetrahedron's corner at the origin: the nearest point is that corner.
    point = -np.array(magnitudes)
    scene = Scene([SceneObject('corner', TriangleMesh(TETRAHEDRON, TETRAHEDRON_FACES), Pose())])
    result = scene.query(point)
    # Exact to rounding, or to the spacing of subnormals (5e-324) where it is subnormal.
    assert abs(result.distance - float(exact_norm(point))) <= 4 * EPS * result.distance + 1e-323
    assert result.distance > 0.0
    assert_unit(result.normal)
    assert result.normal @ [-1.0, -1.0, -1.0] > 0.0
    # A convex hull is exact to GJK's rounding of its size instead (about 1e-17 m here).
    hull = Scene([SceneObject('corner', ConvexMesh(TETRAHEDRON), Pose())]).query(point)
    assert abs(hull.distance - result.distance) <= 4 * EPS * 0.05
    assert_unit(hull.normal)


HAND = load_mesh(hand_mesh_path(), scale=0.001, check_self_intersection=False)
FAR_OBJECTS = [*OBJECTS,
               SceneObject('hand', TriangleMesh(HAND.vertices, HAND.faces),
                           Pose.from_rpy([0.0, 0.0, -0.075], [0.3, -0.2, 0.1])),
               SceneObject('hull', ConvexMesh(HAND.vertices),
                           Pose.from_rpy([0.2, 0.0, -0.075], [0.0, 0.4, 0.0]))]


@pytest.mark.parametrize('reach', [1e20, 1e154, 1e155, 1e300])
@pytest.mark.parametrize('index', range(len(FAR_OBJECTS)), ids=[o.name for o in FAR_OBJECTS])
def test_huge_offsets_give_the_exact_distance_and_a_unit_normal(index, reach):
    scene_object = FAR_OBJECTS[index]
    scene = Scene([scene_object])
    rng = np.random.default_rng(26)
    centre, radius = scene_object.shape.bounding_sphere()
    centre = scene_object.pose.to_world(centre)
    for direction in rng.normal(size=(20, 3)):
        u = exact_unit(direction)
        point = centre + reach * u
        result = scene.query(point)
        if index < len(OBJECTS):
            truth = every_distance(point[None])[0, index]
        else:
            # Every point of a mesh is within its radius of the centre: at 1e20 radii, the
            # distance from the centre is the distance to the mesh to rounding.
            truth = float(exact_norm(point - centre))
            assert radius / truth < EPS / 1e4
        assert result.distance == pytest.approx(truth, rel=4 * EPS)
        assert_unit(result.normal)
        assert result.normal @ u == pytest.approx(1.0, abs=4 * EPS)


def test_points_far_from_a_mesh_keep_their_sign_and_exact_distance():
    # Near 1e17 m the rounding of q - corner (~10 m) used to garble the hand's features and
    # flip the sign; beyond 2^26 radii the search starts from a point pulled in on the ray.
    scene = Scene([FAR_OBJECTS[-2]])
    mesh, pose = FAR_OBJECTS[-2].shape, FAR_OBJECTS[-2].pose
    rng = np.random.default_rng(27)
    for exponent in range(0, 18):
        points = rng.normal(size=(10, 3)) * 10.0 ** exponent
        truth, _ = mesh_signed_distance(pose.to_local(points), mesh.vertices, mesh.faces)
        batch = scene.query_many(points)
        np.testing.assert_allclose(batch.distance, truth, rtol=4 * EPS, atol=ATOL)
