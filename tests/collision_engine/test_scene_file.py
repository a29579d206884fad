"""Scene files: what parses, and the one-line error naming file and key for what does not."""

import os
from pathlib import Path
import re
import sys
import textwrap

from fuzzing import examples
from ground_truth.distances import scene_path
from hypothesis import given, HealthCheck, settings
from hypothesis import strategies as st
import numpy as np
import pytest
import yaml

from collision_engine.errors import SceneError
from collision_engine.scene_file import (BoxSpec, CapsuleSpec, CylinderSpec, MeshSpec,
                                         read_scene, SphereSpec)

GOOD = """\
frame_id: world
tip_radius: 0.001
cross_validation: {fcl: true, every: 10, tolerance: 1.0e-6}
objects:
  - name: cuboid
    shape: {box: {size: [0.1, 0.1, 0.2]}}
    pose: {position: [0.0, 0.0, -0.075], rpy: [0.0, 0.0, 0.0]}
    material: {stiffness: [160, 160, 160], damping: [0.8, 0.8, 0.8]}
  - name: ball
    shape: {sphere: {radius: 0.02}}
    pose: {position: [0.1, 0.0, 0.0], quaternion: [0.0, 0.0, 0.0, 1.0]}
  - name: can
    shape: {cylinder: {radius: 0.025, height: 0.1}}
  - name: pill
    shape: {capsule: {radius: 0.01, length: 0.05}}
  - name: hand
    shape: {mesh: {file: hand.stl, scale: 0.001}}
"""


def write(tmp_path: Path, text: str, name: str = 'scene.yaml') -> Path:
    (tmp_path / 'hand.stl').write_bytes(b'')  # existence is all read_scene checks
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def test_a_full_scene_parses(tmp_path):
    spec = read_scene(write(tmp_path, GOOD))
    assert spec.frame_id == 'world' and spec.tip_radius == 0.001
    assert spec.cross_validation.fcl and spec.cross_validation.every == 10
    assert [o.name for o in spec.objects] == ['cuboid', 'ball', 'can', 'pill', 'hand']
    cuboid, ball, can, pill, hand = spec.objects
    assert cuboid.shape == BoxSpec((0.1, 0.1, 0.2))
    np.testing.assert_allclose(cuboid.pose.translation, [0.0, 0.0, -0.075])
    np.testing.assert_allclose(cuboid.material.stiffness, [160.0, 160.0, 160.0])
    np.testing.assert_allclose(cuboid.material.damping, [0.8, 0.8, 0.8])
    assert ball.shape == SphereSpec(0.02) and ball.material is None
    assert can.shape == CylinderSpec(0.025, 0.1)
    np.testing.assert_allclose(can.pose.rotation, np.eye(3))
    assert pill.shape == CapsuleSpec(0.01, 0.05)
    assert hand.shape == MeshSpec((tmp_path / 'hand.stl').resolve(), 0.001, None)


ANATOMY = """\
anatomy:
  media:
    liver: {speed_of_sound: 1595.0, impedance: 1.65e+6, attenuation: 0.5,
            scatterer_density: 100.0, scatterer_amplitude: 0.003}
    fluid: {speed_of_sound: 1480.0, impedance: 1.48e+6, attenuation: 0.0022,
            scatterer_density: 0.0, scatterer_amplitude: 0.0}
  structures:
    - {name: body, object: cuboid, medium: liver}
    - name: cyst
      shape: {sphere: {radius: 0.01}}
      pose: {position: [0.0, 0.0, -0.05]}
      medium: fluid
"""


def test_an_anatomy_parses_and_shares_its_object(tmp_path):
    spec = read_scene(write(tmp_path, GOOD + ANATOMY))
    assert list(spec.anatomy.media) == ['liver', 'fluid']
    liver = spec.anatomy.media['liver']
    assert (liver.speed_of_sound, liver.impedance, liver.attenuation, liver.scatterer_density,
            liver.scatterer_amplitude) == (1595.0, 1.65e6, 0.5, 100.0, 0.003)
    body, cyst = spec.anatomy.structures
    assert body.object == 'cuboid' and body.shape is spec.objects[0].shape
    assert body.pose is spec.objects[0].pose and body.medium == 'liver'
    assert cyst.object is None and cyst.shape == SphereSpec(0.01) and cyst.medium == 'fluid'
    np.testing.assert_allclose(cyst.pose.translation, [0.0, 0.0, -0.05])
    assert read_scene(write(tmp_path, GOOD)).anatomy is None


