"""load_mesh: the shipped meshes, every format, and a clear MeshError for every defect."""

import dataclasses
from pathlib import Path
import re
import subprocess
import sys
import tempfile

from fuzzing import examples
from ground_truth.distances import triangles_meet
from hypothesis import given, HealthCheck, settings
from hypothesis import strategies as st
import numpy as np
import pytest
from scipy.spatial.transform import Rotation
import trimesh
import yaml

from collision_engine.errors import MeshError
from collision_engine.mesh_io import load_mesh, MeshData

SCENE_DIR = Path(__file__).resolve().parents[2] / 'src' / 'collision_engine' / 'scenes'
MESH_DIR = SCENE_DIR / 'meshes'
STL_RECORD = np.dtype([('normal', '<f4', (3,)), ('corners', '<f4', (3, 3)), ('attribute', '<u2')])

# A unit cube [0, 1]^3, each face counter-clockwise seen from outside.
CUBE_VERTICES = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
CUBE_FACES = np.array([
    [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
    [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
])


def numbers(point: np.ndarray) -> str:
    """Coordinates as text that reads back to the same float64 values."""
    return ' '.join(f'{coordinate:.17g}' for coordinate in point)


def binary_stl(corners: np.ndarray) -> bytes:
    """Bytes of a binary STL holding triangles `corners` (m, 3, 3), written by hand."""
    records = np.zeros(len(corners), dtype=STL_RECORD)
    records['corners'] = corners
    return bytes(80) + np.uint32(len(corners)).tobytes() + records.tobytes()


def ascii_stl(corners: np.ndarray) -> bytes:
    facets = ''.join('facet normal 0 0 0\n outer loop\n'
                     + ''.join(f'  vertex {numbers(corner)}\n' for corner in triangle)
                     + ' endloop\nendfacet\n' for triangle in corners)
    return f'solid test\n{facets}endsolid test\n'.encode()


def obj_text(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    lines = [f'v {numbers(vertex)}' for vertex in vertices]
    lines += [f'f {a + 1} {b + 1} {c + 1}' for a, b, c in faces]
    return ('\n'.join(lines) + '\n').encode()


def ply_text(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    header = ['ply', 'format ascii 1.0', f'element vertex {len(vertices)}', 'property float x',
              'property float y', 'property float z', f'element face {len(faces)}',
              'property list uchar int vertex_indices', 'end_header']
    body = [numbers(vertex) for vertex in vertices] + [f'3 {a} {b} {c}' for a, b, c in faces]
    return ('\n'.join(header + body) + '\n').encode()


def write(directory: Path, name: str, data: bytes) -> Path:
    path = directory / name
    path.write_bytes(data)
    return path


def load_error(path: Path, **options) -> str:
    """The MeshError message of loading `path`, checked to name the file."""
    with pytest.raises(MeshError) as raised:
        load_mesh(path, **options)
    message = str(raised.value)
    assert str(path) in message
    return message


def assert_solid(mesh: MeshData) -> None:
    """Check a loaded mesh with trimesh's own tests, not with load_mesh's."""
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.shape[1] == 3
    assert mesh.faces.dtype == np.int64 and mesh.faces.shape[1] == 3
    assert np.all(np.isfinite(mesh.vertices))
    assert len(np.unique(mesh.vertices, axis=0)) == len(mesh.vertices)
    assert np.array_equal(np.unique(mesh.faces), np.arange(len(mesh.vertices)))
    solid = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert solid.is_watertight and solid.is_winding_consistent and solid.volume > 0.0


def finger_intervals(mesh: MeshData, y: float) -> list[tuple[float, float]]:
    """X intervals covered by the cross-section of the mesh at `y` (m), merged where they touch."""
    solid = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    segments = trimesh.intersections.mesh_plane(solid, [0.0, 1.0, 0.0], [0.0, y, 0.0])
    merged = []
    for low, high in sorted(zip(segments[:, :, 0].min(axis=1), segments[:, :, 0].max(axis=1))):
        if merged and low <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], high))
        else:
            merged.append((low, high))
    return merged


# The shipped meshes.

def test_hand_is_a_millimetre_hand_centred_in_its_file():
    hand = load_mesh(MESH_DIR / 'hand.stl', scale=0.001)
    assert_solid(hand)
    assert hand.warnings == () and not hand.is_convex
    assert 3000 <= len(hand.vertices) <= 6000
    low, high = hand.vertices.min(axis=0), hand.vertices.max(axis=0)
    np.testing.assert_allclose(low + high, 0.0, atol=1e-6)
    width, length, thickness = high - low
    assert 0.180 <= length <= 0.190 and 0.11 <= width <= 0.14 and 0.025 <= thickness <= 0.045


def test_hand_has_four_separate_fingers_and_a_thumb():
    hand = load_mesh(MESH_DIR / 'hand.stl', scale=0.001)
    fingers = finger_intervals(hand, 0.03)      # across the proximal phalanges
    assert len(fingers) == 4
    assert min(b[0] - a[1] for a, b in zip(fingers, fingers[1:])) > 0.005
    thumb_and_palm = finger_intervals(hand, -0.02)
    assert len(thumb_and_palm) == 2
    assert thumb_and_palm[1][0] - thumb_and_palm[0][1] > 0.005
    palm_width = thumb_and_palm[1][1] - thumb_and_palm[1][0]
    assert 0.075 <= palm_width <= 0.09


def test_hand_back_faces_up():
    hand = load_mesh(MESH_DIR / 'hand.stl', scale=0.001)
    highest = hand.vertices[np.argmax(hand.vertices[:, 2])]
    assert -0.06 < highest[1] < 0.0 and abs(highest[0]) < 0.04   # on the back of the palm


def test_paper_cylinder_mesh():
    cylinder = load_mesh(MESH_DIR / 'cylinder.stl')
    assert_solid(cylinder)
    assert cylinder.is_convex and len(cylinder.faces) == 152
    rim = np.abs(cylinder.vertices[:, 2]) == np.float32(0.05)
    assert np.all(rim | (np.abs(cylinder.vertices[:, 2]) < 1e-9))
    radius = np.hypot(cylinder.vertices[:, 0], cylinder.vertices[:, 1])
    on_rim = radius > 0.0
    np.testing.assert_allclose(radius[on_rim], 0.025, rtol=1e-7)
    assert np.count_nonzero(~on_rim) == 2   # the centres of the two cap fans


def test_paper_cuboid_mesh():
    cuboid = load_mesh(MESH_DIR / 'cuboid.stl')
    assert_solid(cuboid)
    assert cuboid.is_convex and len(cuboid.faces) == 12 and len(cuboid.vertices) == 8
    np.testing.assert_allclose(np.abs(cuboid.vertices), np.tile([0.05, 0.05, 0.1], (8, 1)),
                               rtol=1e-7)


@pytest.mark.parametrize('name', ['cuboid', 'cylinder', 'hand', 'paper_cuboid_stl',
                                  'paper_cylinder_stl'])
def test_the_papers_scenes_use_its_set_up(name):
    objects = yaml.safe_load((SCENE_DIR / f'{name}.yaml').read_text())['objects']
    assert objects
    for declared in objects:
        assert declared['pose']['position'] == [0.0, 0.0, -0.075]
        assert declared['material'] == {'stiffness': [160.0] * 3, 'damping': [0.8] * 3}


@pytest.mark.parametrize('scene', sorted(SCENE_DIR.glob('*.yaml')), ids=lambda p: p.stem)
def test_the_meshes_of_shipped_scenes_load(scene):
    objects = yaml.safe_load(scene.read_text())['objects']
    assert objects
    for declared in objects:
        mesh = declared['shape'].get('mesh')
        if mesh:
            loaded = load_mesh(SCENE_DIR / mesh['file'], scale=mesh['scale'])
            assert loaded.is_convex == mesh['convex'] and loaded.warnings == ()


def test_paper_cuboid_stl_scene_places_the_mesh_on_the_cuboid_box():
    box = yaml.safe_load((SCENE_DIR / 'cuboid.yaml').read_text())['objects'][0]
    stl = yaml.safe_load((SCENE_DIR / 'paper_cuboid_stl.yaml').read_text())['objects'][0]
    mesh = load_mesh(SCENE_DIR / stl['shape']['mesh']['file'])
    # Fixed-axis roll, pitch, yaw (REP-103); scipy's apply wants a writable copy.
    turned = Rotation.from_euler('xyz', stl['pose']['rpy']).apply(np.array(mesh.vertices))
    np.testing.assert_allclose(turned.max(axis=0), 0.5 * np.array(box['shape']['box']['size']),
                               atol=1e-8)
    np.testing.assert_allclose(turned.min(axis=0), -0.5 * np.array(box['shape']['box']['size']),
                               atol=1e-8)


# Formats, welding, scale.

@pytest.mark.parametrize(('name', 'data'), [
    ('cube.stl', binary_stl(CUBE_VERTICES[CUBE_FACES])),
    ('cube_ascii.stl', ascii_stl(CUBE_VERTICES[CUBE_FACES])),
    ('cube.obj', obj_text(CUBE_VERTICES, CUBE_FACES)),
    ('cube.ply', ply_text(CUBE_VERTICES, CUBE_FACES)),
    ('CUBE.STL', binary_stl(CUBE_VERTICES[CUBE_FACES])),
])
def test_every_format_gives_the_welded_cube(tmp_path, name, data):
    cube = load_mesh(write(tmp_path, name, data), scale=0.05)
    assert_solid(cube)
    assert len(cube.vertices) == 8 and len(cube.faces) == 12 and cube.is_convex
    np.testing.assert_array_equal(np.sort(cube.vertices, axis=0),
                                  np.sort(CUBE_VERTICES * 0.05, axis=0))
    assert cube.path == tmp_path / name and cube.warnings == ()


def test_welding_keeps_an_indexed_file_in_its_order(tmp_path):
    cube = load_mesh(write(tmp_path, 'cube.obj', obj_text(CUBE_VERTICES, CUBE_FACES)))
    np.testing.assert_array_equal(cube.vertices, CUBE_VERTICES)
    np.testing.assert_array_equal(cube.faces, CUBE_FACES)


def test_welding_joins_minus_zero_and_drops_unused_vertices(tmp_path):
    vertices = np.vstack([CUBE_VERTICES, [[-0.0, 0.0, -0.0], [7.0, 7.0, 7.0]]])
    faces = CUBE_FACES.copy()
    first_faces = faces[:3]
    first_faces[first_faces == 0] = 8    # the same corner, written as (-0, 0, -0)
    cube = load_mesh(write(tmp_path, 'cube.obj', obj_text(vertices, faces)))
    assert_solid(cube)
    assert len(cube.vertices) == 8


def test_mesh_data_is_frozen(tmp_path):
    cube = load_mesh(write(tmp_path, 'cube.stl', binary_stl(CUBE_VERTICES[CUBE_FACES])))
    with pytest.raises(dataclasses.FrozenInstanceError):
        cube.is_convex = False
    with pytest.raises(ValueError):
        cube.vertices[0, 0] = 1.0
    with pytest.raises(ValueError):
        cube.faces[0, 0] = 1


def test_loading_a_mesh_module_imports_neither_trimesh_nor_fcl():
    code = ('import sys, collision_engine.mesh_io; '
            'assert "trimesh" not in sys.modules and "fcl" not in sys.modules')
    subprocess.run([sys.executable, '-c', code], check=True)


# Repairs, with a warning.

def test_inside_out_mesh_is_inverted_with_a_warning(tmp_path):
    path = write(tmp_path, 'inside_out.stl', binary_stl(CUBE_VERTICES[CUBE_FACES[:, ::-1]]))
    cube = load_mesh(path)
    assert_solid(cube)
    assert len(cube.warnings) == 1
    assert str(path) in cube.warnings[0] and 'inward' in cube.warnings[0]


def test_zero_area_faces_are_dropped_with_a_warning(tmp_path):
    corners = CUBE_VERTICES[CUBE_FACES]
    slivers = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],     # repeated corner
                        [[0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.0, 1.0, 1.0]]])    # collinear
    path = write(tmp_path, 'slivers.stl', binary_stl(np.vstack([corners[:5], slivers,
                                                                corners[5:]])))
    cube = load_mesh(path)
    assert_solid(cube)
    assert len(cube.faces) == 12 and len(cube.vertices) == 8
    assert cube.warnings == (f'{path}: dropped 2 zero-area faces (0-based, as read: 5, 6)',)


