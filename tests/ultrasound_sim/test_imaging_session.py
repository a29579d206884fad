"""The probe's image in a telerobotic session: made at the remote site, seen and recorded at the
operator's, across the delayed link (one model scan checks it all); and a scanner given a bad
configuration stops at once, naming what to fix.

Truths come from outside the imaging: the frame's stamp is one of the poses the robot published
(its bag), the delay is the link's, and the contact is the robot's F/T sensor's (the tissue's
Hunt-Crossley force, which shares no code with the imaging's coupling).
"""
import math
import pathlib
import signal
import subprocess
import sys
import time

from domains import session_domain_id
from geometry_msgs.msg import PoseStamped
import numpy as np
import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from sensor_msgs.msg import Image

from haptic_bringup.bag import typestore_with
from haptic_bringup.launcher import Loop, loop_environment, LoopConfig
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import read_frames, read_vectors, reported
from haptic_util.qos import FRAME_QOS, HAPTIC_STREAM_QOS
from haptic_util.stamps import to_nanoseconds

DELAY = 0.05  # [s] one way, 5 ms jitter
FRAME_RATE = 30.0  # [Hz] the imager's default
SKIN = -0.025  # [m] the phantom's front at x = y = 0, where the scan presses
PRESSED = 2.0  # [N] on the patient: the probe's face is in the skin
SIZE = (256, 256)


@pytest.fixture(scope='module')
def session(tmp_path_factory):
    folder = tmp_path_factory.mktemp('imaging_scan')
    config = LoopConfig(teleop='model', duration=9.0, record=str(folder / 'bag'),
                        domain_id=session_domain_id(),
                        remote_domain=session_domain_id(second=True), run_dir=folder / 'launch',
                        link={'delay': DELAY, 'jitter': 0.1 * DELAY}, imaging=True)
    with Loop(config) as loop:
        assert loop.wait(60.0) is not None, 'the scan did not end'
    typestore = typestore_with(custom_definitions())
    bag = folder / 'bag'
    robot = read_vectors(bag, typestore, {'/remote/robot/tcp_pose': 'pose',
                                          '/remote/robot/ft_sensor/wrench': 'wrench'},
                         stamped=True)
    return read_frames(bag, typestore), robot, bag, typestore


def test_the_operator_records_the_image_at_the_frame_rate_stamped_and_framed(session):
    frames, _, _, _ = session
    assert len(frames.stamp) > 3 * FRAME_RATE
    assert frames.images.shape[1:] == SIZE and frames.frame_ids == {'ultrasound_probe'}
    assert np.all(np.diff(frames.stamp) > 0.0)  # each from a newer pose, in order
    assert np.median(np.diff(frames.stamp)) == pytest.approx(1.0 / FRAME_RATE, rel=0.1)


def test_each_frame_is_stamped_with_a_pose_the_robot_published_and_crossed_the_link(session):
    frames, robot, _, _ = session
    poses = robot['/remote/robot/tcp_pose'][0]
    assert np.isin(frames.stamp, poses).all()
    latency = frames.received - frames.stamp  # one clock: both sites on this machine
    assert np.min(latency) > DELAY - 4 * 0.1 * DELAY
    assert np.median(latency) > DELAY


def test_the_image_shows_tissue_where_the_probe_presses_and_nothing_in_air(session):
    frames, robot, _, _ = session
    pose_times, tcp = robot['/remote/robot/tcp_pose']
    force_times, force = robot['/remote/robot/ft_sensor/wrench']
    pressing = np.interp(frames.stamp, force_times, np.linalg.norm(force, axis=1)) > PRESSED
    height = np.interp(frames.stamp, pose_times, tcp[:, 2])
    in_air = height > SKIN + 0.002
    assert pressing.sum() > FRAME_RATE and in_air.sum() > FRAME_RATE  # the scan does both
    brightness = frames.images.reshape(len(frames.stamp), -1).mean(axis=1)
    assert np.all(brightness[in_air] == 0.0)
    assert np.all(brightness[pressing] > 20.0)
    columns_dark = (frames.images[pressing].max(axis=1) == 0).mean()
    assert columns_dark < 0.05  # pressed flat: every scanline coupled


def test_the_imager_made_every_frame_from_good_poses_and_nothing_was_dropped(session):
    _, _, bag, typestore = session
    dark = reported(bag, typestore, 'dark')['probe_imager']
    assert dark[-1] == '0'  # no pose it could not image
    assert reported(bag, typestore, 'dropped')['operator_recorder'][-1] == '0'


