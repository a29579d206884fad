"""Integration fixtures: the loop's nodes as real processes, in a DDS domain of the test's own."""
import subprocess
import sys

from domains import session_domain_id
from loop_client import LoopClient
import pytest

from haptic_bringup.launcher import Loop, LoopConfig


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


@pytest.fixture
def hogged_core():
    """One core kept busy by another process, as on a workstation doing other work."""
    hog = subprocess.Popen([sys.executable, '-c', 'while True: pass'])
    yield hog
    hog.kill()
    hog.wait()
