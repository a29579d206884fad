"""Node faults mid-contact: the wand's force reaches zero within 10 ms, and the loop recovers.

The loop runs as three processes with the simulated wand pressing into the cuboid's top face and
holding there, rendering the contact locally (the default). A node is then killed (SIGKILL) and
restarted, or paused (SIGSTOP) for 100 ms, over and over; this test notes each fault's instant.
When the force on the hand stopped is measured twice, from what the device applied, never from
the driver's intentions, from the signal (or, for a kill, from the killed node's last answer, if
it answered after the signal was sent): the simulated device's own record of when its rendered
force switched off (servo resolution, 0.25 ms), and ``wand/applied_wrench`` as this separate
process received it (the mean force of the servo periods that ended in each tick: the force
stopped inside the last report that held any).
"""
import os
import signal
import time

from loop_client import LoopClient
import numpy as np
import pytest

from haptic_bringup.launcher import Loop, LoopConfig
from haptic_wand_driver.params import WandDriverParams

# Per kind of fault, alternating between the collision and the force node. A kill costs a
# restart, about 5 s here (imports, the scene); 20 of them took a CI run's 30 minutes too close.
TRIALS = {'SIGKILL': 10, 'SIGSTOP 100 ms': 20}
FAULTY = ('collision_engine', 'force_renderer')
TIME_TO_ZERO = 0.010  # [s] the bound
PAUSE = 0.100  # [s] SIGSTOP length
RECOVERY_TIMEOUT = 60.0  # [s] a restarted node imports and loads its scene first
REJOIN_TIMEOUT = 20.0  # [s] a restarted node that has not rejoined by then: a side joins anew
STEADY = 0.2  # [s] of unbroken contact force before each fault
PRESSING = """\
waypoints:
  - {t: 0.0, x: 0.0, y: 0.0, z: 0.0}
  - {t: 1.0, x: 0.0, y: 0.0, z: -0.035}
  - {t: 3600.0, x: 0.0, y: 0.0, z: -0.035}
"""  # 10 mm into the top face (z = -0.025 m), held: a steady contact force


@pytest.fixture(scope='module')
def pressing_loop(tmp_path_factory):
    """The full loop, the wand pressing on the cuboid; yields (loop, client, stats file)."""
    from domains import session_domain_id
    folder = tmp_path_factory.mktemp('fail_safe')
    script = folder / 'press.yaml'
    script.write_text(PRESSING)
    stats = folder / 'stats.npz'
    domain = session_domain_id()
    config = LoopConfig(experiment=str(script), domain_id=domain, run_dir=folder / 'launch',
                        overrides={'wand_driver': {'stats_file': str(stats)}})
    loop = Loop(config)
    loop.start()
    client = LoopClient(domain)
    try:
        wait_for_fresh_force(client, time.time_ns(), RECOVERY_TIMEOUT)
        yield loop, client, stats
    finally:
        client.close()
        loop.stop()


def wait_for_fresh_force(client: LoopClient, since_ns: int, timeout: float) -> int:
    """Spin until a non-zero wrench answering a pose stamped after ``since_ns`` arrives."""
    deadline = time.monotonic() + timeout
    seen, fresh, strongest = 0, 0, 0.0
    while time.monotonic() < deadline:
        client.executor.spin_once(timeout_sec=0.005)
        arrived, client.wrenches = client.wrenches, {}  # look at each wrench once
        for (sec, nanosec), wrench in arrived.items():
            seen += 1
            if sec * 1_000_000_000 + nanosec > since_ns:
                fresh += 1
                strongest = max(strongest, abs(wrench.wrench.force.z))
                if strongest > 0.05:
                    return time.time_ns()
    raise TimeoutError(f'the loop did not recover: {seen} wrenches seen, {fresh} fresh, '
                       f'strongest fresh force {strongest:.3g} N')


def wait_for_steady_contact(client: LoopClient, timeout: float = 10.0) -> None:
    """Spin until every wrench of the last STEADY seconds pushed out of the top face."""
    deadline = time.monotonic() + timeout
    client.wrenches.clear()
    steady_since = time.monotonic()
    while time.monotonic() < deadline:
        client.executor.spin_once(timeout_sec=0.005)
        if any(w.wrench.force.z <= 0.1 for w in client.wrenches.values()):
            steady_since = time.monotonic()
        client.wrenches.clear()
        if time.monotonic() - steady_since >= STEADY:
            return
    raise TimeoutError('the wand did not settle into contact')


