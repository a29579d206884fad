"""The patient phantom: a closed, outward torso mesh that the collision engine loads, queries."""
from math import gamma
import pathlib

import numpy as np
import pytest
import trimesh

from collision_engine import load_scene, read_scene
from robot_site.impedance_robot import ImpedanceRobot, ImpedanceRobotConfig
from robot_site.phantom import DEFAULT_OUTPUT, main, phantom_mesh, TORSO_SIZE
from robot_site.tissue import ABDOMEN, SceneSurface, Tissue

SCENE = pathlib.Path(__file__).resolve().parents[2] / 'src/collision_engine/scenes/phantom.yaml'
FRONT = -0.025  # m: the abdomen's front, at x = y = 0


@pytest.fixture(scope='module')
def scene():
    return load_scene(SCENE)


def test_the_shipped_mesh_is_the_one_the_script_makes(tmp_path):
    main([str(tmp_path / 'phantom.stl')])
    assert (tmp_path / 'phantom.stl').read_bytes() == DEFAULT_OUTPUT.read_bytes()
    assert read_scene(SCENE).objects[0].shape.file == DEFAULT_OUTPUT


def test_the_mesh_is_closed_wound_outward_and_torso_sized():
    mesh = phantom_mesh()
    assert mesh.is_watertight and mesh.is_winding_consistent
    np.testing.assert_allclose(mesh.extents, TORSO_SIZE, rtol=1e-9)
    # A superellipsoid of exponent p has volume 8·abc·Γ(1 + 1/p)³ / Γ(1 + 3/p); the mesh's
    # facets cut a little inside it. A positive volume means outward normals.
    a, b, c = np.array(TORSO_SIZE) / 2
    exact = 8 * a * b * c * gamma(1 + 1 / 3) ** 3 / gamma(2)
    assert 0.99 * exact < mesh.volume < exact
    assert trimesh.load(DEFAULT_OUTPUT).is_watertight


def test_the_scene_answers_queries_on_the_abdomen(scene):
    above = scene.query((0.0, 0.0, 0.0))
    assert above.distance == pytest.approx(-FRONT, abs=1e-6)
    np.testing.assert_allclose(above.normal, [0.0, 0.0, 1.0], atol=1e-6)
    inside = scene.query((0.0, 0.0, FRONT - 0.01))
    assert inside.distance == pytest.approx(-0.01, abs=1e-6)
    flank = scene.query((0.2, 0.0, -0.1))
    assert flank.distance == pytest.approx(0.05, abs=1e-6)
    np.testing.assert_allclose(flank.normal, [1.0, 0.0, 0.0], atol=1e-6)


def test_a_robot_pressing_the_phantom_feels_the_abdomen(scene):
    robot = ImpedanceRobot(ImpedanceRobotConfig(stiffness=1500.0),
                           environment=Tissue(ABDOMEN, SceneSurface(scene)))
    robot.read(0.0)
    robot.command([0.0, 0.0, FRONT - 0.025])
    state = robot.read(2.0)
    depth = FRONT - state.position[2]
    assert 0.01 < depth < 0.025
    # Along the facet's normal, which tilts from +z by under a milliradian.
    np.testing.assert_allclose(state.external_force, [0, 0, ABDOMEN.normal_force(depth, 0.0)],
                               rtol=1e-6, atol=0.01)


def test_the_scene_material_is_the_abdomen_linearised_at_the_scan_force():
    material = read_scene(SCENE).objects[0].material
    depth = ABDOMEN.static_depth(8.0)
    np.testing.assert_allclose(material.stiffness, ABDOMEN.tangent_stiffness(depth), rtol=1e-3)
    np.testing.assert_allclose(material.damping, ABDOMEN.tangent_damping(depth), rtol=1e-3)


@pytest.mark.parametrize('arguments, message', [
    (dict(size=(0.3, 0.0, 0.1)), 'size must be 3 finite lengths'),
    (dict(size=(0.3, 0.2)), 'size must be 3 finite lengths'),
    (dict(exponent=1.5), 'exponent must be finite >= 2'),
    (dict(subdivisions=0), 'subdivisions must be an integer >= 1'),
])
def test_bad_arguments_are_refused(arguments, message):
    with pytest.raises(ValueError, match=message):
        phantom_mesh(**arguments)