# Defects, each a MeshError naming the file and the defect.

def test_missing_file(tmp_path):
    assert 'no such mesh file' in load_error(tmp_path / 'absent.stl')


def test_unreadable_file(tmp_path):
    (tmp_path / 'folder.stl').mkdir()
    assert 'cannot read' in load_error(tmp_path / 'folder.stl')


def test_unsupported_format(tmp_path):
    assert "unsupported mesh format '.3ds'" in load_error(write(tmp_path, 'cube.3ds', b'x'))


def test_empty_file(tmp_path):
    assert 'empty file' in load_error(write(tmp_path, 'empty.stl', b''))


def test_truncated_binary_stl(tmp_path):
    data = binary_stl(CUBE_VERTICES[CUBE_FACES])
    message = load_error(write(tmp_path, 'truncated.stl', data[:-20]))
    assert 'truncated' in message and 'declares 12 triangles (684 bytes)' in message
    assert 'has 664 bytes' in message


def test_binary_stl_shorter_than_its_header(tmp_path):
    assert 'shorter than the 84-byte header' in load_error(write(tmp_path, 'short.stl',
                                                                 b'\x01' * 40))


def test_garbage_stl(tmp_path):
    garbage = np.random.default_rng(0).bytes(1000)
    assert 'truncated or garbage binary STL' in load_error(write(tmp_path, 'garbage.stl',
                                                                 garbage))


