"""The DDS domains of this test session, held for the session so parallel runs never share one.

Each session takes two domains (a loop may run beside another) by locking a file per domain in
the temp folder; a lock dies with its process, so a killed session frees its domains.
"""
import fcntl
import functools
import os
import tempfile

__all__ = ['session_domain_id']

FIRST, LAST = 1, 200  # ROS_DOMAIN_IDs to take from (all valid on one machine)
_held = []  # open lock files: closing one would free its domain


@functools.lru_cache(maxsize=None)
def _domains() -> tuple:
    taken = []
    for domain in range(FIRST, LAST + 1):
        handle = open(os.path.join(tempfile.gettempdir(), f'haptic_tests_domain_{domain}.lock'),
                      'w')
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.close()
            continue
        _held.append(handle)
        taken.append(domain)
        if len(taken) == 2:
            return tuple(taken)
    raise RuntimeError(f'no two free DDS domains in {FIRST}..{LAST} for this test session')


def session_domain_id(second: bool = False) -> int:
    """Return this session's domain; ``second``: its other one, for a loop beside the first."""
    return _domains()[1 if second else 0]
