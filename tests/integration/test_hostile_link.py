"""A telerobotic session under attack from the remote site's network: the patient stays safe.

Both sites run as real processes over their gateways, their streams through DDS as a real
arm's would be. A stranger process joins the remote site's DDS domain and, one after another:
forges a command of another session stamped 10 s ahead; reads the operator's session and forges
one in it, 10 s ahead, one numbered 2**63, and one at 1e308 m/s; sends malformed bytes on the
command topic at 50 Hz; floods commands, asked at 20 kHz (below the sites' priority, it got
770-5353 a second in three runs with a core hogged); forges a target 60 mm deep, then a
TCP pose 50 mm below the real one (from which the commanding node would let its target go
deeper, and learn a contact no patient has).
Every figure comes from the bag (the patient's F/T force, the wand's poses, the planes sent to
the operator) or from the nodes' own reports, never from their internals.
"""
import contextlib
import math
import os
import time

from domains import session_domain_id
from geometry_msgs.msg import PoseStamped
import numpy as np
import pytest
import rclpy
from rclpy.context import Context
from rclpy.node import Node
from rosbags.highlevel import AnyReader
from test_teleop import (DELAY, FORCE_SCALE, reports, streams, wait_for_the_session_start,
                         window)

from haptic_bringup.bag import typestore_with
from haptic_bringup.launcher import Loop, LoopConfig, SCAN_DURATION
from haptic_bringup.recorder import custom_definitions
from haptic_contract.streams import POSE, WRENCH
from haptic_contract.teleop_fields import COMMAND
from haptic_msgs.msg import TeleopCommand
from haptic_util.newest import NewestMessage
from haptic_util.qos import HAPTIC_STREAM_QOS
from haptic_util.tally import Tally

MAX_PATIENT_FORCE = 20.0  # [N] the follower's and the robot's default
PRESSING = 4.0  # [N] the patient's force once the scan presses (8 N, less on a loaded machine)
# The attacks on the link's content, each after a quiet window: alternated, so that the scan's
# own changes (deeper, then sweeping) fall in both.
CONTENT = ('another session', 'ahead', 'numbered far ahead', 'absurd speed', 'malformed')
QUIET = 0.5  # [s] pressed and not attacked, just before each attack on the content
# Both sites' 1 kHz processes and their gateways run real-time, as README asks of a session
# on a shared machine: the stranger does not outrank them (CI runs as root). At normal
# scheduling, on 2 cores, the link stalled 0.1-0.25 s now and then, attacked or not, and each
# stall held the robot back and cost the scan force for good.
SESSION_PRIORITY = 50
# The stranger stands for another host on the network, with a CPU of its own: its process runs
# real-time above the sites, so that their 1.3-1.9 of this machine's 2 cores do not starve what
# it sends. Below them, its publishing thread woke up to 0.8 s late and sent 1-16 of an attack's
# 25 (6 in a CI run); above them it sends all 25. Its flood, which would take a core here, it
# sends below the sites: another host would bring that core.
STRANGER_PRIORITY = SESSION_PRIORITY + 10
FLOOD_PRIORITY = SESSION_PRIORITY - 10
HELD = 0.375  # of the quiet windows' median force: pressed still (a robot let go retracts to 0)


def quiet_windows(windows: dict) -> list:
    return [name for name in windows if name.startswith('quiet before')]


def spans(windows: dict, names) -> list:
    """Return the (start, end) of each named window."""
    return [windows[name][:2] for name in names]


def during(times: np.ndarray, windows: dict, names) -> np.ndarray:
    """Which of ``times`` fall in any of the named windows."""
    return np.any([window(times, *span) for span in spans(windows, names)], axis=0)


def rate(times: np.ndarray, intervals) -> float:
    """Messages a second stamped ``times`` over the (start, end) ``intervals`` together."""
    count = sum(np.count_nonzero(window(times, start, end)) for start, end in intervals)
    return count / sum(end - start for start, end in intervals)