def run_imager(tmp_path: pathlib.Path, *parameters: str) -> str:
    """Start the node with ``parameters``; return its one error line (it must exit with 2)."""
    args = [sys.executable, '-m', 'ultrasound_sim.node', '--ros-args']
    for parameter in parameters:
        args += ['-p', parameter]
    result = subprocess.run(args, env=loop_environment(session_domain_id(), tmp_path / 'log'),
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 2, result.stderr
    lines = [line for line in result.stderr.splitlines() if line.startswith('error:')]
    assert len(lines) == 1, result.stderr
    return lines[0]


@pytest.mark.parametrize('parameters, words', [
    (('probe_type:=phased', 'depth:=0.0'), ['probe_imager', 'probe_type', 'phased']),
    (('scene_file:=package://collision_engine/scenes/probe_phantom.yaml',),
     ['probe_phantom.yaml', 'no acoustic properties']),
])
def test_a_badly_configured_scanner_stops_at_start_naming_what_to_fix(tmp_path, parameters,
                                                                      words):
    line = run_imager(tmp_path, *parameters)
    for word in words:
        assert word in line


def test_a_pose_that_cannot_be_imaged_gives_a_dark_frame_with_its_reason_logged(tmp_path):
    """The node alone, fed by the test: each pose imaged once, a bad one dark and its reason."""
    domain_id = session_domain_id()
    node = subprocess.Popen([sys.executable, '-m', 'ultrasound_sim.node'],
                            env=loop_environment(domain_id, tmp_path / 'log'),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        feeder = Node('test_robot', context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(feeder)
        frames = {}
        feeder.create_subscription(Image, 'probe/image', lambda msg: frames.setdefault(
            to_nanoseconds(msg.header.stamp), msg), FRAME_QOS)
        poses = feeder.create_publisher(PoseStamped, 'robot/tcp_pose', HAPTIC_STREAM_QOS)
        shown = {}
        for frame_id, z in (('base_link', SKIN - 0.003), ('base_link', math.nan),
                            ('world', SKIN - 0.003), ('base_link', SKIN + 0.001)):
            pose = PoseStamped()
            pose.header.frame_id, pose.pose.position.z = frame_id, z
            pose.header.stamp = feeder.get_clock().now().to_msg()
            stamp = to_nanoseconds(pose.header.stamp)
            deadline = time.monotonic() + 60.0  # the node's start: imports and its warm-up
            while stamp not in frames and time.monotonic() < deadline:
                poses.publish(pose)  # again until it is imaged: a best-effort stream
                executor.spin_once(timeout_sec=0.05)
            assert stamp in frames, f'no frame of the pose {frame_id} z={z}'
            shown[(frame_id, z)] = np.asarray(frames[stamp].data).mean()
        deadline = time.monotonic() + 2.5  # its 1 Hz report logs what went dark
        while time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.05)
    finally:
        rclpy.try_shutdown(context=context)
        node.send_signal(signal.SIGINT)
        log, _ = node.communicate(timeout=30)
    assert node.returncode == 0, log
    assert list(shown.values())[0] > 20.0  # pressed: tissue
    assert all(value == 0.0 for value in list(shown.values())[1:]), shown
    assert 'dark frame' in log and "'world', not 'base_link'" in log, log


# Frames far slower than their period: 256 lines of 2048 samples take about 37 ms of CPU here,
# against 5 ms between frames.
OVERLOADED = ('frame_rate:=200.0', 'scanlines:=256', 'samples:=2048')
OVERLOAD_TIME = 4.0  # [s] of frames watched


def test_an_imager_asked_for_more_frames_than_it_makes_drops_them_and_images_the_newest_pose(
        tmp_path):
    """The node alone, fed a pose each turn of the test's loop: frames come as fast as it makes
    them, each from a pose the feeder sent shortly before it arrived. A queue of the frames
    asked for would fall behind by a second for each second watched."""
    domain_id = session_domain_id()
    command = [sys.executable, '-m', 'ultrasound_sim.node', '--ros-args']
    for parameter in OVERLOADED:
        command += ['-p', parameter]
    node = subprocess.Popen(command, env=loop_environment(domain_id, tmp_path / 'log'),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    arrivals = []  # (the feeder's newest stamp when the frame arrived, the frame's stamp) ns
    newest, first = [0], None
    try:
        feeder = Node('test_robot', context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(feeder)
        feeder.create_subscription(Image, 'probe/image', lambda msg: arrivals.append(
            (newest[0], to_nanoseconds(msg.header.stamp))), FRAME_QOS)
        poses = feeder.create_publisher(PoseStamped, 'robot/tcp_pose', HAPTIC_STREAM_QOS)
        pose = PoseStamped()
        pose.header.frame_id, pose.pose.position.z = 'base_link', SKIN - 0.003
        deadline = time.monotonic() + 60.0  # the node's start: imports and its warm-up
        while time.monotonic() < deadline:
            pose.header.stamp = feeder.get_clock().now().to_msg()
            newest[0] = to_nanoseconds(pose.header.stamp)
            poses.publish(pose)
            executor.spin_once(timeout_sec=0.001)
            if first is None and arrivals:  # the first frame: watch the next ones
                deadline, first = time.monotonic() + OVERLOAD_TIME, len(arrivals)
    finally:
        rclpy.try_shutdown(context=context)
        node.send_signal(signal.SIGINT)
        log, _ = node.communicate(timeout=30)
    assert node.returncode == 0, log
    watched = np.array(arrivals[first:], dtype=np.int64)
    assert len(watched) > 4, log  # it makes frames
    assert len(watched) < 0.5 * 200.0 * OVERLOAD_TIME  # and drops most of those asked for
    assert np.all(np.diff(watched[:, 1]) > 0)  # each from a newer pose
    age = 1e-9 * (watched[:, 0] - watched[:, 1])  # the pose's age when its frame arrived
    assert age.max() < 0.25 * OVERLOAD_TIME, age