def fault_trials(loop, client, fault, count: int) -> list:
    """Run ``count`` faults; per trial, the node, the clock just before and just after the signal,
    when the node was back (restarted or resumed), and how long the loop took to recover [s]."""
    trials = []
    for trial in range(count):
        wait_for_steady_contact(client)
        name = FAULTY[trial % 2]
        before_ns, after_ns, resumed_ns = fault(loop, name)
        recovered_ns = (rejoined(loop, client, name, resumed_ns) if fault is kill_and_restart
                        else wait_for_fresh_force(client, resumed_ns, RECOVERY_TIMEOUT))
        trials.append((name, before_ns, after_ns, resumed_ns,
                       (recovered_ns - resumed_ns) * 1e-9))
    return trials


def killed_at(client, name: str, before: int, back: int) -> int:
    """The latest clock a SIGKILL sent at ``before`` may be measured from: the fault's instant or
    earlier [ns].

    A busy machine can take milliseconds to deliver the signal (12 ms in a CI run), and the
    node answers poses meanwhile; each answer holds for its lifetime after its pose. An answer
    to a pose stamped after ``before`` shows the node was alive then. Every answer stamped
    before ``back`` came from the killed process: a restarted one hears only later poses.
    """
    stamps = np.array(client.answer_stamps[name], dtype=np.int64)
    return int(max(before, stamps[stamps < back].max(initial=before)))


def rejoined(loop, client, name: str, since_ns: int) -> int:
    """Wait for the restarted ``name`` to rejoin the loop; if it does not, join each side anew.

    Fast DDS 2.14 sometimes never delivers between a restarted participant and one that
    survived a peer's SIGKILL (eProsima/Fast-DDS#5053, #5469, open). Twice (2026-11-28), the
    side at fault was a survivor, and restarting the killed node again did not help (three
    times; twice, with this client joining anew twice). In a CI run it was this client: the
    restarted force node published some 870 wrenches a second, the wand driver took them, this
    client saw none. In a local run it was the collision node: it answered every pose, and the
    restarted force node received nothing and published no wrench. So, as a supervisor would,
    the other faulty node is restarted, then this client joins anew (``LoopClient.rejoin``),
    then the node is restarted again; each is counted and printed. Returns when the force came
    back [ns].
    """
    other = FAULTY[1 - FAULTY.index(name)]
    for side in (other, 'this client', name):
        try:
            return wait_for_fresh_force(client, since_ns, REJOIN_TIMEOUT)
        except TimeoutError as silence:
            # Whether the restarted process was still running tells a silent one from a dead one.
            REJOINS.append(f'{side} ({name} silent: {silence}; exit code '
                           f'{loop.child(name).returncode})')
            if side == 'this client':
                client.rejoin()
            else:
                os.killpg(loop.child(side).pid, signal.SIGKILL)
                loop.restart(side)
    try:
        return wait_for_fresh_force(client, since_ns, RECOVERY_TIMEOUT)
    except TimeoutError as error:
        raise TimeoutError(f'{error}; after joining anew: {REJOINS}') from None


REJOINS = []  # sides joined anew (this client or a node) because a restart did not rejoin


def signal_group(pid: int, signum: int) -> tuple:
    """Send ``signum`` to a process group; return the clock just before and just after."""
    before = time.time_ns()
    os.killpg(pid, signum)
    return before, time.time_ns()


def kill_and_restart(loop, name):
    before, after = signal_group(loop.child(name).pid, signal.SIGKILL)
    time.sleep(0.2)
    restarted_ns = time.time_ns()
    loop.restart(name)
    return before, after, restarted_ns


def pause_and_resume(loop, name):
    pid = loop.child(name).pid
    before, after = signal_group(pid, signal.SIGSTOP)
    time.sleep(PAUSE)
    resumed_ns = time.time_ns()
    os.killpg(pid, signal.SIGCONT)
    return before, after, resumed_ns


