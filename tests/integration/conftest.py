"""Integration fixtures: the loop's nodes as real processes, in a DDS domain of the test's own."""
import os

from loop_client import LoopClient
import pytest

from haptic_bringup.launcher import Loop, LoopConfig


def session_domain_id(second: bool = False) -> int:
    """Pick a domain per test session, so parallel runs on one machine do not interfere.

    ``second`` gives another domain of the session's, for a loop that runs beside the first.
    """
    return 1 + os.getpid() % 100 + (100 if second else 0)


@pytest.fixture(scope='module')
def collision_and_force(tmp_path_factory):
    """Start the collision and force nodes as processes; the test stands in for the wand."""
    config = LoopConfig(nodes=('collision_engine', 'force_renderer'),
                        domain_id=session_domain_id(), run_dir=tmp_path_factory.mktemp('launch'))
    with Loop(config) as loop:
        yield loop


@pytest.fixture
def client():
    wand = LoopClient(session_domain_id())
    yield wand
    wand.close()
