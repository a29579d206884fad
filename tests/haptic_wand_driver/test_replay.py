"""ReplayDevice: CSV and rosbag2 (mcap, sqlite3) round trips, playback options, bad recordings."""

from ground_truth.wand import quaternion_from_matrix, rotation_x, rotation_y, rotation_z
import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import get_typestore, Stores

from haptic_wand_driver.pose_table import PoseTable, write_pose_csv
from haptic_wand_driver.replay import ReplayDevice, ReplayError

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
SAMPLE = 0.002
BAG_START_NS = 1_700_000_000_250_000_000
CSV_START = 12.25


def trajectory(t):
    """A smooth 5-DOF path with its exact rates: ((n, 5) coordinates, (n, 5) rates)."""
    t = np.asarray(t, dtype=float)
    w = np.pi
    coordinates = np.stack([0.03 * np.sin(w * t), 0.02 * np.cos(w * t), -0.01 * t,
                            0.2 * np.sin(t), 0.3 * np.sin(2 * t)], axis=-1)
    rates = np.stack([0.03 * w * np.cos(w * t), -0.02 * w * np.sin(w * t), np.full_like(t, -0.01),
                      0.2 * np.cos(t), 0.6 * np.cos(2 * t)], axis=-1)
    return coordinates, rates


def sample_times():
    return np.arange(0.0, 2.0 + SAMPLE / 2, SAMPLE)


def write_csv(path):
    times = sample_times()
    write_pose_csv(path, PoseTable(CSV_START + times, trajectory(times)[0]))
    return path


def pose_message(nanoseconds, coordinates, pitch=0.0):
    msgs = TYPESTORE.types
    x, y, z, roll, yaw = coordinates
    qx, qy, qz, qw = quaternion_from_matrix(rotation_z(yaw) @ rotation_y(pitch) @ rotation_x(roll))
    return msgs['geometry_msgs/msg/PoseStamped'](
        header=msgs['std_msgs/msg/Header'](
            stamp=msgs['builtin_interfaces/msg/Time'](sec=nanoseconds // 10 ** 9,
                                                      nanosec=nanoseconds % 10 ** 9),
            frame_id='world'),
        pose=msgs['geometry_msgs/msg/Pose'](
            position=msgs['geometry_msgs/msg/Point'](x=x, y=y, z=z),
            orientation=msgs['geometry_msgs/msg/Quaternion'](x=qx, y=qy, z=qz, w=qw)))


def write_bag(path, storage=StoragePlugin.MCAP, topic='/wand/pose', pitch=0.0, count=None):
    times = sample_times()[:count]
    coordinates = trajectory(times)[0]
    with Writer(path, version=9, storage_plugin=storage) as writer:
        other = writer.add_connection('/wand/twist', 'geometry_msgs/msg/TwistStamped',
                                      typestore=TYPESTORE)
        poses = writer.add_connection(topic, 'geometry_msgs/msg/PoseStamped',
                                      typestore=TYPESTORE)
        for index, (t, row) in enumerate(zip(times, coordinates)):
            stamp = BAG_START_NS + round(t * 1e9)
            message = pose_message(stamp, row, pitch if index == 3 else 0.0)
            writer.write(poses, stamp,
                         TYPESTORE.serialize_cdr(message, 'geometry_msgs/msg/PoseStamped'))
        writer.write(other, BAG_START_NS, TYPESTORE.serialize_cdr(
            TYPESTORE.types['geometry_msgs/msg/TwistStamped'](
                header=TYPESTORE.types['std_msgs/msg/Header'](
                    stamp=TYPESTORE.types['builtin_interfaces/msg/Time'](sec=0, nanosec=0),
                    frame_id='world'),
                twist=TYPESTORE.types['geometry_msgs/msg/Twist'](
                    linear=TYPESTORE.types['geometry_msgs/msg/Vector3'](x=0.0, y=0.0, z=0.0),
                    angular=TYPESTORE.types['geometry_msgs/msg/Vector3'](x=0.0, y=0.0, z=0.0))),
            'geometry_msgs/msg/TwistStamped'))
    return path


def assert_plays_the_trajectory(replay):
    """Compare playback at off-sample instants with the analytic path and its derivative."""
    clock = 50.0
    assert replay.read(clock).time == clock
    for t in np.arange(0.0013, 1.99, 0.0371):
        state = replay.read(clock + t)
        coordinates, rates = trajectory(t)
        np.testing.assert_allclose(state.coordinates, coordinates, atol=1e-6)
        np.testing.assert_allclose(state.rates, rates, atol=2e-5)


def test_csv_round_trip(tmp_path):
    assert_plays_the_trajectory(ReplayDevice(write_csv(tmp_path / 'track.csv')))


@pytest.mark.parametrize('storage', [StoragePlugin.MCAP, StoragePlugin.SQLITE3])
def test_bag_round_trip(tmp_path, storage):
    bag = write_bag(tmp_path / 'bag', storage)
    assert_plays_the_trajectory(ReplayDevice(bag))
    single_file = next(p for p in bag.iterdir() if p.suffix in ('.mcap', '.db3'))
    assert_plays_the_trajectory(ReplayDevice(single_file))


def test_bag_quaternions_match_csv_angles(tmp_path):
    from_bag = ReplayDevice(write_bag(tmp_path / 'bag'))
    from_csv = ReplayDevice(write_csv(tmp_path / 'track.csv'))
    for now in (0.0, 0.5, 1.234):
        np.testing.assert_allclose(from_bag.read(now).orientation, from_csv.read(now).orientation,
                                   atol=1e-12)