def test_truncated_ascii_stl(tmp_path):
    data = ascii_stl(CUBE_VERTICES[CUBE_FACES])
    assert 'truncated ASCII STL' in load_error(write(tmp_path, 'cut.stl', data[:300]))


@pytest.mark.parametrize('value', [np.nan, np.inf, -np.inf])
def test_non_finite_coordinates(tmp_path, value):
    corners = CUBE_VERTICES[CUBE_FACES].copy()
    corners[4, 1, 2] = value
    message = load_error(write(tmp_path, 'nan.stl', binary_stl(corners)))
    assert '1 vertices have NaN or Inf coordinates' in message


def test_non_finite_coordinates_in_obj(tmp_path):
    vertices = CUBE_VERTICES.copy()
    vertices[3, 0] = np.nan
    message = load_error(write(tmp_path, 'nan.obj', obj_text(vertices, CUBE_FACES)))
    assert '1 vertices have NaN or Inf coordinates (0-based: 3)' in message


def test_no_faces(tmp_path):
    path = write(tmp_path, 'points.obj', obj_text(CUBE_VERTICES, np.zeros((0, 3), int)))
    assert 'no faces' in load_error(path)


def test_only_zero_area_faces(tmp_path):
    line = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]])
    assert 'no faces: all 1 faces have zero area' in load_error(
        write(tmp_path, 'line.stl', binary_stl(line)))


