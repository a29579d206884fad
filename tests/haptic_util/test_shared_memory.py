"""A process finds the Fast DDS segments it owns by the locks it holds, and removes only those."""
import fcntl
import os
import subprocess
import sys

from haptic_util.shared_memory import held_by, remove_segments_held_by, segments


def _segment(directory, name: str) -> None:
    for file in (name, f'{name}_el', f'sem.{name}_mutex'):
        (directory / file).write_bytes(b'')


def test_the_segments_whose_lock_a_process_holds_are_its_own_and_only_those_go(tmp_path):
    for name in ('fastrtps_0123456789abcdef', 'fastrtps_port7411', 'fastrtps_port7413'):
        _segment(tmp_path, name)
    owned = ['fastrtps_0123456789abcdef', 'fastrtps_port7411']
    mine = [open(tmp_path / f'{name}_el', 'rb') for name in owned]
    for handle in mine:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    # Another live process holds the third, as a peer participant does.
    peer = subprocess.Popen(
        [sys.executable, '-c', 'import fcntl, sys; h = open(sys.argv[1], "rb"); '
         'fcntl.flock(h, fcntl.LOCK_EX); print("locked", flush=True); sys.stdin.read()',
         str(tmp_path / 'fastrtps_port7413_el')],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert peer.stdout.readline() == 'locked\n'
        assert held_by(os.getpid(), tmp_path) == owned
        assert held_by(peer.pid, tmp_path) == ['fastrtps_port7413']
        assert remove_segments_held_by(os.getpid(), tmp_path) == owned
        assert segments(tmp_path) == {'fastrtps_port7413'}
        assert sorted(path.name for path in tmp_path.iterdir()) == [
            'fastrtps_port7413', 'fastrtps_port7413_el', 'sem.fastrtps_port7413_mutex']
    finally:
        peer.communicate('')
        for handle in mine:
            handle.close()
