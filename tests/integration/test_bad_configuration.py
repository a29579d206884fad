"""A node given a bad configuration stops at once with one line naming the file, key or field.

Nothing starts half-configured: the process exits with code 2 before it publishes anything.
"""
import pathlib
import subprocess
import sys

import pytest

from haptic_bringup.launcher import loop_environment

CUBOID = """\
frame_id: world
objects:
  - name: cuboid
    shape: {box: {size: [0.2, 0.1, 0.1]}}
    pose: {position: [0.0, 0.0, -0.075]}
"""


def run_node(module: str, tmp_path: pathlib.Path, *parameters: str) -> subprocess.CompletedProcess:
    args = [sys.executable, '-m', module, '--ros-args']
    for parameter in parameters:
        args += ['-p', parameter]
    return subprocess.run(args, env=loop_environment(99, tmp_path / 'log'), capture_output=True,
                          text=True, timeout=120)


def error_line(result: subprocess.CompletedProcess) -> str:
    assert result.returncode == 2, result.stderr
    lines = [line for line in result.stderr.splitlines() if line.startswith('error:')]
    assert len(lines) == 1, result.stderr
    return lines[0]


@pytest.mark.parametrize('label, text, expected', [
    ('typo in a key', CUBOID.replace('pose:', 'pos:'), ['scene.yaml', 'objects[0]', 'pos']),
    ('unknown shape', CUBOID.replace('box:', 'cube:'),
     ['scene.yaml', 'objects[0].shape', 'cube']),
    ('NaN stiffness', CUBOID + '    material: {stiffness: [160, .nan, 160], damping: [0, 0, 0]}\n',
     ['scene.yaml', 'objects[0].material.stiffness']),
    ('negative stiffness', CUBOID + '    material: {stiffness: [-1, 1, 1], damping: [0, 0, 0]}\n',
     ['scene.yaml', 'objects[0].material.stiffness']),
    ('missing mesh file', CUBOID.replace('{box: {size: [0.2, 0.1, 0.1]}}',
                                         '{mesh: {file: nowhere.stl}}'),
     ['scene.yaml', 'nowhere.stl']),
    ('not YAML', 'objects: [\n', ['scene.yaml']),
])
def test_collision_node_refuses_a_bad_scene(tmp_path, label, text, expected):
    scene = tmp_path / 'scene.yaml'
    scene.write_text(text)
    line = error_line(run_node('collision_engine.node', tmp_path, f'scene_file:={scene}'))
    for word in expected:
        assert word in line, f'{label}: {line}'


def test_collision_node_refuses_a_missing_scene_file(tmp_path):
    missing = tmp_path / 'missing.yaml'
    line = error_line(run_node('collision_engine.node', tmp_path, f'scene_file:={missing}'))
    assert 'scene_file' in line and 'missing.yaml' in line


def test_collision_node_refuses_a_malformed_stl(tmp_path):
    (tmp_path / 'broken.stl').write_bytes(b'solid broken\n  facet normal 0 0 1\n')
    scene = tmp_path / 'scene.yaml'
    scene.write_text(CUBOID.replace('{box: {size: [0.2, 0.1, 0.1]}}',
                                    '{mesh: {file: broken.stl}}'))
    line = error_line(run_node('collision_engine.node', tmp_path, f'scene_file:={scene}'))
    assert 'broken.stl' in line


@pytest.mark.parametrize('parameter, expected', [
    ('stiffness:=[160.0, -5.0, 160.0]', "'stiffness'"),
    ('law:=spring', "'law'"),
    ('force_limit:=ten', "'force_limit'"),
])
def test_force_node_refuses_bad_parameters(tmp_path, parameter, expected):
    line = error_line(run_node('force_renderer.node', tmp_path, parameter))
    assert expected in line and 'force_renderer' in line


def test_driver_refuses_a_device_that_is_not_available(tmp_path):
    line = error_line(run_node('haptic_wand_driver.node', tmp_path, 'device:=quanser'))
    assert "'quanser'" in line and 'simulated' in line


def test_driver_refuses_a_missing_replay_file(tmp_path):
    line = error_line(run_node('haptic_wand_driver.node', tmp_path, 'device:=replay',
                               f'replay_file:={tmp_path / "run.csv"}'))
    assert 'run.csv' in line