def test_time_scale_and_start_offset(tmp_path):
    replay = ReplayDevice(write_csv(tmp_path / 'track.csv'), time_scale=2.0, start_offset=0.5)
    replay.read(10.0)
    state = replay.read(10.3)
    coordinates, rates = trajectory(0.5 + 2.0 * 0.3)
    np.testing.assert_allclose(state.coordinates, coordinates, atol=1e-6)
    np.testing.assert_allclose(state.rates, 2.0 * rates, atol=4e-5)


def test_without_loop_the_last_pose_is_held_at_rest(tmp_path):
    replay = ReplayDevice(write_csv(tmp_path / 'track.csv'))
    replay.read(0.0)
    state = replay.read(5.0)
    np.testing.assert_allclose(state.coordinates, trajectory(2.0)[0], atol=1e-12)
    np.testing.assert_array_equal(state.rates, np.zeros(5))


def test_loop_starts_over(tmp_path):
    replay = ReplayDevice(write_csv(tmp_path / 'track.csv'), loop=True)
    assert replay.duration == pytest.approx(2.0)
    replay.read(0.0)
    np.testing.assert_allclose(replay.read(2.0 + 0.7).coordinates, trajectory(0.7)[0], atol=1e-6)


def test_applied_wrench_is_ignored_and_limits_are_zero(tmp_path):
    replay = ReplayDevice(write_csv(tmp_path / 'track.csv'))
    replay.read(0.0)
    replay.apply(np.array([5.0, 0.0, 0.0]), np.zeros(3))
    np.testing.assert_allclose(replay.read(0.5).coordinates, trajectory(0.5)[0], atol=1e-6)
    assert replay.limits.force_limit == 0.0 and replay.limits.torque_limit == 0.0
    assert replay.limits.workspace.lower[2] == pytest.approx(-0.02)


def test_missing_and_unsupported_files(tmp_path):
    text = tmp_path / 'track.txt'
    text.write_text('t,x,y,z\n')
    for path, expected in ((tmp_path / 'nothing.csv', 'no such file'),
                           (text, 'unsupported recording type')):
        with pytest.raises(ReplayError, match=expected) as raised:
            ReplayDevice(path)
        assert str(path) in str(raised.value)


def test_malformed_csv_names_the_file(tmp_path):
    path = tmp_path / 'track.csv'
    path.write_text('t,x,y\n0,0,0\n')
    with pytest.raises(ReplayError, match=r'lacks column\(s\) z') as raised:
        ReplayDevice(path)
    assert str(path) in str(raised.value)


def test_bag_without_the_topic(tmp_path):
    bag = write_bag(tmp_path / 'bag', topic='/other/pose')
    with pytest.raises(ReplayError, match="no topic '/wand/pose'.*/other/pose") as raised:
        ReplayDevice(bag)
    assert str(bag) in str(raised.value)


def test_bag_with_the_topic_of_another_type(tmp_path):
    bag = tmp_path / 'bag'
    with Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection('/wand/pose', 'std_msgs/msg/String',
                                           typestore=TYPESTORE)
        writer.write(connection, 1, TYPESTORE.serialize_cdr(
            TYPESTORE.types['std_msgs/msg/String'](data='hi'), 'std_msgs/msg/String'))
    with pytest.raises(ReplayError, match='has type std_msgs/msg/String, expected '
                                          'geometry_msgs/msg/PoseStamped'):
        ReplayDevice(bag)


def test_bag_pose_with_pitch_names_the_message(tmp_path):
    with pytest.raises(ReplayError, match='message 3: .*pitch'):
        ReplayDevice(write_bag(tmp_path / 'bag', pitch=0.2))


def test_corrupt_and_foreign_bags(tmp_path):
    corrupt = tmp_path / 'broken.mcap'
    corrupt.write_bytes(b'not an mcap file at all' * 10)
    folder = tmp_path / 'folder'
    folder.mkdir()
    for path in (corrupt, folder):
        with pytest.raises(ReplayError, match='cannot open as a rosbag2 recording') as raised:
            ReplayDevice(path)
        assert str(path) in str(raised.value)


def test_a_single_pose_cannot_be_replayed(tmp_path):
    with pytest.raises(ReplayError, match='at least two poses'):
        ReplayDevice(write_bag(tmp_path / 'bag', count=1))


@pytest.mark.parametrize('options, expected', [(dict(time_scale=0.0), 'time_scale'),
                                               (dict(start_offset=2.5), 'start_offset'),
                                               (dict(start_offset=-0.1), 'start_offset')])
def test_bad_options_are_refused(tmp_path, options, expected):
    with pytest.raises(ReplayError, match=expected):
        ReplayDevice(write_csv(tmp_path / 'track.csv'), **options)


def test_playback_interpolates_each_coordinate_linearly_between_samples(tmp_path):
    rng = np.random.default_rng(3)
    times = np.cumsum(rng.uniform(0.0005, 0.002, size=200))
    coordinates = np.column_stack([rng.uniform(-0.05, 0.05, size=(200, 3)),
                                   rng.uniform(-0.4, 0.4, size=(200, 2))])
    path = tmp_path / 'noisy.csv'
    write_pose_csv(path, PoseTable(times, coordinates))
    device = ReplayDevice(path)
    device.read(10.0)  # starts playback at the first sample
    queries = np.concatenate([rng.uniform(0.0, times[-1] - times[0], 50), times[:5] - times[0]])
    for elapsed in np.sort(queries):
        state = device.read(10.0 + elapsed)
        expected = [np.interp(times[0] + elapsed, times, column) for column in coordinates.T]
        np.testing.assert_allclose(state.coordinates, expected, rtol=0, atol=1e-12)
