"""Shared test set-up: ``tests/`` is importable, so ``ground_truth`` is one module for all."""
import os
import pathlib
import sys

TESTS = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(TESTS))

# Anything a test starts that speaks DDS stays on this machine, in a domain of its own.
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
os.environ.setdefault('ROS_DOMAIN_ID', '42')


def pytest_sessionfinish(session, exitstatus):
    """Leave no Fast DDS shared memory behind: nodes killed on purpose, and this process's own."""
    from haptic_bringup.processes import clean_stale_shm
    clean_stale_shm()