class Stranger:
    """A process on the remote site's network: it hears and publishes what it likes.

    It takes what it heard in the thread that publishes, just before it publishes: no thread of
    its own spinning an executor, which would hold Python's lock at its own priority while the
    sends wait for it.
    """

    LISTEN_PERIOD = 0.01  # [s] while publishing, what it heard is taken no more often than this

    def __init__(self, domain: int) -> None:
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = Node('stranger', context=self.context)
        self.heard = None  # the operator's latest command, as fields
        self.pressed = 0.0  # [N] the patient's force, as the robot's sensor says
        refused = Tally()  # its own malformed commands, heard back
        self._commands = NewestMessage(self.node, COMMAND, 'teleop/command', refused=refused)
        self._wrenches = NewestMessage(self.node, WRENCH, 'robot/ft_sensor/wrench',
                                       refused=refused)
        self.command = self.node.create_publisher(TeleopCommand, 'teleop/command',
                                                  HAPTIC_STREAM_QOS)
        self.target = self.node.create_publisher(PoseStamped, 'robot/target_pose',
                                                 HAPTIC_STREAM_QOS)
        self.tcp = self.node.create_publisher(PoseStamped, 'robot/tcp_pose', HAPTIC_STREAM_QOS)

    def listen(self) -> None:
        """Take the newest command and force, if any came since the last call."""
        command, wrench = self._commands.take(), self._wrenches.take()
        if command is not None:
            self._hear(command)
        if wrench is not None:
            self.pressed = abs(wrench[WRENCH.index('wrench.force.z')])

    def _hear(self, fields) -> None:
        """Keep the operator's latest command: not one of ours, which it also hears."""
        session = fields[COMMAND.index('session')]
        stamp = fields[COMMAND.index('header.stamp.sec')]
        if self.heard is None or (session == self.heard[COMMAND.index('session')]
                                  and fields[COMMAND.index('sequence')] < 2**62
                                  and stamp < time.time() + 1.0
                                  and abs(fields[COMMAND.index('velocity.x')]) < 100.0):
            self.heard = fields

    def forged_command(self, *, session=None, sequence=None, sequence_step=1, ahead=0.0,
                       velocity=0.0) -> bytes:
        """A command like the operator's latest, in its session unless told, changed as asked."""
        fields = list(self.heard)
        now = time.time() + ahead
        fields[COMMAND.index('header.stamp.sec')] = int(now)
        fields[COMMAND.index('header.stamp.nanosec')] = int(now % 1 * 1e9)
        if session is not None:
            fields[COMMAND.index('session')] = session
        fields[COMMAND.index('sequence')] = (sequence if sequence is not None else
                                             fields[COMMAND.index('sequence')] + sequence_step)
        fields[COMMAND.index('velocity.x')] = velocity
        return COMMAND.encode(fields)

    def pose(self, frame: str, z_offset: float) -> bytes:
        """A pose in ``frame``, ``z_offset`` m from the real TCP's last commanded position."""
        now = time.time()
        position = self.heard[COMMAND.index('position.x'):COMMAND.index('position.z') + 1]
        return POSE.encode((int(now), int(now % 1 * 1e9), frame, position[0], position[1],
                            position[2] + z_offset, 0.0, 0.0, 0.0, 1.0))

    def repeat(self, publisher, make, rate: float, duration: float) -> int:
        """Publish ``make()`` at ``rate`` Hz for ``duration`` s; return how many."""
        sent, start, listened = 0, time.monotonic(), -math.inf
        while time.monotonic() - start < duration:
            if time.monotonic() - listened >= self.LISTEN_PERIOD:
                self.listen()
                listened = time.monotonic()
            publisher.publish(make())
            sent += 1
            lag = start + sent / rate - time.monotonic()
            if lag > 0:
                time.sleep(lag)
        return sent

    def close(self) -> None:
        self._commands.destroy()
        self._wrenches.destroy()
        self.node.destroy_node()
        self.context.try_shutdown()


@contextlib.contextmanager
def realtime(priority: int):
    """Run the calling thread under SCHED_FIFO at ``priority`` meanwhile, if it may."""
    before = os.sched_getscheduler(0), os.sched_getparam(0)
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except PermissionError:
        pass  # the sites then run at normal scheduling too (their nodes say so)
    try:
        yield
    finally:
        os.sched_setscheduler(0, *before)


def malformed(count: int):
    """Bytes that start like a TeleopCommand and name string lengths that cannot fit."""
    for k in range(count):
        yield b'\x00\x01\x00\x00' + bytes(8) + (1000 + k).to_bytes(4, 'little') + b'base_link'


