"""Where a report comes from: the machine, the versions, the date and the commit it was made on."""

from pathlib import Path
import platform
import subprocess
import time

import machine as bench_machine
from report_format import format_utc

__all__ = ['VERSIONED', 'provenance']

ROOT = Path(__file__).resolve().parents[1]
VERSIONED = ('numpy', 'scipy', 'numba', 'ros-jazzy-rclpy', 'python-fcl', 'coal', 'trimesh',
             'rosbags', 'matplotlib')


def _git(*args: str) -> str:
    try:
        done = subprocess.run(['git', *args], cwd=ROOT, capture_output=True, text=True,
                              timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return ''
    return done.stdout.strip() if done.returncode == 0 else ''


def provenance() -> dict:
    """Describe the machine, the versions, the date and the commit the report is made on."""
    machine = bench_machine.describe(*VERSIONED)
    commit = _git('rev-parse', 'HEAD') or 'unknown'
    dirty = _git('status', '--porcelain', '--untracked-files=no')
    return {'date': format_utc(time.time()), 'cpu': machine['cpu'], 'cores': machine['cores'],
            'python': machine['python'], 'platform': platform.platform(),
            'commit': commit + (' (with uncommitted changes)' if dirty else ''),
            'versions': {package: machine[package] for package in VERSIONED}}
