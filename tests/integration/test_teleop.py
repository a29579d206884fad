"""Both sites as real processes, each in its own DDS domain, over their gateways with a delay.

Every figure comes from the bag (what the device applied to the hand, what the remote sensor
read) or from the nodes' own reports, never from the schemes' internal books.
"""
import concurrent.futures
import os
import pathlib
import signal
import time

from ament_index_python.packages import get_package_share_directory
from domains import session_domain_id
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
import yaml

from haptic_bringup.bag import recover, typestore_with
from haptic_bringup.discovery import GraphWatcher
from haptic_bringup.hold_request import hold_during
from haptic_bringup.launcher import Loop, LoopConfig, SCAN_DURATION, SCAN_SCRIPT
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.scan_clock import wait_for_session_start
from haptic_bringup.session import (bags, published_counts, read_numbers, read_session_start,
                                    read_vectors, reported, SITE_PUBLISHERS, topic_counts)
from haptic_contract.graph import absolute, REMOTE_PREFIX, TELEOP_HOLD
from link_emulator.link import silence_timeout

DELAY = 0.05  # [s] one way
FORCE_SCALE = 0.3  # the leader's default
MAX_PATIENT_FORCE = 20.0  # [N] the follower's default
JITTER = 0.1 * DELAY  # [s]
LINK_TIMEOUT = silence_timeout(0.1, JITTER)  # [s] both ends', as the launcher sets them
MODEL_LIFETIME = 0.010  # [s] the leader's default
# [s] the restart test's scan holds its press longer: a site restarted with a core hogged took
# 6-10.5 s to start on a 2-core machine, and the scan lifted 9.5 s after it was killed.
RESTART_HOLD = 8.0
PRESSING = (6.0, 8.0)  # [s] into the scan (its session start): pressed, sweeping
HELD = 7.0  # [N] the force the operator asks the remote site to hold once PRESSING is over
STREAMS = {'/wand/pose': 'pose', '/wand/applied_wrench': 'wrench',
           '/teleop/feedback': 'pose', '/remote/robot/ft_sensor/wrench': 'wrench',
           '/remote/robot/tcp_pose': 'pose'}


def teleop(folder: pathlib.Path, scheme: str = 'model', duration: float = 9.0,
           experiment: str = None, gateway_in_process: bool = True, **link):
    config = LoopConfig(teleop=scheme, duration=duration, record=str(folder / 'bag'),
                        experiment=experiment,
                        domain_id=session_domain_id(),
                        remote_domain=session_domain_id(second=True), run_dir=folder / 'launch',
                        link={'delay': DELAY, 'jitter': JITTER, 'loss': 0.01, **link},
                        gateway_in_process=gateway_in_process)
    return Loop(config)


def crossing_endpoints() -> dict:
    """What each site's DDS domain shows of the streams that cross: (publishers, subscribers).

    Read once the watcher sees each stream's publisher, and a second later: a site's endpoints
    are one participant's, discovered together.
    """
    seen = {}
    for domain, topic in ((session_domain_id(), '/teleop/feedback'),
                          (session_domain_id(second=True), '/teleop/command')):
        watcher = GraphWatcher(domain)
        try:
            assert not watcher.wait({topic: (1, 0)}, 30.0), f'{topic} never published'
            time.sleep(1.0)
            seen[topic] = watcher.counts(topic)
        finally:
            watcher.close()
    return seen


def streams(folder: pathlib.Path) -> dict:
    typestore = typestore_with(custom_definitions())
    topics = {topic: kind for topic, kind in STREAMS.items() if topic != '/teleop/feedback'}
    series = read_vectors(folder / 'bag', typestore, topics)
    with AnyReader(bags(folder / 'bag'), default_typestore=typestore) as reader:
        connections = [c for c in reader.connections if c.topic == '/teleop/feedback']
        series['/teleop/feedback'] = np.array(
            [stamp * 1e-9 for _, stamp, _ in reader.messages(connections=connections)])
    return series


def zeroed(folder: pathlib.Path, since: float) -> float:
    """By when the device's force had stopped after ``since``, by its own stamps (s).

    Each applied wrench is the mean over the servo periods that ended since the tick before
    (``SimulatedWand.applied``, as ``test_fail_safe.seen_from_outside`` reads it): the first one
    after ``since`` that is zero means no force from the tick before it on, whose stamp this
    returns. Not the zero one's own: at a slowed driver's 10 ms ticks the force stopped up to a
    tick before it. The stamp is the device's tick; the bag's receive time is the recorder's,
    which a busy recorder delays. A device that stalled has no ticks in between, so it shows.
    """
    times, felt = read_vectors(folder / 'bag', typestore_with(custom_definitions()),
                               {'/wand/applied_wrench': 'wrench'},
                               stamped=True)['/wand/applied_wrench']
    after = times > since
    ticks = np.diff(times[after][:200])
    print(f'device ticks after {since:.3f}: longest gap {1e3 * ticks.max():.1f} ms')
    first_zero = np.flatnonzero(after & (np.linalg.norm(felt, axis=1) == 0.0))[0]
    return times[first_zero - 1]