@pytest.fixture(scope='module')
def attacked(tmp_path_factory):
    folder = tmp_path_factory.mktemp('hostile')
    config = LoopConfig(teleop='model', duration=SCAN_DURATION, record=str(folder / 'bag'),
                        domain_id=session_domain_id(),
                        remote_domain=session_domain_id(second=True), run_dir=folder / 'launch',
                        intra_process=False, link={'delay': DELAY, 'jitter': 0.1 * DELAY},
                        thread_priority=SESSION_PRIORITY)
    windows = {}
    # The stranger is on the network before the sites start, as one would be. One that joined
    # mid-session stalled the real-time sites for 0.2-0.34 s as the patient was first pressed,
    # and the scan never pressed 4 N (a CI run). The cause is not found (README, real-time
    # priority).
    with realtime(STRANGER_PRIORITY):  # and so its DDS threads, which inherit it
        stranger = Stranger(config.remote_domain_id)
    try:
        with Loop(config) as loop:
            # From the session's start: a fresh clone's first session compiles its kernels first.
            deadline = wait_for_the_session_start(config.domain_id, 180.0) + 30.0
            # Both of the stranger's subscriptions must have matched: under load its command
            # reader was once discovered after the patient was pressed (a CI run).
            while ((stranger.heard is None or stranger.pressed < PRESSING)
                   and time.monotonic() < deadline):
                time.sleep(0.05)
                stranger.listen()
            assert stranger.heard is not None, 'the operator\'s commands were never heard'
            assert stranger.pressed >= PRESSING, 'the scan never pressed the patient'
            session = stranger.heard[COMMAND.index('session')]

            def attack(name, publisher, make, rate, duration):
                if name in CONTENT:  # pressed, not attacked: what the attack is compared with
                    quiet = time.time()
                    time.sleep(QUIET)
                    windows[f'quiet before {name}'] = (quiet, time.time(), 0)
                start = time.time()
                with realtime(FLOOD_PRIORITY if name == 'flood' else STRANGER_PRIORITY):
                    sent = stranger.repeat(publisher, make, rate, duration)
                windows[name] = (start, time.time(), sent)
            attack('another session', stranger.command,
                   lambda: stranger.forged_command(session=session ^ 1, ahead=10.0), 50, 0.5)
            attack('ahead', stranger.command,  # numbered past the operator's next ones, what
                   # the stranger heard lagging what the follower took by up to 0.1 s here
                   lambda: stranger.forged_command(ahead=10.0, sequence_step=500), 50, 0.5)
            attack('numbered far ahead', stranger.command,
                   lambda: stranger.forged_command(sequence=2**63), 50, 0.5)
            attack('absurd speed', stranger.command,
                   lambda: stranger.forged_command(velocity=-1.7e308), 50, 0.5)
            bytes_out = malformed(10_000)
            attack('malformed', stranger.command, lambda: next(bytes_out), 50, 1.0)
            attack('flood', stranger.command,
                   lambda: stranger.forged_command(session=session ^ 1), 20_000, 1.0)
            recovered = time.time()
            time.sleep(2.0)  # nothing sent: the session goes on by itself, or not
            windows['after the flood'] = (recovered, time.time(), 0)
            attack('deep target', stranger.target, lambda: stranger.pose('base_link', -0.06),
                   1000, 0.5)
            attack('tcp below', stranger.tcp, lambda: stranger.pose('base_link', -0.05),
                   2000, 0.5)
            assert loop.wait(60.0) is not None, 'the scan did not end'
    finally:
        stranger.close()
    return folder, streams(folder), windows


