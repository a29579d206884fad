"""Stopping the loop as ``ros2 launch`` and a terminal do: SIGINT to the whole process group.

``ros2 launch`` sends SIGINT to every node on top of the one its process group already got from
the terminal; users press Ctrl-C twice. Each trial starts the three nodes in one process group,
waits until the loop runs, signals the group twice 2 ms apart, at a different moment of the
running loop, and requires every node to exit 0 with nothing on its error stream but its own log
lines. (A SIGINT during a node's first imports, before any of its code runs, ends it as any Python
program: ``KeyboardInterrupt``. The start-up after that is covered in ``test_executor.py``.)
"""
import os
import signal
import subprocess
import time

from domains import session_domain_id
from loop_client import LoopClient
import pytest
import yaml

from haptic_bringup.launcher import loop_environment, LoopConfig, node_parameters, NODES

TRIALS = 20
GAP = 0.002  # [s] between the two SIGINTs
SPREAD = 0.5  # [s] the latest moment after the loop closed that a trial signals at
CRASHES = ('Traceback', 'FATAL', 'terminate called', 'Segmentation fault')


def start_group(tmp_path) -> list:
    """The three nodes, the first one leading a new process group that the others join."""
    config = LoopConfig(experiment='hold', domain_id=session_domain_id())
    env = loop_environment(config.domain_id, tmp_path / 'log')
    params = tmp_path / 'params.yaml'
    params.write_text(yaml.safe_dump(node_parameters(config)))
    processes = []
    for _, module, _ in NODES.values():
        leader = processes[0].pid if processes else 0
        processes.append(subprocess.Popen(
            [config.python, '-m', module, '--ros-args', '--params-file', str(params)],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
            process_group=leader))
    return processes


@pytest.mark.parametrize('trial', range(TRIALS))
def test_two_sigints_to_the_group_stop_every_node_cleanly(tmp_path, trial):
    processes = start_group(tmp_path)
    listener = LoopClient(session_domain_id())
    try:
        assert listener.spin_until(lambda: listener.wrenches, timeout=60.0), 'no loop'
    finally:
        listener.close()
    time.sleep(SPREAD * trial / (TRIALS - 1))
    os.killpg(processes[0].pid, signal.SIGINT)
    time.sleep(GAP)
    try:
        os.killpg(processes[0].pid, signal.SIGINT)
    except ProcessLookupError:
        pass  # every node had already gone
    for process, name in zip(processes, NODES):
        _, err = process.communicate(timeout=60)
        assert process.returncode == 0, f'{name} exited {process.returncode}:\n{err}'
        assert not any(crash in err for crash in CRASHES), f'{name}:\n{err}'