def reports(folder: pathlib.Path, node: str, key: str) -> list:
    """The values ``node`` reported for ``key`` on /diagnostics, in order."""
    return reported(folder / 'bag', typestore_with(custom_definitions()), key).get(node, [])


def window(times: np.ndarray, start: float, end: float) -> np.ndarray:
    return (times >= start) & (times < end)


@pytest.fixture(scope='module')
def scan(tmp_path_factory):
    """The scan at 50 ms; once ``PRESSING`` is over the operator asks for a force-hold."""
    folder = tmp_path_factory.mktemp('teleop_scan')
    with concurrent.futures.ThreadPoolExecutor(1) as requests:
        asked = requests.submit(hold_during, session_domain_id(), HELD, PRESSING[1], None, 120.0)
        # 11 s, not 9: the follower reports once a second, and a hold asked at 8 s into a 9 s
        # scan was once over before a report showed it (a CI run).
        with teleop(folder, duration=11.0) as loop:
            graph = crossing_endpoints()
            assert loop.wait(60.0) is not None, 'the scan did not end'
        assert asked.result() is not None, 'the operator\'s gateway never took the hold'
    return folder, streams(folder), graph


def test_what_crosses_is_handed_over_in_each_site_s_process_and_read_from_no_dds(scan):
    """Each gateway is a node of its site's process, and hands what crosses to the site's nodes
    there: in each site's DDS domain, the stream that came across has its publisher (the
    gateway's, for a recorder or a viewer elsewhere) and no reader. So what a stranger on a
    site's network publishes on it reaches no node (``test_hostile_link`` attacks the layout
    in which a site's streams go through DDS)."""
    _, _, graph = scan
    assert graph == {'/teleop/feedback': (1, 0), '/teleop/command': (1, 0)}


def test_the_patient_is_felt_scaled_across_the_delayed_link(scan):
    folder, series, _ = scan
    start = read_session_start(folder / 'bag', typestore_with(custom_definitions()))
    felt_times, felt = series['/wand/applied_wrench']
    patient_times, patient = series['/remote/robot/ft_sensor/wrench']
    held = window(felt_times - start, *PRESSING)
    pressed = window(patient_times - start, *PRESSING)
    felt_force = np.median(felt[held, 2]) / FORCE_SCALE
    patient_force = np.median(patient[pressed, 2])
    assert patient_force > 5.0  # the scan presses
    assert felt_force == pytest.approx(patient_force, rel=0.15)
    assert np.max(np.linalg.norm(patient, axis=1)) <= MAX_PATIENT_FORCE


def test_the_operator_measures_the_round_trip_from_echoed_stamps(scan):
    folder, _, _ = scan
    round_trips = [float(v) for v in reports(folder, 'teleop_leader', 'round_trip_s')
                   if v != 'nan']
    assert round_trips, 'the leader never reported a round trip'
    assert np.median(round_trips) == pytest.approx(2 * DELAY, abs=0.02)


def test_each_site_records_itself_into_the_session_and_loses_nothing(scan):
    folder, series, _ = scan
    assert bags(folder / 'bag') == [folder / 'bag' / 'operator', folder / 'bag' / 'remote']
    assert len(series['/remote/robot/tcp_pose'][0]) > 1000
    assert len(series['/wand/pose'][0]) > 1000
    assert reports(folder, 'teleop_follower', 'published')  # its /diagnostics, from /remote
    published = published_counts(folder / 'bag', typestore_with(custom_definitions()),
                                 SITE_PUBLISHERS)
    recorded = topic_counts(folder / 'bag')
    assert set(published) == set(SITE_PUBLISHERS)
    assert {topic: recorded[topic] for topic in SITE_PUBLISHERS} == published
    for recorder in ('operator_recorder', 'remote_recorder'):
        assert reports(folder, recorder, 'dropped')[-1] == '0'


def test_a_force_hold_asked_at_the_operator_s_site_crosses_and_the_remote_site_holds(scan):
    """``teleop/hold`` crosses the gateways as a reliable message: the follower, at the remote
    site, reports the force it holds."""
    folder, _, _ = scan
    held = reports(folder, 'teleop_follower', 'force_hold')
    assert held and held[0] == 'None'  # not holding as the scan began
    assert float(held[-1]) == HELD
    _, arrived = read_numbers(folder / 'bag', typestore_with(custom_definitions()),
                              REMOTE_PREFIX + absolute(TELEOP_HOLD))
    assert arrived.tolist() == [HELD]  # in the remote site's bag, once