def test_the_patient_is_never_pressed_past_the_limit_nor_let_go(attacked):
    """Pressed within the limit through every attack, and never let go through those on the
    link's content: had one locked the operator out, the robot would have held and retracted
    to no force. Pressed still means a median force in each of those attacks, and in the quiet
    windows between them, of more than ``HELD`` of the quiet windows' median (3 N of the scan's
    8 N): on a slow or loaded machine the scan presses less (a CI run pressed 3.4 N as the
    attacks began, 2.9 N as they ended, and failed 3 N). A median, not the least: should the
    link stall for 0.1 s, attacked or not, the robot holds and retracts for a moment, as it
    must. A lockout holds it at no force for good: the next window's median shows that, and
    after the last attack on the content, the flood and the check after it do.

    A 20 kHz flood costs the remote site's one Python process about half a core to refuse,
    stranger by stranger: on a loaded machine it may fall behind the operator's commands, and
    then holds as on a silent link. That stays safe, and it follows again once the flood ends;
    shedding a flood before the site is the authenticated gateway's part (issue 27). Following
    again, it presses as the hand feels, as after a stalled gateway (``test_teleop``): the
    operator's feedback lapsed meanwhile, the hand sank feeling nothing, and passivity gives back
    no push the device's port has not taken in. A hand that presses harder gets it back; the
    scripted one is a fixed spring, so with a core hogged it may press on less than before.
    """
    _, series, windows = attacked
    times, patient = series['/remote/robot/ft_sensor/wrench']
    force = np.linalg.norm(patient, axis=1)
    assert force.max() <= MAX_PATIENT_FORCE
    pressed = np.median(force[during(times, windows, quiet_windows(windows))])
    assert pressed > 3.0
    for name in (*CONTENT, *quiet_windows(windows)):
        assert np.median(force[during(times, windows, [name])]) > HELD * pressed, name
    _, end, _ = windows['after the flood']
    felt_times, felt = series['/wand/applied_wrench']
    felt_after = np.median(np.linalg.norm(felt[window(felt_times, end - 0.5, end)], axis=1))
    pressed_after = np.median(force[window(times, end - 0.5, end)])
    print(f'\nafter the flood: the patient {pressed_after:.2f} N, felt {felt_after:.2f} N')
    assert pressed_after > 1.0  # following and pressing again, not let go
    assert felt_after / FORCE_SCALE == pytest.approx(pressed_after, rel=0.2)  # as the hand feels


def test_the_operator_s_site_keeps_its_rate_through_every_attack(attacked):
    """The attacks reach the remote site only: the operator's site goes on at its rate (a forged
    echo once took it from 954 Hz to 0 for the rest of the run). Through the attacks on the
    link's content it keeps 80 % of its rate in the quiet windows between them, pressed as in
    them: a slow machine's loop runs slower in contact (with a core busy, 560-620 Hz pressed
    against 700-830 Hz in the approach), and its rate wanders as the scan presses deeper and
    sweeps (here 460-950 Hz in half-second windows), which alternation shares between both. A
    CI run compared the attacks with the second before them all, and they got 0.72 of it. In
    no attack does the site stop. The stranger's flood takes one of this machine's two cores:
    during it, the operator's site may get less of the machine, which is not what is tested
    here."""
    _, series, windows = attacked
    poses = series['/wand/pose'][0]

    def rate_in(names):
        return rate(poses, spans(windows, names))
    quiet, under_attack = rate_in(quiet_windows(windows)), rate_in(CONTENT)
    print(f'\nthe operator\'s site: {under_attack:.0f} Hz through the attacks on the content, '
          f'{quiet:.0f} Hz in the quiet windows between them; by window, '
          + ', '.join(f'{name} {rate_in([name]):.0f}' for name in windows))
    assert under_attack >= 0.8 * quiet
    for name in windows:
        assert rate_in([name]) >= 0.25 * quiet, name


def planes(folder) -> tuple[np.ndarray, np.ndarray]:
    """When the operator's site recorded each feedback with a plane (s), and its point (m)."""
    with AnyReader([folder / 'bag' / 'operator'],
                   default_typestore=typestore_with(custom_definitions())) as reader:
        connections = [c for c in reader.connections if c.topic == '/teleop/feedback']
        rows = [(stamp * 1e-9, message.plane.point)
                for message, stamp in ((reader.deserialize(raw, c.msgtype), stamp)
                                       for c, stamp, raw in reader.messages(connections))
                if message.kind == message.KIND_PLANE]
    return (np.array([time for time, _ in rows]),
            np.array([(point.x, point.y, point.z) for _, point in rows]))


