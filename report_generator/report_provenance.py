"""Where a report or a benchmark's result comes from: the machine, versions, date, commit, load."""

import os
from pathlib import Path
import platform
import subprocess
import time

from bench import machine as bench_machine
from report_generator.report_format import format_utc

__all__ = ['OUTPUTS', 'VERSIONED', 'provenance']

ROOT = Path(__file__).resolve().parents[1]
VERSIONED = ('numpy', 'scipy', 'numba', 'ros-jazzy-rclpy', 'python-fcl', 'coal', 'trimesh',
             'rosbags', 'matplotlib')
OUTPUTS = ('report', 'bench/results')  # what the runs write: not the code they ran


def _git(*args: str) -> str:
    try:
        done = subprocess.run(['git', *args], cwd=ROOT, capture_output=True, text=True,
                              timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return ''
    return done.stdout.strip() if done.returncode == 0 else ''


def provenance() -> dict:
    """Describe the machine, the versions, the date, the commit and the load average now."""
    machine = bench_machine.describe(*VERSIONED)
    commit = _git('rev-parse', 'HEAD') or 'unknown'
    dirty = _git('status', '--porcelain', '--untracked-files=no', '--', '.',
                 *(f':!{output}' for output in OUTPUTS))
    return {'date': format_utc(time.time()), 'cpu': machine['cpu'], 'cores': machine['cores'],
            'python': machine['python'], 'platform': platform.platform(),
            'commit': commit + (' (with uncommitted changes)' if dirty else ''),
            'load': list(os.getloadavg()),
            'versions': {package: machine[package] for package in VERSIONED}}
