"""Bags as Jazzy writes them (mcap, metadata version 9), read back by independent readers."""
import multiprocessing
import os
import pathlib
import signal
import time

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
import pytest
from rosbags.highlevel import AnyReader
import yaml

from haptic_bringup.bag import BagWriter, FLUSH_PERIOD, recover, typestore_with

POSE = 'geometry_msgs/msg/PoseStamped'
STATE_DEFINITION = ('haptic_msgs/msg/Probe', 'std_msgs/Header header\nfloat64 distance\n')


def store():
    return typestore_with([STATE_DEFINITION])


def pose_cdr(typestore, index: int) -> bytes:
    types = typestore.types
    header = types['std_msgs/msg/Header'](
        stamp=types['builtin_interfaces/msg/Time'](sec=index, nanosec=7), frame_id='world')
    pose = types['geometry_msgs/msg/Pose'](
        position=types['geometry_msgs/msg/Point'](x=0.001 * index, y=0.0, z=-0.05),
        orientation=types['geometry_msgs/msg/Quaternion'](x=0.0, y=0.0, z=0.0, w=1.0))
    return typestore.serialize_cdr(types[POSE](header=header, pose=pose), POSE)


def probe_cdr(typestore, index: int) -> bytes:
    types = typestore.types
    header = types['std_msgs/msg/Header'](
        stamp=types['builtin_interfaces/msg/Time'](sec=index, nanosec=0), frame_id='world')
    return typestore.serialize_cdr(types['haptic_msgs/msg/Probe'](header=header,
                                                                  distance=-0.5 * index),
                                   'haptic_msgs/msg/Probe')


def write_bag(path: pathlib.Path, count: int) -> None:
    typestore = store()
    writer = BagWriter(path, typestore)
    writer.add_topic('/wand/pose', POSE)
    writer.add_topic('/probe', 'haptic_msgs/msg/Probe')
    for index in range(count):
        writer.write('/wand/pose', 1_000_000 * (index + 1), pose_cdr(typestore, index))
        writer.write('/probe', 1_000_000 * (index + 1) + 1, probe_cdr(typestore, index))
    writer.close()


def test_metadata_is_rosbag2_version_9_with_mcap_storage(tmp_path):
    write_bag(tmp_path / 'bag', 5)
    metadata = yaml.safe_load((tmp_path / 'bag' / 'metadata.yaml').read_text())
    info = metadata['rosbag2_bagfile_information']
    assert info['version'] == 9
    assert info['storage_identifier'] == 'mcap'
    assert info['message_count'] == 10
    assert {t['topic_metadata']['name']: t['message_count']
            for t in info['topics_with_message_count']} == {'/wand/pose': 5, '/probe': 5}


def test_rosbags_anyreader_reads_back_every_message(tmp_path):
    write_bag(tmp_path / 'bag', 20)
    with AnyReader([tmp_path / 'bag'], default_typestore=store()) as reader:
        poses = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages()
                 if c.topic == '/wand/pose']
    assert [p.header.stamp.sec for p in poses] == list(range(20))
    assert poses[7].pose.position.x == pytest.approx(0.007)


def test_mcap_ros2_support_decodes_the_custom_type_from_the_bag_alone(tmp_path):
    write_bag(tmp_path / 'bag', 4)
    with open(tmp_path / 'bag' / 'bag.mcap', 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        probes = [m.distance for _, channel, _, m in reader.iter_decoded_messages()
                  if channel.topic == '/probe']
    assert probes == [0.0, -0.5, -1.0, -1.5]


def _write_forever(path: str, progress: str) -> None:
    """Write poses until killed; every 50, the count and the writer's clock before and after.

    The kill may land in the middle of a line: a line is only read when it is whole.
    """
    typestore = store()
    writer = BagWriter(pathlib.Path(path), typestore)
    writer.add_topic('/wand/pose', POSE)
    index = 0
    with open(progress, 'w') as marks:
        while True:
            before = time.monotonic()
            writer.write('/wand/pose', time.time_ns(), pose_cdr(typestore, index))
            index += 1
            if index % 50 == 0:
                marks.write(f'{index} {before} {time.monotonic()}\n')
                marks.flush()
            time.sleep(0.0005)


def flushed_at_least(progress: pathlib.Path) -> int:
    """How many messages a writer killed after its last mark had surely flushed.

    It flushes at the first write ``FLUSH_PERIOD`` after its last flush, so the last flush came
    less than ``FLUSH_PERIOD`` before its last write, which began after the last mark's
    ``before``: every message written ``FLUSH_PERIOD`` before that was flushed. On a busy machine
    the writer's own clock says how many that is; its share of the two seconds does not (a
    writer that started late wrote faster than the average).
    """
    marks = [tuple(line.split()) for line in progress.read_text().splitlines(keepends=True)
             if line.endswith('\n') and len(line.split()) == 3]
    last_write = float(marks[-1][1])
    return max((int(count) for count, _, after in marks
                if float(after) <= last_write - FLUSH_PERIOD), default=0)


def test_a_bag_killed_with_sigkill_is_recovered_up_to_its_last_flush(tmp_path):
    bag, progress = tmp_path / 'killed', tmp_path / 'progress'
    writer = multiprocessing.get_context('fork').Process(target=_write_forever,
                                                         args=(str(bag), str(progress)))
    writer.start()
    time.sleep(2.0)
    os.kill(writer.pid, signal.SIGKILL)
    writer.join()
    assert not (bag / 'metadata.yaml').exists()
    recovered = recover(bag, store())
    with AnyReader([recovered], default_typestore=store()) as reader:
        stamps = [reader.deserialize(raw, c.msgtype).header.stamp.sec
                  for c, _, raw in reader.messages()]
    # Every message of every flushed chunk, in order, and none written FLUSH_PERIOD before the
    # end lost.
    assert stamps == list(range(len(stamps)))
    assert len(stamps) >= flushed_at_least(progress) > 0


def test_a_session_with_a_killed_site_is_refused_until_recovered_then_read_as_one(
        tmp_path, capsys):
    """A session folder holds a bag per site; one whose recorder was killed has no metadata."""
    from haptic_bringup.bag_tool import main
    from haptic_bringup.session import bags, topic_counts
    write_bag(tmp_path / 'scan' / 'operator', 3)
    typestore = store()
    killed = BagWriter(tmp_path / 'scan' / 'remote', typestore)
    killed.add_topic('/remote/wand/pose', POSE)
    for index in range(4):
        killed.write('/remote/wand/pose', 1_000_000 * (index + 1), pose_cdr(typestore, index))
    killed._writer.storage.flush_period = 0.0  # what FLUSH_PERIOD later would have flushed
    killed.flush_if_due()  # and then the recorder was killed: never closed
    with pytest.raises(ValueError, match='haptic_bag recover'):
        bags(tmp_path / 'scan')
    assert main(['recover', str(tmp_path / 'scan')]) == 0
    assert 'recovered' in capsys.readouterr().out
    assert [bag.name for bag in bags(tmp_path / 'scan')] == ['operator', 'remote-recovered']
    counts = {'/wand/pose': 3, '/probe': 3, '/remote/wand/pose': 4}
    assert topic_counts(tmp_path / 'scan') == counts
