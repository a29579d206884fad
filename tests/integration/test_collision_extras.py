"""What the collision and force nodes publish beside the loop: nearby objects and RViz markers."""
import time

from domains import session_domain_id
from loop_client import LoopClient
import pytest
from visualization_msgs.msg import Marker, MarkerArray

from haptic_bringup.launcher import Loop, LoopConfig
from haptic_msgs.msg import CollisionStateArray
from haptic_util.qos import HAPTIC_STREAM_QOS, MARKER_QOS

TWO_BALLS = """\
frame_id: world
objects:
  - name: left
    shape: {sphere: {radius: 0.02}}
    pose: {position: [0.0, 0.05, 0.0]}
  - name: right
    shape: {sphere: {radius: 0.02}}
    pose: {position: [0.0, -0.08, 0.0]}
"""


@pytest.fixture(scope='module')
def two_balls(tmp_path_factory):
    folder = tmp_path_factory.mktemp('extras')
    scene = folder / 'two_balls.yaml'
    scene.write_text(TWO_BALLS)
    config = LoopConfig(nodes=('collision_engine', 'force_renderer'),
                        domain_id=session_domain_id(), run_dir=folder / 'launch',
                        overrides={'collision_engine': {'scene_file': str(scene),
                                                        'report_radius': 0.1},
                                   'force_renderer': {'scene_file': str(scene)}})
    with Loop(config):
        client = LoopClient(session_domain_id())
        yield client
        client.close()


def receive(client, message_type, topic, qos, predicate, timeout=10.0):
    received = []
    subscription = client.node.create_subscription(message_type, topic, received.append, qos)
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            client.send((0.0, 0.0, 0.0))
            client.executor.spin_once(timeout_sec=0.01)
            matching = [m for m in received if predicate(m)]
            if matching:
                return matching[-1]
    finally:
        client.node.destroy_subscription(subscription)
    raise TimeoutError(f'nothing suitable on {topic}')


def test_every_object_within_the_radius_is_reported_nearest_first(two_balls):
    nearby = receive(two_balls, CollisionStateArray, 'collision/nearby', HAPTIC_STREAM_QOS,
                     lambda m: len(m.states) == 2)
    assert [s.object for s in nearby.states] == ['left', 'right']
    assert [s.distance for s in nearby.states] == pytest.approx([0.03, 0.06], abs=1e-12)
    assert nearby.radius == 0.1 and nearby.header.frame_id == 'world'


def test_markers_show_the_objects_the_contact_and_the_force(two_balls):
    markers = receive(two_balls, MarkerArray, 'collision/markers', MARKER_QOS,
                      lambda m: any(k.ns.startswith('contact') for k in m.markers))
    spheres = [m for m in markers.markers if m.ns.startswith('scene/')]
    assert sorted(m.ns for m in spheres) == ['scene/left', 'scene/right']
    assert all(m.type == Marker.SPHERE and m.scale.x == pytest.approx(0.04) for m in spheres)
    assert all(m.header.frame_id == 'world' for m in markers.markers)
    arrow = receive(two_balls, Marker, 'wand/force_marker', MARKER_QOS,
                    lambda m: m.type == Marker.ARROW)
    assert len(arrow.points) == 2 and arrow.header.frame_id == 'world'
