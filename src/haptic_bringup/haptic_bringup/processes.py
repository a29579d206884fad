"""Child processes of the local launcher: started in their own groups, stopped without orphans.

Each node runs in its own session, so a Ctrl-C in the terminal reaches only the launcher, which
then stops the nodes together and the recorder after them (so it loses nothing). A child also
receives SIGTERM if the launcher itself dies (``PR_SET_PDEATHSIG``), so even a killed launcher
leaves no orphans. Fast DDS leaves shared-memory segments behind a SIGKILLed process; those no
live process holds, among those the launcher's own processes made, are removed at the end.
"""
import ctypes
import fcntl
import math
import os
import pathlib
import signal
import subprocess
import sys
import time
from typing import Callable, Iterable, Optional

from haptic_util import shared_memory
from haptic_util.executor import hold_stop_signals
from haptic_util.shared_memory import SHM_DIR

__all__ = ['Child', 'start_child', 'stop_children', 'clean_stale_shm', 'run_until_stopped',
           'wait_any_exit']

PR_SET_PDEATHSIG = 1
CREATION_GRACE = 2.0  # [s] a segment this young may still be being locked by its creator
PORT_BASE, DOMAIN_GAIN = 7400, 250  # Fast DDS (RTPS) well-known port mapping


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


def _as_child() -> None:
    """In the child before it runs Python: die with the launcher, hold SIGINT until taken."""
    libc = ctypes.CDLL('libc.so.6', use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    hold_stop_signals({signal.SIGINT})


def start_child(name: str, argv: list, env: dict) -> Child:
    """Start ``argv`` as a new session whose processes die with the launcher.

    A SIGINT that comes while the child still imports waits until its node can take it
    (``haptic_util.executor``): it then exits 0, as a started node does. SIGTERM ends it.
    """
    process = subprocess.Popen(argv, env=env, start_new_session=True, preexec_fn=_as_child)
    return Child(name, process, argv, env)


def stop_children(children: list, *, timeout: float = 5.0, gently: bool = True) -> dict:
    """Stop children together: SIGINT to all, then SIGTERM, then SIGKILL to those left.

    Each step waits up to ``timeout`` for all of them. Together, so that a session stops within
    the slowest child's time rather than the sum of all (issue 24: every process within 2 s of
    a Ctrl-C), as ``ros2 launch`` stops its processes. ``gently=False`` starts at SIGTERM: for
    children that may still be importing and must end now rather than once started (a started
    node stops cleanly on either).

    Returns each child's exit code (negative: the signal that ended it), in their order.
    """
    escalation = (signal.SIGINT, signal.SIGTERM, signal.SIGKILL)[0 if gently else 1:]
    for signum in escalation:
        running = [child for child in children if child.returncode is None]
        for child in running:
            child.signal(signum)
        deadline = time.monotonic() + timeout
        for child in running:
            try:
                child.process.wait(max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                pass
    return {child.name: child.process.wait() for child in children}


def clean_stale_shm(directory: pathlib.Path = SHM_DIR, *, domains: Iterable[int],
                    existing: set) -> list:
    """Remove Fast DDS segments our own processes left behind; return their names.

    A segment is ours when it was not in the ``existing`` snapshot (taken before our processes
    started) and, for a port segment, when its port belongs to one of our ``domains``. Of those,
    a segment is stale when no live process holds its ``_el`` lock file; one younger than
    ``CREATION_GRACE`` is left alone, as its creator may not have locked it yet. Segments of
    other users of this machine are never touched, stale or not.
    """
    domains = set(domains)
    removed = []
    now = time.time()
    for name in sorted(shared_memory.segments(directory) - set(existing)):
        port = _port(name)
        if port is not None and _domain_of_port(port) not in domains:
            continue
        try:
            if now - (directory / name).stat().st_mtime < CREATION_GRACE:
                continue
            with (directory / f'{name}_el').open('rb') as handle:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            continue  # a live participant holds it
        except FileNotFoundError:
            pass  # no lock file: nobody can hold it
        removed.append(shared_memory.remove_segment(name, directory))
    return removed


def _port(segment: str) -> Optional[int]:
    suffix = segment[len('fastrtps_port'):]
    return int(suffix) if segment.startswith('fastrtps_port') and suffix.isdigit() else None


def _domain_of_port(port: int) -> int:
    """Fast DDS's default port mapping: 7400 + 250 x domain + offsets below 250."""
    return (port - PORT_BASE) // DOMAIN_GAIN


def wait_any_exit(children: list, timeout: float, poll: float = 0.05) -> Optional[Child]:
    """Wait up to ``timeout`` s for any child to exit; return it, or None."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for child in children:
            if child.returncode is not None:
                return child
        time.sleep(poll)
    return None


def run_until_stopped(session, program: str, ready: Callable[[], str], *,
                      limit: float = math.inf,
                      why: Callable[[Optional[Child]], str] = lambda ended: 'stopped') -> int:
    """Start ``session``, run it until Ctrl-C, a child's exit or ``limit`` s, stop it; its code.

    ``session`` starts, stops (returning each child's exit code) and says which child exited
    first; ``ready()`` and ``why(that child)`` are the lines said once it is up and once it has
    stopped. The code: 1 when it could not start or a child failed (a Ctrl-C is no failure).
    """
    stop = []
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.append(True))
    try:
        session.start()
    except RuntimeError as error:
        print(f'{program}: {error}', file=sys.stderr)
        return 1
    print(f'{program}: {ready()}', flush=True)
    deadline = time.monotonic() + limit
    while not stop and time.monotonic() < deadline and session.exited() is None:
        time.sleep(0.05)
    ended = session.exited()
    codes = session.stop()
    print(f'{program}: {why(ended)} ({", ".join(f"{n}: {c}" for n, c in codes.items())})')
    return 1 if any(code not in (0, -signal.SIGINT) for code in codes.values()) else 0