@pytest.mark.parametrize('old, new, message', [
    ('  media:', '  medias:', r"anatomy\.medias: unknown key \(did you mean 'media'\?\)"),
    ('impedance: 1.65e+6, ', '', r'anatomy\.media\.liver\.impedance: missing'),
    ('speed_of_sound: 1595.0', 'speed_of_sound: 0.0',
     r'anatomy\.media\.liver\.speed_of_sound: must be a finite number > 0'),
    ('attenuation: 0.5', 'attenuation: -0.5',
     r'anatomy\.media\.liver\.attenuation: must be a finite number >= 0'),
    ('scatterer_density: 100.0', 'scatterer_density: .nan',
     r'anatomy\.media\.liver\.scatterer_density: must be a finite number'),
    ('scatterer_amplitude: 0.003', 'scatterer_amplitude: 0.003, colour: red',
     r'anatomy\.media\.liver\.colour: unknown key'),
    ('object: cuboid, medium: liver', 'object: nothing, medium: liver',
     r"anatomy\.structures\[0\]\.object: no object 'nothing' in objects"),
    ('object: cuboid, medium: liver', 'object: cuboid, medium: bone',
     r"anatomy\.structures\[0\]\.medium: no medium 'bone' in anatomy\.media"),
    ('object: cuboid, medium: liver', 'medium: liver',
     r'anatomy\.structures\[0\]: give object .* or shape, one of them'),
    ('object: cuboid, medium: liver', 'object: cuboid, pose: {}, medium: liver',
     r"anatomy\.structures\[0\]\.pose: an object's surface has the object's pose"),
    ('name: cyst', 'name: body', r"anatomy\.structures\[1\]\.name: duplicate name 'body'"),
    ('radius: 0.01}}', 'radius: -0.01}}',
     r'anatomy\.structures\[1\]\.shape\.sphere\.radius: must be a finite number > 0'),
])
def test_anatomy_errors_name_the_file_and_the_key(tmp_path, old, new, message):
    assert old in ANATOMY
    path = write(tmp_path, GOOD + ANATOMY.replace(old, new, 1))
    with pytest.raises(SceneError, match=f'^{re.escape(str(path))}: {message}'):
        read_scene(path)


@pytest.mark.parametrize('anatomy, message', [
    ('anatomy: {media: {}, structures: []}', r'anatomy\.media: must be a mapping of at least one'),
    ('anatomy: {media: {a: 1}, structures: []}', r'anatomy\.media\.a: must be a mapping'),
    ('anatomy: {media: []}', r'anatomy\.structures: missing'),
])
def test_anatomy_structure_errors(tmp_path, anatomy, message):
    path = write(tmp_path, GOOD + anatomy + '\n')
    with pytest.raises(SceneError, match=f'^{re.escape(str(path))}: {message}'):
        read_scene(path)


def test_defaults(tmp_path):
    spec = read_scene(write(tmp_path, 'objects: []\n'))
    assert spec.frame_id == 'world' and spec.tip_radius == 0.0 and spec.objects == ()
    assert not spec.cross_validation.fcl


@pytest.mark.parametrize('name', ['cuboid', 'cylinder', 'hand', 'paper_cuboid_stl',
                                  'paper_cylinder_stl'])
def test_shipped_scenes_parse(name):
    spec = read_scene(scene_path(name))
    assert len(spec.objects) == 1 and spec.objects[0].material is not None


