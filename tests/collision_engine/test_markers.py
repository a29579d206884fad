"""RViz markers never carry a file path: package:// URIs, else the mesh's own triangles."""

import os
from pathlib import Path
import sys

from ground_truth.distances import scene_path
import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from visualization_msgs.msg import Marker

from collision_engine.markers import package_uri, scene_markers
from collision_engine.scene_file import read_scene
from haptic_util.paths import package_file

INSTALLED_SCENES = Path(sys.prefix) / 'share' / 'collision_engine' / 'scenes'
needs_install = pytest.mark.skipif(not (INSTALLED_SCENES / 'hand.yaml').is_file(),
                                   reason=f'collision_engine is not installed under {sys.prefix}')
# A unit cube [0, 1]^3 in millimetres, each face counter-clockwise seen from outside.
CUBE = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)]) * 10.0
CUBE_FACES = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                       [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


@pytest.fixture(autouse=True)
def installed(monkeypatch):
    """This repository's packages, as make test finds them."""
    monkeypatch.setenv('AMENT_PREFIX_PATH', os.environ.get('AMENT_PREFIX_PATH', sys.prefix))


def every_string(message) -> list[str]:
    """All string fields of a message, recursively (what a subscriber receives as text)."""
    strings = []
    for name in message.get_fields_and_field_types():
        value = getattr(message, name)
        if isinstance(value, str):
            strings.append(value)
        elif hasattr(value, 'get_fields_and_field_types'):
            strings += every_string(value)
    return strings


@needs_install
def test_an_installed_mesh_is_published_by_its_package_uri():
    marker, = scene_markers(read_scene(INSTALLED_SCENES / 'hand.yaml'))
    assert marker.type == Marker.MESH_RESOURCE
    assert marker.mesh_resource == 'package://collision_engine/scenes/meshes/hand.stl'
    assert package_file(marker.mesh_resource).resolve() == \
        (INSTALLED_SCENES / 'meshes' / 'hand.stl').resolve()
    assert marker.scale.x == marker.scale.y == marker.scale.z == 0.001


def test_a_mesh_elsewhere_is_published_as_its_triangles(tmp_path):
    (tmp_path / 'private').mkdir()
    lines = [f'v {x} {y} {z}' for x, y, z in CUBE]
    lines += [f'f {a} {b} {c}' for a, b, c in CUBE_FACES + 1]
    (tmp_path / 'private' / 'cube.obj').write_text('\n'.join(lines) + '\n')
    scene = tmp_path / 'private' / 'scene.yaml'
    scene.write_text('objects:\n  - name: cube\n'
                     '    shape: {mesh: {file: cube.obj, scale: 0.001}}\n'
                     '    pose: {position: [0.1, 0.2, 0.3], rpy: [0.1, 0.2, 0.3]}\n')
    marker, = scene_markers(read_scene(scene))
    assert marker.type == Marker.TRIANGLE_LIST and marker.mesh_resource == ''
    assert not any(str(tmp_path) in text or 'file:' in text for text in every_string(marker))
    points = np.array([[p.x, p.y, p.z] for p in marker.points]).reshape(-1, 3, 3)
    # The file's triangles in metres, in the object's frame (the pose carries the placement).
    np.testing.assert_array_equal(points, CUBE[CUBE_FACES] * 0.001)
    assert (marker.scale.x, marker.scale.y, marker.scale.z) == (1.0, 1.0, 1.0)
    pose = marker.pose
    np.testing.assert_allclose([pose.position.x, pose.position.y, pose.position.z],
                               [0.1, 0.2, 0.3])
    np.testing.assert_allclose(
        Rotation.from_quat([pose.orientation.x, pose.orientation.y, pose.orientation.z,
                            pose.orientation.w]).as_euler('xyz'), [0.1, 0.2, 0.3])


@pytest.mark.parametrize('name', ['cuboid', 'cylinder', 'hand', 'paper_cuboid_stl',
                                  'paper_cylinder_stl'])
def test_no_shipped_scene_publishes_a_path(name):
    for marker in scene_markers(read_scene(scene_path(name))):
        assert not any('file:' in text or text.startswith('/') for text in every_string(marker))


@needs_install
def test_package_uri_of_files_in_and_out_of_shares(tmp_path):
    assert package_uri(tmp_path / 'x.stl') is None
    assert package_uri(INSTALLED_SCENES / 'meshes' / 'hand.stl') == \
        'package://collision_engine/scenes/meshes/hand.stl'
    assert package_uri(INSTALLED_SCENES / 'meshes' / '..' / 'hand.yaml') == \
        'package://collision_engine/scenes/hand.yaml'


def test_a_tool_s_contact_segment_runs_from_the_tool_s_witness():
    from collision_engine import load_scene
    from collision_engine.markers import contact_markers

    scene = load_scene(scene_path('probe_flat'))
    result = scene.query_tool(scene.tool.shape, ((0.0, 0.0, 0.01), (0.0, 0.0, 0.0, 1.0)))
    point, segment = contact_markers(result, 'world')
    start, end = segment.points
    # The probe's centre at z = 0.01: its face 30 mm below it, 5 mm above the slab's top.
    assert (start.z, end.z) == pytest.approx((0.01 - 0.03, -0.025), abs=1e-12)
    assert point.pose.position.z == pytest.approx(-0.025, abs=1e-12)
