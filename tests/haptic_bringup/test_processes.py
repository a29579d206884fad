"""Child processes: stopped in escalating steps with their whole group; stale shm removed."""
import fcntl
import os
import signal
import sys
import time

import psutil

from haptic_bringup.processes import clean_stale_shm, start_child, stop_children
from haptic_util.shared_memory import segments

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


def test_only_our_own_dead_segments_are_removed(tmp_path):
    """Ours: made after the snapshot, and for a port, in one of our domains (7400 + 250 d + k)."""
    def segment(name, age=60.0, lock=True):
        (tmp_path / name).write_bytes(b'segment')
        (tmp_path / f'sem.{name}_mutex').write_bytes(b'')
        if lock:
            (tmp_path / f'{name}_el').write_bytes(b'')
        os.utime(tmp_path / name, (time.time() - age, time.time() - age))

    segment('fastrtps_someone_elses')  # dead, but there before us: not ours
    before = segments(tmp_path)
    segment('fastrtps_dead')
    segment('fastrtps_live')
    segment('fastrtps_young', age=0.0)  # its creator may not have locked it yet
    segment('fastrtps_port7411', lock=False)  # domain 0: ours
    segment('fastrtps_port17661')  # domain 41, not ours: stays though nobody holds it
    with open(tmp_path / 'fastrtps_live_el', 'rb') as held:
        fcntl.flock(held, fcntl.LOCK_SH)  # a live participant holds its lock
        removed = clean_stale_shm(tmp_path, domains=[0, 42], existing=before)
    assert removed == ['fastrtps_dead', 'fastrtps_port7411']
    assert {p.name for p in tmp_path.iterdir() if not p.name.startswith('sem.')} == {
        'fastrtps_someone_elses', 'fastrtps_someone_elses_el', 'fastrtps_live',
        'fastrtps_live_el', 'fastrtps_young', 'fastrtps_young_el', 'fastrtps_port17661',
        'fastrtps_port17661_el'}
