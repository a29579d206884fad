"""Fast DDS's shared-memory segments on this machine: listing them, whose they are, removing one.

Fast DDS keeps each participant's data segment (0.5 MB) and each of its input ports as files in
/dev/shm, each beside a lock file (``<segment>_el``) that its owner holds with ``flock`` while it
lives, and a named semaphore (``sem.<segment>_mutex``). A participant deleted normally removes
what it owns; a process that ends with its participant alive (killed, or a node process, see
``haptic_util.executor``) leaves them behind.
"""
import os
import pathlib
from typing import Iterable

__all__ = ['SHM_DIR', 'held_by', 'remove_segment', 'remove_segments_held_by', 'segments']

SHM_DIR = pathlib.Path('/dev/shm')
LOCKS = pathlib.Path('/proc/locks')


def segments(directory: pathlib.Path = SHM_DIR) -> set:
    """Names of the Fast DDS segments now in ``directory``."""
    return {path.name for path in directory.glob('fastrtps_*') if not path.name.endswith('_el')}


def remove_segment(segment: str, directory: pathlib.Path = SHM_DIR) -> str:
    """Remove ``segment``, its lock file and its semaphore; return its name."""
    for name in (segment, f'{segment}_el', f'sem.{segment}_mutex'):
        (directory / name).unlink(missing_ok=True)
    return segment


def held_by(pid: int, directory: pathlib.Path = SHM_DIR, locks: pathlib.Path = LOCKS) -> list:
    """Return the segments in ``directory`` whose lock file ``pid`` holds: the ones it owns."""
    held = {_file_of(fields) for fields in _flocks(locks) if int(fields[4]) == pid}
    owned = []
    for lock in directory.glob('fastrtps_*_el'):
        try:
            status = lock.stat()
        except FileNotFoundError:  # removed meanwhile
            continue
        if (os.major(status.st_dev), os.minor(status.st_dev), status.st_ino) in held:
            owned.append(lock.name[:-len('_el')])
    return sorted(owned)


def remove_segments_held_by(pid: int, directory: pathlib.Path = SHM_DIR) -> list:
    """Remove the segments ``pid`` owns (only just before it ends: it still maps them)."""
    return [remove_segment(segment, directory) for segment in held_by(pid, directory)]


def _flocks(locks: pathlib.Path) -> Iterable[list]:
    """Yield the fields of each granted ``flock`` in ``/proc/locks`` (waiters: '->', skipped)."""
    for line in locks.read_text().splitlines():
        fields = line.split()
        if len(fields) >= 6 and fields[1] == 'FLOCK':
            yield fields


def _file_of(fields: list) -> tuple:
    """(major, minor, inode) of a ``/proc/locks`` entry's file (``MAJ:MIN:INODE``, hex:hex:dec)."""
    major, minor, inode = fields[5].split(':')
    return int(major, 16), int(minor, 16), int(inode)
