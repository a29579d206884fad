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


@pytest.mark.parametrize('law', ['proxy', 'centroid'])
def test_force_node_refuses_a_point_law_for_a_scene_with_a_tool(tmp_path, law):
    scene = tmp_path / 'scene.yaml'
    scene.write_text('tool: {shape: {box: {size: [0.01, 0.04, 0.06]}}}\n' + CUBOID)
    line = error_line(run_node('force_renderer.node', tmp_path, f'law:={law}',
                               f'scene_file:={scene}'))
    assert f"law '{law}' renders a point tip" in line and 'mounts a tool' in line, line


@pytest.mark.parametrize('parameter, expected', [
    ('passivity:=1', "'passivity' must be true or false, got 1"),
    ('frame_id:=1.5', "'frame_id' must be a string, got 1.5"),
    ('rate:=abc', "'rate' must be a number"),
    ('rate:=true', "'rate' must be a number"),
    ('min_subscribers:=1.5', "'min_subscribers' must be an integer"),
    ('stats_file:=[1, 2]', "'stats_file' must be a string"),
])
def test_driver_names_a_parameter_of_the_wrong_type_in_one_line(tmp_path, parameter, expected):
    line = error_line(run_node('haptic_wand_driver.node', tmp_path, parameter))
    assert expected in line and 'wand_driver' in line, line


def test_a_malformed_command_line_is_one_line(tmp_path):
    result = subprocess.run([sys.executable, '-m', 'force_renderer.node', '--ros-args', '-p',
                             'law'], env=loop_environment(99, tmp_path / 'log'),
                            capture_output=True, text=True, timeout=120)
    assert 'law' in error_line(result)


def test_a_misspelt_parameter_is_named_with_its_likely_meaning(tmp_path):
    result = run_node('force_renderer.node', tmp_path, 'stifness:=[1.0, 1.0, 1.0]',
                      'law:=spring')  # the typo is reported before the bad law stops the node
    error_line(result)
    assert "'stifness' is not a parameter of this node, ignored; did you mean 'stiffness'?" \
        in result.stderr


def test_driver_refuses_a_device_that_is_not_available(tmp_path):
    line = error_line(run_node('haptic_wand_driver.node', tmp_path, 'device:=quanser'))
    assert "'quanser'" in line and 'simulated' in line


def test_driver_refuses_a_missing_replay_file(tmp_path):
    line = error_line(run_node('haptic_wand_driver.node', tmp_path, 'device:=replay',
                               f'replay_file:={tmp_path / "run.csv"}'))
    assert 'run.csv' in line


@pytest.mark.parametrize('flags, failed', [([], 'composed'), (['--separate'], 'wand_driver')],
                         ids=['composed', 'separate'])
def test_the_launcher_stops_a_partial_loop_and_fails(tmp_path, flags, failed):
    """A node that cannot start takes the loop down with it: no idle half-loop, exit 1."""
    result = subprocess.run(
        [sys.executable, '-m', 'haptic_bringup.launcher', *flags, '--experiment', 'cubiod',
         '--domain-id', '99', '--run-dir', str(tmp_path)],
        env=loop_environment(99, tmp_path / 'log'), capture_output=True, text=True, timeout=180)
    assert result.returncode == 1, result.stderr
    assert "error: wand_driver: experiment 'cubiod'" in result.stderr
    assert f'{failed} exited with code 2' in result.stderr
    assert 'Traceback' not in result.stderr, result.stderr
