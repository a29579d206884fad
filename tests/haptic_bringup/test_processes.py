"""Child processes: stopped in escalating steps with their whole group; stale shm removed."""
import fcntl
import os
import signal
import sys
import time

import psutil

from haptic_bringup.processes import clean_stale_shm, start_child, stop_children

STUBBORN = """
import signal, subprocess, sys, time
signal.signal(signal.SIGINT, signal.SIG_IGN)   # ignores Ctrl-C, as a hung node would
subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)'])   # and has a child
print('ready', flush=True)
time.sleep(60)
"""


def test_a_child_that_ignores_sigint_is_stopped_with_its_whole_group():
    child = start_child('stubborn', [sys.executable, '-c', STUBBORN], env=None)
    assert _eventually(lambda: len(_group(child.pid)) == 2), 'the child did not start its own'
    group = _group(child.pid)
    started = time.monotonic()
    codes = stop_children([child], timeout=0.5)
    assert codes['stubborn'] == -signal.SIGTERM
    assert time.monotonic() - started < 3.0  # escalated after the 0.5 s timeout, no hang
    assert _eventually(lambda: not [p for p in group if _alive(p)]), 'the group outlived it'


def _eventually(condition, timeout: float = 30.0) -> bool:
    deadline = time.monotonic() + timeout
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.05)
    return condition()


def _group(pgid: int) -> list:
    return [p for p in psutil.process_iter(['pid']) if _group_of(p) == pgid]


def _alive(process) -> bool:
    try:
        return process.is_running() and process.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def _group_of(process):
    try:
        return os.getpgid(process.pid)
    except (ProcessLookupError, psutil.NoSuchProcess):
        return None


def test_only_segments_no_live_process_holds_are_removed(tmp_path):
    for name in ('fastrtps_dead', 'fastrtps_live'):
        (tmp_path / name).write_bytes(b'segment')
        (tmp_path / f'{name}_el').write_bytes(b'')
    (tmp_path / 'sem.fastrtps_dead_mutex').write_bytes(b'')
    for name, age in (('fastrtps_port7411', 60.0), ('fastrtps_port7413', 0.0)):
        (tmp_path / name).write_bytes(b'port without a lock file')
        (tmp_path / f'sem.{name}_mutex').write_bytes(b'')
        os.utime(tmp_path / name, (time.time() - age, time.time() - age))
    with open(tmp_path / 'fastrtps_live_el', 'rb') as held:
        fcntl.flock(held, fcntl.LOCK_SH)  # a live participant holds its lock
        assert clean_stale_shm(tmp_path) == ['fastrtps_dead', 'fastrtps_port7411']
    # The live one stays, and so does a fresh lock-less one (its creator may be making the lock).
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        'fastrtps_live', 'fastrtps_live_el', 'fastrtps_port7413', 'sem.fastrtps_port7413_mutex']
