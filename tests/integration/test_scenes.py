"""Scenes that change what the loop computes, over the real processes: a sphere tip, no objects.

Expected forces are worked here from the cuboid's geometry (top face at z = -0.025 m), not by the
toolkit's code.
"""
from domains import session_domain_id
from loop_client import LoopClient, press
import pytest

from haptic_bringup.launcher import Loop, LoopConfig

K = 160.0  # [N/m]
RADIUS = 0.001  # [m]
TOP = -0.025  # [m] z of the cuboid's top face
SPHERE_TIP = f"""\
frame_id: world
tip_radius: {RADIUS}
objects:
  - name: cuboid
    shape: {{box: {{size: [0.2, 0.1, 0.1]}}}}
    pose: {{position: [0.0, 0.0, -0.075]}}
    material: {{stiffness: [{K}, {K}, {K}], damping: [0.8, 0.8, 0.8]}}
"""
EMPTY = 'frame_id: world\nobjects: []\n'


def loop_on(text: str, folder, domain: int):
    """The collision and force nodes on scene ``text`` in ``domain``; yields a client."""
    scene = folder / 'scene.yaml'
    scene.write_text(text)
    config = LoopConfig(nodes=('collision_engine', 'force_renderer'),
                        domain_id=domain, run_dir=folder / 'launch',
                        overrides={'collision_engine': {'scene_file': str(scene)},
                                   'force_renderer': {'scene_file': str(scene)}})
    with Loop(config):
        client = LoopClient(domain)
        client.wait_connected()
        yield client
        client.close()


@pytest.fixture(scope='module')
def sphere_tip(tmp_path_factory):
    yield from loop_on(SPHERE_TIP, tmp_path_factory.mktemp('sphere_tip'), session_domain_id())


@pytest.fixture(scope='module')
def empty(tmp_path_factory):
    yield from loop_on(EMPTY, tmp_path_factory.mktemp('empty'), session_domain_id(second=True))


@pytest.mark.parametrize('depth', [0.0005, 0.001, 0.0015])  # the centre is outside at first
def test_a_sphere_tip_is_pushed_back_its_depth(sphere_tip, depth):
    press(sphere_tip, (0.01, 0.02, TOP + RADIUS - depth), (0.0, 0.0, K * depth), f'{depth} m')


def test_an_empty_scene_answers_every_pose_with_no_object_and_zero_force(empty):
    press(empty, (0.0, 0.0, TOP - 0.01), (0.0, 0.0, 0.0), 'empty scene')
    assert empty.spin_until(lambda: empty.states), 'no collision state came'
    assert all(s.status == s.STATUS_NO_OBJECT and s.object == '' for s in empty.states.values())
