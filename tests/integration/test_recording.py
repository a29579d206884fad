"""Recording a session over ROS 2: nothing lost under load; a bag recoverable after kill -9.

Published counts come from what each node itself says in its final ``/diagnostics`` report.
"""
import os
import signal
import subprocess
import sys
import time

from domains import session_domain_id
from load import hogged
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from test_teleop import wait_for_the_session_start
import yaml

from haptic_bringup import bag_tool
from haptic_bringup.bag import typestore_with
from haptic_bringup.launcher import Loop, loop_environment, LoopConfig
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import (bags, published_counts, PUBLISHERS, reported,
                                    SITE_PUBLISHERS, topic_counts)

DURATION = 4.0  # [s] of tapping
RECORDER_PAUSE = 0.5  # [s]
TELEOP = {'teleop': 'model', 'link': {'delay': 0.05, 'jitter': 0.005, 'loss': 0.01}}
RECORDERS = {'separate': ['recorder'], 'composed': ['recorder'],
             'teleop': ['operator_recorder', 'remote_recorder']}


def session_config(tmp_path, **kwargs) -> LoopConfig:
    return LoopConfig(scene='package://collision_engine/scenes/cuboid.yaml', experiment='cuboid',
                      domain_id=session_domain_id(), record=str(tmp_path / 'bag'),
                      run_dir=tmp_path / 'launch', **kwargs)


def layout_config(tmp_path, layout: str) -> LoopConfig:
    if layout == 'teleop':
        return LoopConfig(duration=DURATION, record=str(tmp_path / 'bag'),
                          domain_id=session_domain_id(),
                          remote_domain=session_domain_id(second=True),
                          run_dir=tmp_path / 'launch', **TELEOP)
    return session_config(tmp_path, duration=DURATION, composed=layout == 'composed')


def last_report(bag, typestore, key: str) -> int:
    """The last value any recorder reported for ``key`` (0 when none did)."""
    values = [v for node in reported(bag, typestore, key).values() for v in node[-1:]]
    return sum(int(v) for v in values)


def decoded(bag, topic: str) -> list:
    """The messages of ``topic``, decoded by an independent reader from the bag's own schemas."""
    with open(next(bag.glob('*.mcap')), 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        return [message for _, _, _, message in reader.iter_decoded_messages(topics=[topic])]


def stamps(messages: list) -> list:
    """Header stamps, ns."""
    return [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in messages]


@pytest.mark.parametrize('layout', ['separate', 'composed', 'teleop'])
def test_with_a_core_hogged_the_bag_holds_every_message_each_node_published(tmp_path, layout):
    """Nothing killed, nothing lost, with one core kept busy by another process throughout.

    The loop's recorder is in its process (composed, ``haptic_loop``'s default), a recorder
    process records three processes (``--separate``), and each telerobotic site records itself.
    """
    with hogged(cores=1), Loop(layout_config(tmp_path, layout)) as loop:
        ended = loop.wait(DURATION + 60.0)
        assert ended is not None and ended.name in ('wand_driver', 'composed', 'operator')
    bag = tmp_path / 'bag'
    typestore = typestore_with(custom_definitions())
    for each in bags(bag):
        info = yaml.safe_load((each / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
        assert info['version'] == 9 and info['storage_identifier'] == 'mcap'
    publishers = SITE_PUBLISHERS if layout == 'teleop' else PUBLISHERS
    published = published_counts(bag, typestore, publishers)
    recorded = topic_counts(bag)
    assert set(published) == set(publishers)  # every node's last report is in
    # A recorder process may lose a best-effort message DDS could not hand it in time, but it
    # says so; one in the loop's process takes each from the publisher's hand and loses none.
    lost = {topic: last_report(bag, typestore, f'lost: {topic}') for topic in publishers}
    if layout != 'separate':
        assert set(lost.values()) == {0}
    assert {topic: recorded.get(topic, 0) + lost[topic] for topic in publishers} == published
    for recorder in RECORDERS[layout]:
        assert reported(bag, typestore, 'dropped')[recorder][-1] == '0'
    # An independent reader decodes the bag from its own schemas.
    own = bag / 'operator' if layout == 'teleop' else bag
    poses = stamps(decoded(own, '/wand/pose'))
    assert len(poses) == recorded['/wand/pose']
    assert (poses[-1] - poses[0]) * 1e-9 >= 0.95 * DURATION  # the whole session
    if layout != 'teleop':
        states = decoded(bag, '/collision/state')
        assert min(s.distance for s in states) < 0.0  # the taps went into the cuboid
        assert recorded['/scene/description'] == 1  # latched: published once, at start-up


def test_a_recorder_process_paused_mid_session_loses_nothing(tmp_path):
    """Its process stopped for 0.5 s (SIGSTOP), as a busy machine may deschedule it: the loop's
    six streams, about 3000 messages meanwhile, wait in its shared-memory port 8192 deep, their
    buffers in the writers' segments of 8 MB (``haptic_util.transport``). With Fast DDS's
    default port, 512 deep, stopped 0.15 s, each of three runs lost 59 to 66 messages of every
    stream; with its default segments, 512 kB, stopped 0.25 s, 80 of each of the driver's."""
    with Loop(session_config(tmp_path, duration=DURATION)) as loop:
        wait_for_the_session_start(loop.config.domain_id, 180.0)
        time.sleep(1.0)
        recorder = loop.child('recorder').pid
        os.kill(recorder, signal.SIGSTOP)
        time.sleep(RECORDER_PAUSE)
        os.kill(recorder, signal.SIGCONT)
        ended = loop.wait(DURATION + 60.0)
        assert ended is not None and ended.name == 'wand_driver'
    bag = tmp_path / 'bag'
    typestore = typestore_with(custom_definitions())
    published = published_counts(bag, typestore)
    assert set(published) == set(PUBLISHERS)
    assert {topic: last_report(bag, typestore, f'lost: {topic}') for topic in PUBLISHERS} == \
        dict.fromkeys(PUBLISHERS, 0)
    assert {topic: topic_counts(bag)[topic] for topic in PUBLISHERS} == published


def test_a_loop_killed_with_sigkill_leaves_a_bag_recovered_without_a_hole(tmp_path, capsys):
    """The loop and its recorder die together. Every report of the driver in the recovered bag
    comes after exactly as many poses as it says it had published: what is left is the session
    up to a point, whole."""
    with Loop(session_config(tmp_path, composed=True)) as loop:
        time.sleep(4.0)
        os.killpg(loop.child('composed').pid, signal.SIGKILL)
    bag = tmp_path / 'bag'
    assert not (bag / 'metadata.yaml').exists()
    with pytest.raises(ValueError, match='haptic_bag recover'):
        topic_counts(bag)
    assert bag_tool.main(['recover', str(bag)]) == 0
    assert f'recovered {bag} into {bag}-recovered' in capsys.readouterr().out
    typestore = typestore_with(custom_definitions())
    poses, reports = [], []
    with AnyReader([tmp_path / 'bag-recovered'], default_typestore=typestore) as reader:
        for connection, time_ns, raw in reader.messages():
            if connection.topic == '/wand/pose':
                poses.append(time_ns)
            elif connection.topic == '/diagnostics':
                reports += [(time_ns, int(value.value))
                            for status in reader.deserialize(raw, connection.msgtype).status
                            if status.hardware_id == 'wand_driver'
                            for value in status.values if value.key == 'published']
    assert len(reports) >= 2 and reports[-1][1] > 0
    poses = np.array(poses)
    assert [int(np.sum(poses <= when)) for when, _ in reports] == [n for _, n in reports]


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