def test_face_index_out_of_range(tmp_path):
    faces = CUBE_FACES.copy()
    faces[3, 1] = 11
    message = load_error(write(tmp_path, 'bad_index.ply', ply_text(CUBE_VERTICES, faces)))
    assert 'face indices outside the 8 vertices' in message


def test_open_box(tmp_path):
    path = write(tmp_path, 'open.stl', binary_stl(CUBE_VERTICES[CUBE_FACES[:-1]]))
    message = load_error(path)
    assert 'not watertight: 3 boundary edges' in message and '0 non-manifold' in message


def test_non_manifold_edges(tmp_path):
    fin = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [-1.0, -1.0, 0.5]],
                    [[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, -1.0, 0.5]]])
    path = write(tmp_path, 'fin.stl', binary_stl(np.vstack([CUBE_VERTICES[CUBE_FACES], fin])))
    message = load_error(path)
    assert 'not watertight: 0 boundary edges' in message and '1 non-manifold edges' in message


def test_flipped_face(tmp_path):
    faces = CUBE_FACES.copy()
    faces[7] = faces[7, ::-1]
    message = load_error(write(tmp_path, 'flipped.stl', binary_stl(CUBE_VERTICES[faces])))
    assert 'inconsistent winding: 3 edges' in message


def test_bodies_touching_at_a_vertex(tmp_path):
    corners = CUBE_VERTICES[CUBE_FACES]
    path = write(tmp_path, 'pinch.stl', binary_stl(np.vstack([corners, corners + 1.0])))
    message = load_error(path)
    assert 'not a manifold at 1 vertices where separate fans of faces meet' in message


def test_bodies_wound_opposite_ways(tmp_path):
    outward = CUBE_VERTICES[CUBE_FACES]
    inward = CUBE_VERTICES[CUBE_FACES[:, ::-1]] + [2.0, 0.0, 0.0]
    message = load_error(write(tmp_path, 'mixed.stl', binary_stl(np.vstack([outward, inward]))))
    assert '1 of its 2 separate bodies are wound inward' in message


def test_flat_closed_surface(tmp_path):
    triangle = CUBE_VERTICES[[0, 4, 6]]
    path = write(tmp_path, 'flat.stl', binary_stl(np.stack([triangle, triangle[::-1]])))
    assert 'encloses no volume' in load_error(path)


def test_millimetres_read_as_metres(tmp_path):
    path = write(tmp_path, 'mm.stl', binary_stl(CUBE_VERTICES[CUBE_FACES] * 100.0))
    message = load_error(path)
    assert '100 m across after scale 1' in message
    assert 'looks like millimetres read as metres: set scale: 0.001' in message
    assert load_mesh(path, scale=0.001).vertices.max() == pytest.approx(0.1)


def test_metres_scaled_as_millimetres(tmp_path):
    path = write(tmp_path, 'm.stl', binary_stl(CUBE_VERTICES[CUBE_FACES] * 0.05))
    assert 'looks like metres scaled as millimetres' in load_error(path, scale=0.001)


