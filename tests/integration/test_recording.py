"""Recording a session over ROS 2: nothing lost on a clean stop; readable after kill -9."""
import os
import signal
import subprocess
import sys
import time

from domains import session_domain_id
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
import numpy as np
import pytest
import yaml

from haptic_bringup.bag import FLUSH_PERIOD, recover, typestore_with
from haptic_bringup.launcher import Loop, loop_environment, LoopConfig
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import published_counts, PUBLISHERS, topic_counts

DURATION = 4.0  # [s] of tapping


def session_config(tmp_path, **kwargs) -> LoopConfig:
    return LoopConfig(scene='package://collision_engine/scenes/cuboid.yaml', experiment='cuboid',
                      domain_id=session_domain_id(), record=str(tmp_path / 'bag'),
                      run_dir=tmp_path / 'launch', **kwargs)


def decoded(bag, topic: str) -> list:
    """The messages of ``topic``, decoded by an independent reader from the bag's own schemas."""
    with open(next(bag.glob('*.mcap')), 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        return [message for _, _, _, message in reader.iter_decoded_messages(topics=[topic])]


def stamps(messages: list) -> list:
    """Header stamps, ns."""
    return [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in messages]


@pytest.mark.parametrize('composed', [False, True], ids=['separate', 'composed'])
def test_a_clean_stop_records_every_message_each_node_published(tmp_path, composed):
    """Composed, the nodes hand their streams over in the process: the recorder's get all."""
    with Loop(session_config(tmp_path, duration=DURATION, composed=composed)) as loop:
        ended = loop.wait(DURATION + 30.0)
        assert ended is not None and ended.name == ('composed' if composed else 'wand_driver')
    bag = tmp_path / 'bag'
    info = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert info['version'] == 9 and info['storage_identifier'] == 'mcap'
    published = published_counts(bag, typestore_with(custom_definitions()))
    recorded = topic_counts(bag)
    assert set(published) == set(PUBLISHERS)
    assert {topic: recorded[topic] for topic in PUBLISHERS} == published
    # An independent reader decodes the bag from its own schemas.
    states = decoded(bag, '/collision/state')
    assert len(states) == published['/collision/state']
    assert min(s.distance for s in states) < 0.0  # the taps went into the cuboid
    poses = stamps(decoded(bag, '/wand/pose'))
    assert (poses[-1] - poses[0]) * 1e-9 >= 0.95 * DURATION  # the whole session


def test_a_recorder_killed_with_sigkill_leaves_a_recoverable_bag(tmp_path):
    with Loop(session_config(tmp_path)) as loop:
        time.sleep(4.0)
        os.killpg(loop.child('recorder').pid, signal.SIGKILL)
        killed = time.time_ns()
    bag = tmp_path / 'bag'
    assert not (bag / 'metadata.yaml').exists()
    recovered = recover(bag, typestore_with(custom_definitions()))
    poses = stamps(decoded(recovered, '/wand/pose'))
    # Everything up to the last flush, at most FLUSH_PERIOD (0.5 s) before the kill, is there,
    # without holes: a lost chunk would leave a gap of about a flush period (a busy machine's
    # driver skips a few ticks at most).
    assert poses == sorted(poses)
    assert (killed - poses[-1]) * 1e-9 < FLUSH_PERIOD + 0.2
    assert max(np.diff(poses)) * 1e-9 < FLUSH_PERIOD / 2
    counts = topic_counts(recovered)
    assert counts['/collision/state'] > 0 and counts['/wand/wrench'] > 0


def test_a_recorder_pointed_at_an_existing_bag_refuses_and_leaves_it_untouched(tmp_path):
    with Loop(session_config(tmp_path, duration=1.0)) as loop:
        loop.wait(60.0)
    bag = tmp_path / 'bag'
    before = {path.name: path.read_bytes() for path in bag.iterdir()}
    again = subprocess.run(
        [sys.executable, '-m', 'haptic_bringup.launcher', '--experiment', 'cuboid',
         '--duration', '1', '--record', str(bag), '--domain-id', str(session_domain_id()),
         '--run-dir', str(tmp_path / 'again')],
        env=loop_environment(session_domain_id(), tmp_path / 'log'), capture_output=True,
        text=True, timeout=180)
    assert again.returncode == 1
    errors = [line for line in again.stderr.splitlines() if line.startswith('error:')]
    assert len(errors) == 1 and str(bag) in errors[0] and 'exists' in errors[0], again.stderr
    assert {path.name: path.read_bytes() for path in bag.iterdir()} == before