def test_the_contact_the_operator_is_sent_stays_on_the_skin(attacked):
    """The stranger's TCP poses (``tcp below``) taught the remote site's contact estimate, before
    the follower refused poses its robot cannot have: a plane 1.6 km above the patient in one
    run of that baseline here (the session went on), 99.8 m in a CI run, where the operator
    refused it and fell silent for good. Every plane sent, through each attack and after, lies
    within 10 mm of the skin where the quiet windows had it (the scan moves it 4 mm). So do
    those from the first touch: a CI run sent two 12-13 mm above it 20 ms into the contact,
    before any attack, where the fit gave its plane before it knew the stiffness (1 run in 3
    here with a core busy; since it waits, 1.8-2.8 mm in 5 runs)."""
    folder, _, windows = attacked
    times, points = planes(folder)
    skin = np.median(points[during(times, windows, quiet_windows(windows)), 2])
    off = np.abs(points[:, 2] - skin)
    print(f'\nthe planes sent: up to {off.max() * 1e3:.1f} mm from the skin at '
          f'z = {skin * 1e3:.1f} mm')
    assert off.max() <= 0.01


def test_the_robot_s_site_keeps_its_rate_through_the_flood(attacked):
    """The flood is shed by the follower's reader, in DDS, not queued in the site's process: the
    robot's own streams go on. At normal scheduling, when the follower took every message as
    its executor delivered it, one Python callback each, the robot's TCP poses stopped for
    0.3-1.5 s in each of 5 runs here (in one, its site published 1 message in the flood's
    second); taken at a bounded rate, it kept 522-967 Hz (4 runs). Real-time, as here, that
    baseline kept 681 and 933 Hz (2 runs) and the bounded reader 713-945 Hz (11 runs, 2 with a
    core hogged; 719-887 Hz in 3 more, a core hogged, with floods of 770-5353 a second): the
    bound matters most where the site is not real-time."""
    _, series, windows = attacked
    tcp = series['/remote/robot/tcp_pose'][0]
    quiet = rate(tcp, spans(windows, quiet_windows(windows)))
    start, end, _ = windows['flood']
    flood, after = rate(tcp, [(start, end)]), rate(tcp, [(end, end + 0.5)])
    print(f'\nthe robot\'s site: {flood:.0f} Hz through the flood, {after:.0f} Hz in the half '
          f'second after it, {quiet:.0f} Hz in the quiet windows')
    assert flood >= 0.5 * quiet
    assert after >= 0.5 * quiet


def test_each_attack_is_refused_and_named_by_the_follower(attacked):
    """Each kind counted under its own name (best effort: DDS may drop one of a kind on a busy
    machine, never the count of what came)."""
    folder, _, windows = attacked

    def refused(kind):
        said = reports(folder, 'teleop_follower', f'refused: {kind}')
        return int(said[-1]) if said else 0
    # Of the flood, DDS drops what the reader's history cannot hold while the site is busy:
    # not a refusal, and not the operator's commands.
    assert refused('command another session') > 0.9 * windows['another session'][2]
    assert refused('command stamped in the future') >= 0.9 * windows['ahead'][2]
    assert refused('command sequence ahead of its stamp') >= \
        0.9 * windows['numbered far ahead'][2]
    assert refused('command faster than a hand') >= 0.9 * windows['absurd speed'][2]
    assert refused('malformed teleop/command') >= 0.9 * windows['malformed'][2]
    # Each forged TCP pose comes 0.5 ms from a true one and 50 mm from it: half at least, as
    # DDS may drop some on a busy machine.
    assert refused('TCP faster than the robot') >= 0.5 * windows['tcp below'][2]


def test_the_session_goes_on_by_itself_and_nothing_raised(attacked):
    folder, series, windows = attacked
    for node in ('teleop_leader', 'teleop_follower', 'sim_robot', 'wand_driver'):
        said = reports(folder, node, 'callback_errors')
        assert said and said[-1] == '0', node
    last_attack = max(end for _, end, _ in windows.values())
    assert np.count_nonzero(series['/teleop/feedback'] > last_attack) > 100  # 100 Hz, model
    tcp_times, tcp = series['/remote/robot/tcp_pose']
    after = tcp_times > last_attack + 0.1
    assert np.ptp(tcp[after, 2]) > 0.01  # it followed the scan's lift to the end
    energy = reports(folder, 'teleop_leader', 'operator_energy_out_j')
    assert energy and all(np.isfinite(float(value)) for value in energy)
