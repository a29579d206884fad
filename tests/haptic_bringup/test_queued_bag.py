"""A bag written by its own thread: nothing put is lost, a full queue never blocks, idle flush."""
import shutil
import threading
import time

from rosbags.highlevel import AnyReader

from haptic_bringup.bag import recover, typestore_with
from haptic_bringup.queued_bag import QueuedBag

POSE = 'geometry_msgs/msg/PoseStamped'
WAIT = 30.0  # [s] the longest a test waits for the writer thread (a loaded machine)


def store():
    return typestore_with([])


def pose(typestore, index: int) -> bytes:
    """The CDR of a pose stamped ``index`` s (what the encoder under test is given)."""
    types = typestore.types
    header = types['std_msgs/msg/Header'](
        stamp=types['builtin_interfaces/msg/Time'](sec=index, nanosec=0), frame_id='world')
    return typestore.serialize_cdr(types[POSE](header=header, pose=types['geometry_msgs/msg/Pose'](
        position=types['geometry_msgs/msg/Point'](x=0.0, y=0.0, z=0.0),
        orientation=types['geometry_msgs/msg/Quaternion'](x=0.0, y=0.0, z=0.0, w=1.0))), POSE)


def stamps(bag, typestore) -> list:
    with AnyReader([bag], default_typestore=typestore) as reader:
        return [reader.deserialize(raw, c.msgtype).header.stamp.sec
                for c, _, raw in reader.messages()]


def test_every_message_put_is_encoded_by_the_writer_thread_and_written_in_order(tmp_path):
    typestore = store()
    threads = set()

    def encode(index):
        threads.add(threading.get_ident())
        return pose(typestore, index)
    bag = QueuedBag(tmp_path / 'bag', typestore)
    bag.add_topic('/wand/pose', POSE, encode=encode)
    assert all(bag.put('/wand/pose', index + 1, index) for index in range(500))
    bag.close()
    assert stamps(tmp_path / 'bag', typestore) == list(range(500))
    assert threads and threading.get_ident() not in threads
    assert bag.counts == {'/wand/pose': 500} and not bag.dropped


def test_a_full_queue_refuses_and_counts_without_blocking_and_keeps_what_it_took(tmp_path):
    typestore = store()
    stuck, release = threading.Event(), threading.Event()

    def encode(index):
        if index == 0:  # the writer thread holds the first message until released
            stuck.set()
            release.wait()
        return pose(typestore, index)
    bag = QueuedBag(tmp_path / 'bag', typestore, capacity=10)
    bag.add_topic('/wand/pose', POSE, encode=encode)
    bag.put('/wand/pose', 1, 0)
    assert stuck.wait(WAIT)
    taken = [bag.put('/wand/pose', index + 1, index) for index in range(1, 30)]
    release.set()
    bag.close()
    assert taken == [True] * 10 + [False] * 19
    assert bag.dropped == {'/wand/pose': 19}
    assert stamps(tmp_path / 'bag', typestore) == list(range(11))


def test_what_was_put_reaches_the_disk_while_the_queue_stays_idle(tmp_path):
    """What a ``kill -9`` would leave: a copy of the open bag, recovered."""
    typestore = store()
    bag = QueuedBag(tmp_path / 'bag', typestore)
    bag.add_topic('/wand/pose', POSE)
    for index in range(20):
        bag.put('/wand/pose', index + 1, pose(typestore, index))
    deadline = time.monotonic() + WAIT
    found = []
    while len(found) < 20 and time.monotonic() < deadline:
        time.sleep(0.1)
        shutil.rmtree(tmp_path / 'copy', ignore_errors=True)
        shutil.rmtree(tmp_path / 'copy-recovered', ignore_errors=True)
        shutil.copytree(tmp_path / 'bag', tmp_path / 'copy')
        found = stamps(recover(tmp_path / 'copy', typestore), typestore)
    bag.close()
    assert found == list(range(20))


def test_a_message_that_cannot_be_encoded_is_counted_with_why_and_the_rest_written(tmp_path):
    typestore = store()
    bag = QueuedBag(tmp_path / 'bag', typestore)
    bag.add_topic('/wand/pose', POSE, encode=lambda index: pose(typestore, index))
    for index in (0, 'not a stamp', 2):
        bag.put('/wand/pose', 1, index)
    bag.close()
    assert stamps(tmp_path / 'bag', typestore) == [0, 2]
    assert bag.dropped == {'/wand/pose': 1} and bag.error.startswith('/wand/pose: ')
