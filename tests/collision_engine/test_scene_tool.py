"""The scene's ``tool:`` section: the probe's shape, its offset, its contact face, bad input."""

from pathlib import Path
import textwrap

from ground_truth.distances import scene_path
import numpy as np
import pytest

from collision_engine import Box, Capsule, ConvexMesh, Cylinder, load_scene, Sphere
from collision_engine.errors import MeshError, SceneError
from collision_engine.scene_file import BoxSpec, read_scene
from collision_engine.tool import face_shell, MAX_FACE_POINTS

SLAB = """\
objects:
  - name: slab
    shape: {box: {size: [0.3, 0.3, 0.05]}}
    pose: {position: [0.0, 0.0, -0.05]}
"""


def scene(tmp_path: Path, tool: str, top: str = '') -> Path:
    path = tmp_path / 'scene.yaml'
    path.write_text(textwrap.dedent(top) + 'tool:\n' + textwrap.indent(textwrap.dedent(tool),
                                                                       '  ') + SLAB)
    return path


def test_a_scene_without_a_tool_has_none():
    assert read_scene(scene_path('cuboid')).tool is None
    assert load_scene(scene_path('cuboid')).tool is None


def test_the_flat_probe_scene_mounts_a_10_by_40_mm_face_at_the_tip():
    spec = read_scene(scene_path('probe_flat'))
    assert spec.tool.shape == BoxSpec((0.01, 0.04, 0.06)) and spec.tool.face_spacing == 0.005
    tool = load_scene(scene_path('probe_flat')).tool
    # 2 x 8 cells of 5 x 5 mm, their centres on the face, which the offset puts at z = 0.
    xs, ys = np.meshgrid([-0.0025, 0.0025], np.arange(-0.0175, 0.018, 0.005), indexing='ij')
    expected = np.column_stack((xs.ravel(), ys.ravel(), np.zeros(16)))
    np.testing.assert_allclose(tool.face, expected, atol=1e-15)
    assert tool.radius == 0.0 and isinstance(tool.shape, Box)


def test_the_phantom_probe_scene_loads_with_the_same_probe():
    tool = load_scene(scene_path('probe_phantom')).tool
    np.testing.assert_allclose(tool.face, load_scene(scene_path('probe_flat')).tool.face)


def test_the_offset_turns_and_moves_the_face(tmp_path):
    tool = load_scene(scene(tmp_path, """\
        shape: {box: {size: [0.02, 0.02, 0.02]}}
        offset: {position: [0.0, 0.0, 0.01], rpy: [0.0, 0.0, 1.5707963267948966]}
        face_spacing: 0.02
        """)).tool
    np.testing.assert_allclose(tool.face, [[0.0, 0.0, 0.0]], atol=1e-15)
    np.testing.assert_allclose(tool.offset.rotation @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
                               atol=1e-15)


def test_every_cell_of_a_box_face_has_the_same_area():
    face, radius = face_shell(Box([0.03, 0.012, 0.05]), 0.005)
    # 6 x 3 cells of 5 x 4 mm: centres 2.5 mm and 2 mm from the edges.
    assert len(face) == 18 and radius == 0.0
    assert np.all(face[:, 2] == -0.025)
    np.testing.assert_allclose(np.unique(face[:, 0]), -0.015 + 0.0025 + 0.005 * np.arange(6))
    np.testing.assert_allclose(np.unique(face[:, 1]), [-0.004, 0.0, 0.004], atol=1e-15)


def test_a_hull_of_a_box_has_the_box_face():
    box = Box([0.01, 0.04, 0.06])
    corners = np.array([[x, y, z] for x in (-0.005, 0.005) for y in (-0.02, 0.02)
                        for z in (-0.03, 0.03)])
    np.testing.assert_allclose(face_shell(ConvexMesh(corners), 0.005)[0],
                               face_shell(box, 0.005)[0], atol=1e-15)


def test_a_pointed_hull_has_its_tip_as_its_face():
    pyramid = ConvexMesh([[0.0, 0.0, -0.01], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0],
                          [-0.01, -0.01, 0.0]])
    np.testing.assert_allclose(face_shell(pyramid, 0.001)[0], [[0.0, 0.0, -0.01]])