@pytest.mark.parametrize('old, new, message', [
    ('frame_id: world', 'frame: world', r"frame: unknown key \(did you mean 'frame_id'\?\)"),
    ('size: [0.1, 0.1, 0.2]', 'sise: [0.1, 0.1, 0.2]',
     r"objects\[0\]\.shape\.box\.sise: unknown key \(did you mean 'size'\?\)"),
    ('stiffness: [160, 160, 160]', 'stiffness: [160, .nan, 160]',
     r'objects\[0\]\.material\.stiffness: must be 3 finite numbers >= 0'),
    ('stiffness: [160, 160, 160]', 'stiffness: [160, -1, 160]',
     r'objects\[0\]\.material\.stiffness: must be 3 finite numbers >= 0'),
    ('stiffness: [160, 160, 160]', 'stiffness: 160',
     r'objects\[0\]\.material\.stiffness: must be a list of 3 numbers'),
    ('damping: [0.8, 0.8, 0.8]', 'damping: [0.8, 0.8, "a"]',
     r'objects\[0\]\.material\.damping: must be 3 finite numbers'),
    ('shape: {box: {size: [0.1, 0.1, 0.2]}}', 'shape: {cone: {radius: 1}}',
     r'objects\[0\]\.shape\.cone: unknown key; allowed: box, sphere, cylinder, capsule, mesh'),
    ('shape: {box: {size: [0.1, 0.1, 0.2]}}', 'shape: {boxx: {size: [0.1, 0.1, 0.2]}}',
     r"objects\[0\]\.shape\.boxx: unknown key \(did you mean 'box'\?\)"),
    ('shape: {box: {size: [0.1, 0.1, 0.2]}}', 'shape: {box: {size: [0.1, 0.1]}}',
     r'objects\[0\]\.shape\.box\.size: must be a list of 3 numbers'),
    ('shape: {box: {size: [0.1, 0.1, 0.2]}}', 'shape: {box: {size: [0.1, 0.0, 0.2]}}',
     r'objects\[0\]\.shape\.box\.size: must be 3 finite numbers > 0'),
    ('shape: {box: {size: [0.1, 0.1, 0.2]}}', 'shape: {}',
     r'objects\[0\]\.shape: must name exactly one shape'),
    ('radius: 0.02', 'radius: -0.02', r'objects\[1\]\.shape\.sphere\.radius: must be a finite '
     r'number > 0'),
    ('radius: 0.02', 'radius: true', r'objects\[1\]\.shape\.sphere\.radius: must be a number'),
    ('file: hand.stl', 'file: missing.stl',
     r'objects\[4\]\.shape\.mesh\.file: no such file: .*missing\.stl'),
    ('scale: 0.001', 'scale: 0.001, convex: yes please',
     r'objects\[4\]\.shape\.mesh\.convex: must be true or false'),
    ('name: ball', 'name: cuboid', r"objects\[1\]\.name: duplicate name 'cuboid'"),
    ('quaternion: [0.0, 0.0, 0.0, 1.0]', 'quaternion: [0.0, 0.0, 0.0, 0.0]',
     r'objects\[1\]\.pose\.quaternion: must be non-zero'),
    ('quaternion: [0.0, 0.0, 0.0, 1.0]', 'quaternion: [0.0, 0.0, 0.0, 1.0], rpy: [0, 0, 0]',
     r'objects\[1\]\.pose: give rpy or quaternion, not both'),
    ('every: 10', 'every: 0', r'cross_validation\.every: must be an integer >= 1'),
    ('tolerance: 1.0e-6', 'tolerance: 0', r'cross_validation\.tolerance: must be a finite '
     r'number > 0'),
    ('tip_radius: 0.001', 'tip_radius: -0.001', r'tip_radius: must be a finite number >= 0'),
    ('  - name: ball\n', '  - nam: ball\n', r"objects\[1\]\.nam: unknown key \(did you mean "
     r"'name'\?\)"),
    ('position: [0.1, 0.0, 0.0]', 'position: [0.1, 0.0, .inf]',
     r'objects\[1\]\.pose\.position: must be 3 finite numbers'),
])
def test_errors_name_the_file_and_the_key(tmp_path, old, new, message):
    assert old in GOOD
    path = write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(SceneError, match=f'^{re.escape(str(path))}: {message}') as raised:
        read_scene(path)
    assert '\n' not in str(raised.value)


@pytest.mark.parametrize('text, message', [
    ('objects: [\n', r'line \d+: not valid YAML'),
    ('- 1\n- 2\n', r': must be a mapping'),
    ('frame_id: world\n', r'objects: missing'),
    ('objects: {a: 1}\n', r'objects: must be a list'),
    ('objects: [{name: a}]\n', r'objects\[0\]\.shape: missing'),
    ('\udcff', r'not a text file'),
])
def test_structural_errors(tmp_path, text, message):
    path = write(tmp_path, '')
    path.write_bytes(text.encode('utf-8', 'surrogateescape'))
    with pytest.raises(SceneError, match=f'^{re.escape(str(path))}: {message}'):
        read_scene(path)


def test_errors_name_the_scene_by_the_path_as_given(tmp_path, monkeypatch):
    # Relative to the working directory, as a user types it: not only its base name.
    (tmp_path / 'site' / 'scenes').mkdir(parents=True)
    (tmp_path / 'site' / 'scenes' / 'scene.yaml').write_text('objects: [{name: a}]\n')
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError, match=r'^site/scenes/scene\.yaml: objects\[0\]\.shape'):
        read_scene('site/scenes/scene.yaml')


def test_missing_scene_file(tmp_path):
    with pytest.raises(SceneError, match='nope.yaml: cannot read the scene file'):
        read_scene(tmp_path / 'nope.yaml')


def test_scene_error_is_a_value_error():
    assert issubclass(SceneError, ValueError)


