"""Child processes of the local launcher: started in their own groups, stopped without orphans.

Each node runs in its own session, so a Ctrl-C in the terminal reaches only the launcher, which
then stops the nodes in a chosen order (the recorder last, so it loses nothing). A child also
receives SIGTERM if the launcher itself dies (``PR_SET_PDEATHSIG``), so even a killed launcher
leaves no orphans. Fast DDS leaves shared-memory segments behind a SIGKILLed process; those no
live process holds are removed at the end, as ``fastdds shm clean`` does.
"""
import ctypes
import fcntl
import os
import pathlib
import signal
import subprocess
import time
from typing import Optional

__all__ = ['Child', 'start_child', 'stop_children', 'clean_stale_shm', 'wait_any_exit']

PR_SET_PDEATHSIG = 1
SHM_DIR = pathlib.Path('/dev/shm')
UNLOCKED_SEGMENT_AGE = 1.0  # [s] a segment without a lock file this old has no owner


class Child:
    """A named child process in its own process group, and how to start it again."""

    def __init__(self, name: str, process: subprocess.Popen, argv: list, env: dict) -> None:
        self.name = name
        self.process = process
        self.argv = argv
        self.env = env

    @property
    def pid(self) -> int:
        return self.process.pid

    @property
    def returncode(self) -> Optional[int]:
        return self.process.poll()

    def signal(self, signum: int) -> None:
        try:
            os.killpg(self.process.pid, signum)
        except ProcessLookupError:
            pass


def _die_with_parent() -> None:
    libc = ctypes.CDLL('libc.so.6', use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


def start_child(name: str, argv: list, env: dict) -> Child:
    """Start ``argv`` as a new session whose processes die with the launcher."""
    process = subprocess.Popen(argv, env=env, start_new_session=True,
                               preexec_fn=_die_with_parent)
    return Child(name, process, argv, env)


def stop_children(children: list, *, timeout: float = 5.0, gently: bool = True) -> dict:
    """Stop children in order: SIGINT, then SIGTERM, then SIGKILL, each after ``timeout``.

    ``gently=False`` starts at SIGTERM: for children that may still be importing, where a
    SIGINT prints a ``KeyboardInterrupt`` traceback and SIGTERM ends them quietly (a started node
    stops cleanly on either).

    Returns each child's exit code (negative: the signal that ended it).
    """
    codes = {}
    escalation = (signal.SIGINT, signal.SIGTERM, signal.SIGKILL)[0 if gently else 1:]
    for child in children:
        for signum in escalation:
            if child.returncode is not None:
                break
            child.signal(signum)
            try:
                child.process.wait(timeout)
            except subprocess.TimeoutExpired:
                continue
        codes[child.name] = child.process.wait()
    return codes


def clean_stale_shm(directory: pathlib.Path = SHM_DIR) -> list:
    """Remove Fast DDS segments no live process holds; return their names.

    A segment is held through its ``_el`` lock file: one nobody has locked is stale, and so is a
    segment left without a lock file at all (once older than a creator needs to make one).
    """
    removed = []
    for lock in sorted(directory.glob('fastrtps_*_el')):
        try:
            with lock.open('rb') as handle:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except (BlockingIOError, FileNotFoundError):
            continue  # a live participant holds it, or it is already gone
        removed.append(_remove_segment(directory, lock.name[:-len('_el')]))
    now = time.time()
    for segment in sorted(directory.glob('fastrtps_*')):
        if segment.name.endswith('_el') or (directory / f'{segment.name}_el').exists():
            continue
        try:
            if now - segment.stat().st_mtime > UNLOCKED_SEGMENT_AGE:
                removed.append(_remove_segment(directory, segment.name))
        except FileNotFoundError:
            pass
    return removed


def _remove_segment(directory: pathlib.Path, segment: str) -> str:
    for name in (segment, f'{segment}_el', f'sem.{segment}_mutex'):
        (directory / name).unlink(missing_ok=True)
    return segment


def wait_any_exit(children: list, timeout: float, poll: float = 0.05) -> Optional[Child]:
    """Wait up to ``timeout`` s for any child to exit; return it, or None."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for child in children:
            if child.returncode is not None:
                return child
        time.sleep(poll)
    return None