def test_a_cylinder_face_is_the_cells_inside_its_cap():
    face, _ = face_shell(Cylinder(0.01, 0.03), 0.005)
    # A 4 x 4 grid of 5 mm cells on the 20 mm square: the 12 centres within 10 mm of the axis.
    assert len(face) == 12 and np.all(np.hypot(face[:, 0], face[:, 1]) <= 0.01)
    assert np.all(face[:, 2] == -0.015)


def test_round_tools_give_their_core_and_radius():
    np.testing.assert_allclose(face_shell(Sphere(0.004), 0.001)[0], [[0.0, 0.0, 0.0]])
    assert face_shell(Sphere(0.004), 0.001)[1] == 0.004
    face, radius = face_shell(Capsule(0.003, 0.02), 0.001)
    np.testing.assert_allclose(face, [[0.0, 0.0, -0.01]])
    assert radius == 0.003


# Bad input.

def test_a_non_convex_tool_mesh_is_refused_naming_the_file(tmp_path):
    hand = Path(scene_path('hand')).parent / 'meshes' / 'hand.stl'
    path = scene(tmp_path, f"""\
        shape: {{mesh: {{file: {hand}, scale: 0.001}}}}
        """)
    with pytest.raises(MeshError, match=rf'{path}: tool.shape.mesh.file: .*hand.stl: the '
                                        'tool mesh is not convex'):
        load_scene(path)


def test_a_tool_declared_non_convex_is_refused(tmp_path):
    (tmp_path / 'probe.stl').write_bytes(b'')
    with pytest.raises(SceneError, match=r'tool.shape.mesh.convex: must be true or omitted'):
        read_scene(scene(tmp_path, 'shape: {mesh: {file: probe.stl, convex: false}}\n'))


@pytest.mark.parametrize('size', ['[0.0, 0.04, 0.06]', '[0.01, -0.04, 0.06]',
                                  '[0.01, .nan, 0.06]'])
def test_a_zero_or_bad_size_is_refused(tmp_path, size):
    with pytest.raises(SceneError, match=r'tool.shape.box.size: must be 3 finite numbers > 0'):
        read_scene(scene(tmp_path, f'shape: {{box: {{size: {size}}}}}\n'))


def test_a_tool_larger_than_the_workspace_is_refused(tmp_path):
    path = scene(tmp_path, 'shape: {sphere: {radius: 0.2}}\n')
    with pytest.raises(SceneError, match=rf'{path}: tool: the tool Sphere\(radius=0.2\) is 0.4 m '
                                         r'across, larger than the workspace \(0.3 m\)'):
        load_scene(path)


def test_a_tool_with_a_tip_radius_is_refused(tmp_path):
    path = scene(tmp_path, 'shape: {sphere: {radius: 0.01}}\n', top='tip_radius: 0.002\n')
    with pytest.raises(SceneError, match=r'tool: give tool or tip_radius, not both'):
        read_scene(path)


def test_a_face_finer_than_a_state_carries_is_refused(tmp_path):
    path = scene(tmp_path, 'shape: {box: {size: [0.04, 0.04, 0.01]}}\nface_spacing: 0.005\n')
    with pytest.raises(SceneError, match=rf'tool: the tool\'s face has 64 points at a '
                                         rf'face_spacing of 0.005 m, more than the '
                                         rf'{MAX_FACE_POINTS}'):
        load_scene(path)


@pytest.mark.parametrize(('key', 'text', 'message'), [
    ('tool.shpe', 'shpe: {sphere: {radius: 0.01}}\n', "unknown key \\(did you mean 'shape'"),
    ('tool.shape', 'offset: {}\n', 'missing'),
    ('tool.face_spacing', 'shape: {sphere: {radius: 0.01}}\nface_spacing: 0\n',
     'must be a finite number > 0'),
    ('tool.offset.rpy', 'shape: {sphere: {radius: 0.01}}\noffset: {rpy: [0, 0]}\n',
     'must be a list of 3 numbers'),
])
def test_tool_keys_are_checked(tmp_path, key, text, message):
    with pytest.raises(SceneError, match=rf'{key}: {message}'):
        read_scene(scene(tmp_path, text))
