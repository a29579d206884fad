"""``haptic_loop`` as a user types it: one process by default, three with ``--separate``."""
import os
import subprocess
import sys

from domains import session_domain_id
import pytest

from haptic_bringup.session import PUBLISHERS, topic_counts

DURATION = 2.0  # [s] of tapping


@pytest.mark.parametrize('flags, layout, processes', [
    ([], 'one process', ['composed']),
    (['--separate'], '3 processes', ['wand_driver', 'collision_engine', 'force_renderer']),
], ids=['default', 'separate'])
def test_the_command_closes_the_loop_records_it_and_stops_cleanly(
        tmp_path, flags, layout, processes):
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    run = subprocess.run(
        [sys.executable, '-m', 'haptic_bringup.launcher', *flags, '--experiment', 'cuboid',
         '--duration', str(DURATION), '--record', str(tmp_path / 'bag'),
         '--run-dir', str(tmp_path / 'launch'), '--domain-id', str(session_domain_id())],
        env=env, capture_output=True, text=True, timeout=180)
    assert run.returncode == 0, run.stdout + run.stderr
    assert 'loop closed in' in run.stdout and f'({layout}, ' in run.stdout, run.stdout
    stopped = run.stdout.split('haptic_loop: stopped (')[1].split(')')[0]
    assert [name for name, _ in (part.split(': ') for part in stopped.split(', '))] == [
        *processes, 'recorder'], stopped
    recorded = topic_counts(tmp_path / 'bag')
    assert all(recorded.get(topic, 0) > 0 for topic in PUBLISHERS), recorded
    poses = recorded['/wand/pose']
    assert 0.5 * DURATION * 1000 <= poses <= 1.5 * DURATION * 1000, poses  # about 1 kHz