# Fuzzing: whatever a scene file holds, read_scene returns a scene or raises SceneError, with the
# file's name in the message; nothing else escapes (no KeyError, TypeError, YAML error, crash).
KEYS = ['frame_id', 'tip_radius', 'cross_validation', 'fcl', 'every', 'tolerance', 'objects',
        'name', 'shape', 'pose', 'position', 'rpy', 'quaternion', 'material', 'stiffness',
        'damping', 'box', 'size', 'sphere', 'radius', 'cylinder', 'height', 'capsule', 'length',
        'mesh', 'file', 'scale', 'convex', 'colour', 'anatomy', 'media', 'structures', 'medium',
        'object', 'speed_of_sound', 'impedance', 'attenuation', 'scatterer_density',
        'scatterer_amplitude']
SCALARS = st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6),
                    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=8))
DOCUMENTS = st.recursive(
    SCALARS,
    lambda inner: st.one_of(st.lists(inner, max_size=4),
                            st.dictionaries(st.sampled_from(KEYS), inner, max_size=5)),
    max_leaves=25)


@settings(max_examples=examples(300), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(document=DOCUMENTS)
def test_fuzzed_structures_give_a_scene_or_a_scene_error(tmp_path_factory, document):
    path = tmp_path_factory.mktemp('fuzz') / 'fuzzed.yaml'
    path.write_text(yaml.safe_dump(document))
    try:
        read_scene(path)
    except SceneError as error:
        assert 'fuzzed.yaml' in str(error)


@settings(max_examples=examples(300), deadline=None)
@given(raw=st.binary(max_size=300))
def test_fuzzed_bytes_give_a_scene_or_a_scene_error(tmp_path_factory, raw):
    path = tmp_path_factory.mktemp('fuzz') / 'bytes.yaml'
    path.write_bytes(raw)
    try:
        read_scene(path)
    except SceneError as error:
        assert 'bytes.yaml' in str(error)


# Mesh paths: every form is taken relative to the scene file's folder (or is absolute).

@pytest.fixture
def layout(tmp_path, monkeypatch):
    """tmp/scenes/scene.yaml beside a.stl and sub/a.stl; tmp/meshes/b.stl; tmp/home/c.stl."""
    for relative in ('scenes/a.stl', 'scenes/sub/a.stl', 'meshes/b.stl', 'home/c.stl'):
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_bytes(b'')
    monkeypatch.setenv('HOME', str(tmp_path / 'home'))
    monkeypatch.setenv('AMENT_PREFIX_PATH', os.environ.get('AMENT_PREFIX_PATH', sys.prefix))
    return tmp_path


def mesh_scene(directory: Path, file: str) -> Path:
    path = directory / 'scenes' / 'scene.yaml'
    path.write_text(f'objects:\n  - {{name: m, shape: {{mesh: {{file: {file!r}}}}}}}\n')
    return path


@pytest.mark.parametrize('file, expected', [
    ('a.stl', 'scenes/a.stl'), ('./a.stl', 'scenes/a.stl'), ('sub/a.stl', 'scenes/sub/a.stl'),
    ('sub/../a.stl', 'scenes/a.stl'), ('../meshes/b.stl', 'meshes/b.stl'),
    ('~/c.stl', 'home/c.stl'),
])
def test_mesh_paths_are_relative_to_the_scene_file(layout, monkeypatch, file, expected):
    # Read from another working directory, by a relative scene path: the scene's folder counts.
    monkeypatch.chdir(layout / 'meshes')
    spec = read_scene(Path('..') / 'scenes' / mesh_scene(layout, file).name)
    assert spec.objects[0].shape.file == (layout / expected).resolve()
    assert spec.objects[0].shape.file.is_absolute()


def test_absolute_and_package_mesh_paths(layout):
    absolute = str(layout / 'meshes' / 'b.stl')
    assert read_scene(mesh_scene(layout, absolute)).objects[0].shape.file == Path(absolute)
    shipped = read_scene(mesh_scene(layout, 'package://collision_engine/scenes/meshes/hand.stl'))
    assert shipped.objects[0].shape.file.name == 'hand.stl'
    assert shipped.objects[0].shape.file.read_bytes() == \
        (scene_path('hand').parent / 'meshes' / 'hand.stl').read_bytes()


@pytest.mark.parametrize('file, message', [
    ('missing.stl', r'no such file: .*scenes/missing\.stl'),
    ('package://collision_engine/../../etc/passwd', 'names no file inside the share folder'),
    ('package://collision_engine//etc/passwd', 'must be relative'),
    ('package://no_such_package/a.stl', "package 'no_such_package' is not installed"),
    ('~no_such_user_here/a.stl', 'cannot expand'),
])
def test_bad_mesh_paths_name_the_scene_and_the_key(layout, file, message):
    path = mesh_scene(layout, file)
    with pytest.raises(SceneError, match=r'objects\[0\]\.shape\.mesh\.file: .*' + message):
        read_scene(path)