def wait_for_the_session_start(domain_id: int, timeout: float) -> float:
    """Return when (time.monotonic) the wand's session began: the scan's time zero."""
    began = wait_for_session_start(domain_id, timeout)
    assert began is not None, 'the session never began'
    return began.monotonic


def test_a_link_stalled_mid_contact_zeroes_the_force_the_robot_lets_go_and_both_meet_again(
        tmp_path):
    """The operator's gateway stops for 0.5 s while the scan presses, then sends what it held.

    The stall comes 6.5 s into the scan, in its sweep, not 6.5 s after the launcher returned:
    under load the scan started up to seconds later.

    The operator's force is zero within the link timeout; the robot holds its TCP (not the last
    target, which lay further in) and retracts: the patient's force never rises during the
    stall; what the gateway held is older than the link allows and never executed; and when the
    link is back the robot and the operator's model meet again: the patient is pressed and the
    hand feels, scaled, the force the patient gets."""
    with teleop(tmp_path, duration=SCAN_DURATION, gateway_in_process=False) as loop:
        start = wait_for_the_session_start(session_domain_id(), SCAN_DURATION)
        time.sleep(max(0.0, start + PRESSING[0] + 0.5 - time.monotonic()))
        gateway = loop.child('operator_gateway')  # a process of its own, to be stopped
        dropped = time.time()
        gateway.signal(signal.SIGSTOP)
        time.sleep(0.5)
        gateway.signal(signal.SIGCONT)
        assert loop.wait(60.0) is not None
    series = streams(tmp_path)
    last_feedback = series['/teleop/feedback'][series['/teleop/feedback'] < dropped + 0.25][-1]
    # The model is valid until the leader's link timeout, and each lasts its lifetime.
    assert zeroed(tmp_path, last_feedback) - last_feedback <= (
        LINK_TIMEOUT + MODEL_LIFETIME + 0.010)
    patient_times, patient = series['/remote/robot/ft_sensor/wrench']
    pressing = np.linalg.norm(patient, axis=1)
    silent = dropped + LINK_TIMEOUT + 0.02  # the follower's watchdog has fired
    # The last reading by then: a 10 ms window was empty when a busy recorder took none in it.
    before = pressing[patient_times <= silent][-1]
    stalled = window(patient_times, silent, dropped + 0.5)
    assert before > 3.0
    assert pressing[stalled].max() <= before + 0.5  # it let go, never pressed on
    tcp_times, tcp = series['/remote/robot/tcp_pose']
    held = window(tcp_times, silent, dropped + 0.5)
    assert tcp[held, 2][-1] > tcp[held, 2][0]  # drawn back, out of the patient
    stale = reports(tmp_path, 'teleop_follower', 'refused: command older than the link allows')
    # Some of what the frozen gateway held came, stale, and was refused; none was followed (the
    # patient's force above). How many came is the machine's speed, not a property: its reader
    # keeps the newest 10 (the haptic depth), and what was in Zenoh's queue (27 in a run).
    assert stale and int(stale[-1]) > 0
    felt_times, felt = series['/wand/applied_wrench']
    felt_before = np.median(felt[window(felt_times, dropped - 0.5, dropped), 2])
    again = dropped + 3.0  # the robot rejoined, the hand pressing on the force it left
    felt_after = np.median(felt[window(felt_times, again, again + 0.5), 2])
    pressed_after = np.median(pressing[window(patient_times, again, again + 0.5)])
    assert felt_before > 0.0 and pressed_after > 1.0  # the hand presses on something again
    assert felt_after / FORCE_SCALE == pytest.approx(pressed_after, rel=0.2)  # as the patient
    assert np.max(pressing) <= MAX_PATIENT_FORCE


def scan_held_longer(folder: pathlib.Path, longer: float) -> pathlib.Path:
    """Write the session's scan with its press held ``longer`` (s) before it lifts."""
    scan = yaml.safe_load(pathlib.Path(get_package_share_directory(SCAN_SCRIPT[0]),
                                       SCAN_SCRIPT[1]).read_text())
    points = scan['waypoints']
    bottom = min(point['z'] for point in points)
    lift = max(point['t'] for point in points if point['z'] == bottom)
    for point in points:
        point['t'] += longer if point['t'] > lift else 0.0
    path = folder / 'scan_held_longer.yaml'
    path.write_text(yaml.safe_dump(scan))
    return path