def times_to_zero(record, faults) -> np.ndarray:
    """For each fault, how long the force on the hand lasted after it [s].

    A fault's instant is bracketed by the clock read just before and just after sending the
    signal; measuring from the earlier reading gives an upper bound of the true delay. The force
    counts as gone at the last drop to zero before the node is back, provided it never came on
    again in between (the port's passivity controller may zero it for a period in contact, and
    the held wrench then pushes again until its deadline).
    """
    on, off = np.sort(record['force_on_ns']), np.sort(record['force_off_ns'])
    delays = []
    for before, back in faults:
        drops = off[(off >= before) & (off < back)]
        last_on = on[on < back].max(initial=-1)
        if drops.size:
            assert last_on < drops[-1], f'the force came back on during the fault at {before}'
            delays.append((drops[-1] - before) * 1e-9)
        else:  # no drop during the fault: the force must have been off already
            assert off[off < before].max(initial=-1) > on[on < before].max(initial=-1)
            assert not np.any((on >= before) & (on < back)), 'the force came back on'
            delays.append(0.0)
    return np.array(delays)


def seen_from_outside(applied: list, faults) -> np.ndarray:
    """For each fault, when the force stopped as seen from outside: (from, to) after it [s].

    Each wand/applied_wrench holds the mean force over the servo periods that ended since the
    previous one (``SimulatedWand.applied``), and repeats the previous mean when none did: two
    ticks less than a servo period apart, on a busy machine. So the force stopped inside the last
    report that still held any, after its earliest period began: one servo period before the
    previous report that had a period to end. A driver slowed by a busy machine makes that
    bracket longer.
    """
    applied = np.array(sorted(applied))
    stamps, force = applied[:, 0], applied[:, 1]
    servo_period = round(1e9 / WandDriverParams().servo_rate)  # [ns]
    brackets = []
    for before, back in faults:
        held = np.flatnonzero((stamps >= before) & (stamps < back) & (force > 0.0))
        if held.size == 0:
            brackets.append((0.0, 0.0))
            continue
        last = first = held.max()
        while first > 1 and stamps[first] - stamps[first - 1] < servo_period:
            first -= 1  # perhaps no period ended in between: the report repeats the one before
        brackets.append((max(stamps[first - 1] - servo_period - before, 0) * 1e-9,
                         (stamps[last] - before) * 1e-9))
    return np.array(brackets)


def test_faults_mid_contact_zero_the_force_within_10_ms_and_the_loop_recovers(pressing_loop):
    loop, client, stats = pressing_loop
    kills = fault_trials(loop, client, kill_and_restart, TRIALS['SIGKILL'])
    pauses = fault_trials(loop, client, pause_and_resume, TRIALS['SIGSTOP 100 ms'])
    others = {c.name: c.pid for c in loop.children if c.name not in FAULTY}
    assert all(loop.child(name).returncode is None for name in others), 'a bystander died'
    loop.stop()  # the driver writes its record on a clean stop
    record = np.load(stats)
    for label, trials in (('SIGKILL', kills), ('SIGSTOP 100 ms', pauses)):
        faults = [(killed_at(client, name, before, back) if label == 'SIGKILL' else before, back)
                  for name, before, _, back, _ in trials]
        delays = times_to_zero(record, faults)
        outside = seen_from_outside(client.applied, faults)
        brackets = np.array([after - before for _, before, after, _, _ in trials]) * 1e-9
        recovery = np.array([seconds for *_, seconds in trials])
        print(f'{label}: {len(trials)} trials, time to zero force max {1e3 * delays.max():.2f} '
              f'ms (median {1e3 * np.median(delays):.2f}; already zero in '
              f'{np.count_nonzero(delays == 0.0)}); recovery median '
              f'{np.median(recovery):.3f} s, max {recovery.max():.3f} s; sending the signal '
              f'took up to {1e3 * brackets.max():.2f} ms (included in the delays, but from '
              f'a killed node\'s last answer when it answered later: '
              f'{sum(at > before for (at, _), (_, before, *_) in zip(faults, trials))}); '
              f'seen from '
              f'outside: stopped by {1e3 * outside[:, 1].max():.2f} ms at the latest, its tick '
              f'starting {1e3 * outside[:, 0].max():.2f} ms after the signal at the latest; '
              f'sides joined anew after a silent restart: {len(REJOINS)}; steps of the '
              f'system clock the driver saw: {record["clock_steps"]}')
        assert delays.max() <= TIME_TO_ZERO, f'{label}: {delays}'
        assert outside[:, 0].max() <= TIME_TO_ZERO, f'{label}, outside: {outside}'
        assert len(trials) == TRIALS[label]
