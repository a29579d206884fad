"""Shared test set-up: domains, Hypothesis profiles, serial tests, no shared memory left behind.

The tests' helpers here (``domains``, ``fuzzing``, ``load``) import by name: pytest puts this
file's folder on the path as it loads it (its default import mode). The ground truth, the
benchmarks and the report are packages of their own (``make setup`` installs them).

Hypothesis profiles: ``ci`` (loaded when ``CI`` is set, as ``make test`` and ``.ci/run`` do)
draws the same examples on every run, so CI is deterministic; ``fuzz`` (``make fuzz``) draws
fresh random examples, ten times as many (``fuzzing.examples``); ``dev`` is Hypothesis's default.
``HYPOTHESIS_PROFILE`` picks one explicitly.
"""
import gc
import os
import pathlib

from hypothesis import HealthCheck, settings
import pytest

_SEGMENTS_BEFORE = pytest.StashKey[set]()

# Anything a test starts that speaks DDS stays on this machine, in a domain of its own.
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
os.environ.setdefault('ROS_DOMAIN_ID', '42')

settings.register_profile('ci', derandomize=True, deadline=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile('fuzz', deadline=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile('dev', deadline=None)
settings.load_profile(os.environ.get('HYPOTHESIS_PROFILE')
                      or ('ci' if os.environ.get('CI') else 'dev'))


TESTS = pathlib.Path(__file__).resolve().parent
# Tests that start ROS nodes or processes, or time what they run. ``make test`` runs them one at
# a time after the others, which share both cores (pytest-xdist): no sibling test takes a core
# from what they measure.
SERIAL = ('integration/', 'haptic_util/', 'haptic_wand_driver/', 'robot_site/', 'teleop_leader/',
          'haptic_bringup/', 'site_gateway/', 'ultrasound_sim/test_imaging_session.py',
          'collision_engine/test_jit.py')
# Of those folders, what times nothing: a build, and processes refused at start.
SHARED = ('integration/test_colcon_build.py', 'integration/test_bad_configuration.py')


def pytest_configure(config):
    config.addinivalue_line('markers', 'serial: starts ROS nodes or processes, or times what '
                            'it runs: run alone (make test runs them after the others)')


def pytest_collection_modifyitems(config, items):
    for item in items:
        relative = item.path.resolve().relative_to(TESTS).as_posix()
        if relative.startswith(SERIAL) and not relative.startswith(SHARED):
            item.add_marker(pytest.mark.serial)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_teardown(item):
    """Collect what a test that starts ROS nodes left, once its fixtures are torn down.

    A node outlives its context's shutdown while anything holds it, and so does its DDS
    participant, every endpoint still matched. A callback that holds its own publisher (a
    stream's source) is a reference cycle, gone only when Python collects it: under load, the
    next test's reader in the same domain counted the last test's writer as well (4 runs in 25
    with two cores kept busy; none in 40 with this).
    """
    yield
    if item.get_closest_marker('serial'):
        gc.collect()


def pytest_sessionstart(session):
    """Note the Fast DDS segments there are before the tests start: only later ones are ours."""
    from haptic_util.shared_memory import segments
    session.config.stash[_SEGMENTS_BEFORE] = segments()


def pytest_sessionfinish(session, exitstatus):
    """Leave no Fast DDS shared memory of ours behind (nodes killed on purpose, and our own)."""
    from haptic_bringup.processes import clean_stale_shm
    from domains import session_domain_id
    clean_stale_shm(domains=[int(os.environ['ROS_DOMAIN_ID']), session_domain_id(),
                             session_domain_id(second=True)],
                    existing=session.config.stash[_SEGMENTS_BEFORE])