def test_a_killed_remote_site_zeroes_the_force_and_a_restarted_one_follows_again(tmp_path):
    """The restarted site's first model finds the wand deep (the hand pressed on through the
    silence), so a passive update shows it where the wand is: no force until the hand presses
    further or touches again. What resumes at once is the link and the robot's following.

    The scan holds its press ``RESTART_HOLD`` longer, so that the restarted site is up before
    the lift it must follow, on a loaded machine too."""
    scan = scan_held_longer(tmp_path, RESTART_HOLD)
    with teleop(tmp_path, duration=SCAN_DURATION + RESTART_HOLD, experiment=str(scan)) as loop:
        time.sleep(PRESSING[0] + 0.5)
        killed = time.time()
        os.kill(loop.child('remote').pid, signal.SIGKILL)
        time.sleep(1.0)
        assert loop.exited().name == 'remote'  # nothing else went down
        loop.restart('remote')
        assert loop.wait(60.0).name == 'operator'
    # The killed site's bag is recovered; the restarted one wrote its own beside it.
    assert recover(tmp_path / 'bag' / 'remote', typestore_with(custom_definitions())).is_dir()
    assert [bag.name for bag in bags(tmp_path / 'bag')] == [
        'operator', 'remote-2', 'remote-recovered']
    series = streams(tmp_path)
    feedback = series['/teleop/feedback']
    last = feedback[feedback < killed + 0.5][-1]
    assert zeroed(tmp_path, last) - last <= LINK_TIMEOUT + MODEL_LIFETIME + 0.010
    resumed = feedback[feedback > killed + 1.0]
    assert len(resumed) > 100, 'the restarted site did not answer'
    assert reports(tmp_path, 'teleop_leader', 'link_live')[-1] == 'True'
    tcp_times, tcp = series['/remote/robot/tcp_pose']
    after = tcp_times > resumed[0]
    assert tcp[after, 2].max() - tcp[after, 2].min() > 0.01  # it followed the wand's lift


def test_reordered_messages_from_the_link_are_ignored_by_stamp(tmp_path):
    """A jitter of 40 % of the delay with reordering: many messages overtake one another."""
    with teleop(tmp_path, duration=9.0, jitter=0.4 * DELAY, reorder=True) as loop:
        assert loop.wait(60.0) is not None
    older = reports(tmp_path, 'teleop_follower', 'refused: command not newer than the last taken')
    assert older and int(older[-1]) > 100
    assert int(reports(tmp_path, 'teleop_leader', 'refused')[-1]) > 10  # older feedback
    series = streams(tmp_path)
    start = read_session_start(tmp_path / 'bag', typestore_with(custom_definitions()))
    felt_times, felt = series['/wand/applied_wrench']
    patient_times, patient = series['/remote/robot/ft_sensor/wrench']
    felt_force = np.median(felt[window(felt_times - start, *PRESSING), 2]) / FORCE_SCALE
    patient_force = np.median(patient[window(patient_times - start, *PRESSING), 2])
    assert patient_force > 5.0
    assert felt_force == pytest.approx(patient_force, rel=0.15)


def test_tdpa_over_the_link_gives_the_hand_no_energy_and_keeps_the_patient_safe(tmp_path):
    """The whole scan with ``tdpa`` at 50 ms, both sites as processes: the leader's controller
    through its coupling, stepped on the real pose periods. The work of what the device applied
    on the hand, tick by tick (each force held over its tick, matched to the pose by stamp)."""
    with teleop(tmp_path, scheme='tdpa', duration=SCAN_DURATION) as loop:
        assert loop.wait(60.0) is not None, 'the scan did not end'
    typestore = typestore_with(custom_definitions())
    topics = {'/wand/pose': 'pose', '/wand/applied_wrench': 'wrench',
              '/remote/robot/ft_sensor/wrench': 'wrench'}
    series = read_vectors(tmp_path / 'bag', typestore, topics, stamped=True)
    pose_times, wand = series['/wand/pose']
    felt_times, felt = series['/wand/applied_wrench']
    _, at_pose, at_felt = np.intersect1d(pose_times, felt_times, return_indices=True)
    following = np.flatnonzero(np.diff(at_pose) == 1)  # consecutive ticks, both recorded
    steps = wand[at_pose[following + 1]] - wand[at_pose[following]]
    work = float(np.einsum('ij,ij->', felt[at_felt[following + 1]], steps))
    # The whole scan, every tick (a count would be this machine's speed: 7387 at load 15).
    assert pose_times[-1] - pose_times[0] > SCAN_DURATION - 1.0
    assert len(following) >= 0.99 * (len(pose_times) - 1)
    assert work <= 0.0, f'the hand was given {work:.4f} J'
    patient = series['/remote/robot/ft_sensor/wrench'][1]
    assert np.max(np.linalg.norm(patient, axis=1)) <= MAX_PATIENT_FORCE
    assert np.max(np.linalg.norm(felt, axis=1)) > 0.5  # it does press, and is felt