@pytest.mark.parametrize('scale', [0.0, -1.0, np.nan, np.inf, 'mm', None, True])
def test_bad_scale(tmp_path, scale):
    path = write(tmp_path, 'cube.stl', binary_stl(CUBE_VERTICES[CUBE_FACES]))
    assert 'scale must be a positive finite number' in load_error(path, scale=scale)


def named_pair(message: str) -> tuple[int, int]:
    """The two face indices a self-intersection message names."""
    found = re.search(r'triangles (\d+) and (\d+) \(0-based, as read\)', message)
    assert found, message
    return int(found.group(1)), int(found.group(2))


def test_self_intersection(tmp_path):
    corners = CUBE_VERTICES[CUBE_FACES]
    overlapping = np.vstack([corners, corners + [0.5, 0.3, 0.2]])
    path = write(tmp_path, 'overlap.stl', binary_stl(overlapping))
    message = load_error(path)
    assert 'self-intersecting' in message
    first, second = named_pair(message)
    assert triangles_meet(overlapping[first], overlapping[second])
    unchecked = load_mesh(path, check_self_intersection=False)
    assert len(unchecked.faces) == 24


def test_one_body_poked_through_itself(tmp_path):
    # A closed, consistently wound single body: one corner of the cube pushed out through the
    # opposite face. Every other check passes; only the self-intersection test catches it.
    vertices = CUBE_VERTICES.copy()
    vertices[7] = [0.3, 0.4, -0.5]
    corners = vertices[CUBE_FACES]
    path = write(tmp_path, 'poked.stl', binary_stl(corners))
    first, second = named_pair(load_error(path))
    assert triangles_meet(corners[first], corners[second])
    assert len(load_mesh(path, check_self_intersection=False).faces) == 12


def test_bodies_touching_along_a_face(tmp_path):
    # A half-size cube against the face x = 1, sharing no vertex: the surface touches itself.
    corners = CUBE_VERTICES[CUBE_FACES]
    touching = np.vstack([corners, 0.5 * corners + [1.0, 0.25, 0.25]])
    path = write(tmp_path, 'touching.stl', binary_stl(touching))
    message = load_error(path)
    assert 'touch or cross' in message
    first, second = named_pair(message)
    assert triangles_meet(touching[first], touching[second])


@pytest.mark.parametrize('name, scale', [('hand.stl', 0.001), ('cylinder.stl', 1.0),
                                         ('cuboid.stl', 1.0)])
def test_shipped_meshes_do_not_meet_themselves(name, scale):
    # Load times, beside FCL's self-collision that this check replaced: bench/bench_mesh_load.py.
    assert load_mesh(MESH_DIR / name, scale=scale, check_self_intersection=True).warnings == ()


def test_separate_bodies_are_not_self_intersecting(tmp_path):
    corners = CUBE_VERTICES[CUBE_FACES]
    path = write(tmp_path, 'apart.stl', binary_stl(np.vstack([corners, corners + [1.01, 0, 0]])))
    assert_solid(load_mesh(path))


# Fuzzing: any input either loads as a valid solid or raises MeshError.

def load_or_mesh_error(name: str, data: bytes) -> None:
    with tempfile.TemporaryDirectory() as directory:
        path = write(Path(directory), name, data)
        try:
            mesh = load_mesh(path)
        except MeshError as error:
            assert str(path) in str(error)
        else:
            assert_solid(mesh)


FUZZ = settings(max_examples=examples(60), deadline=None,
                suppress_health_check=[HealthCheck.too_slow])


@FUZZ
@given(data=st.binary(max_size=400), suffix=st.sampled_from(['.stl', '.obj', '.ply']))
def test_fuzz_random_bytes(data, suffix):
    load_or_mesh_error('fuzz' + suffix, data)


@FUZZ
@given(flips=st.lists(st.tuples(st.integers(0, 683), st.integers(1, 255)), max_size=6))
def test_fuzz_corrupted_binary_stl(flips):
    data = bytearray(binary_stl(CUBE_VERTICES[CUBE_FACES] * 0.1))
    for position, mask in flips:
        data[position] ^= mask
    load_or_mesh_error('fuzz.stl', bytes(data))


@FUZZ
@given(text=st.text(alphabet='vf 0123456789.-e\n', max_size=300),
       suffix=st.sampled_from(['.obj', '.stl']))
def test_fuzz_mesh_like_text(text, suffix):
    load_or_mesh_error('fuzz' + suffix, text.encode())


@FUZZ
@given(cut=st.integers(0, 2000))
def test_fuzz_truncated_ply(cut):
    load_or_mesh_error('fuzz.ply', ply_text(CUBE_VERTICES * 0.1, CUBE_FACES)[:cut])
