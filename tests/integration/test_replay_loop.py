"""The driver replays a recorded trajectory open loop, and the collision node answers it."""
import time

from domains import session_domain_id
from loop_client import LoopClient
import numpy as np

from haptic_bringup.launcher import Loop, LoopConfig

TOP = -0.025  # [m] the cuboid's top face


def test_a_csv_trajectory_is_replayed_through_the_loop(tmp_path):
    trajectory = tmp_path / 'dive.csv'
    times = np.linspace(0.0, 1.0, 101)
    rows = ['t,x,y,z,roll,yaw'] + [f'{t:.3f},0.01,-0.02,{-0.05 * t:.6f},0.0,0.0' for t in times]
    trajectory.write_text('\n'.join(rows) + '\n')
    config = LoopConfig(nodes=('wand_driver', 'collision_engine'),
                        domain_id=session_domain_id(), run_dir=tmp_path / 'launch',
                        overrides={'wand_driver': {'device': 'replay',
                                                   'replay_file': str(trajectory),
                                                   'wait_for_wrench': False}})
    with Loop(config):
        client = LoopClient(session_domain_id())
        try:
            deadline = time.monotonic() + 20.0
            while time.monotonic() < deadline and len(client.states) < 1500:
                client.executor.spin_once(timeout_sec=0.01)
        finally:
            client.close()
    states = [client.states[k] for k in sorted(client.states)]
    assert len(states) >= 1000
    tips = np.array([(s.tip.x, s.tip.y, s.tip.z) for s in states])
    np.testing.assert_allclose(tips[:, :2], np.broadcast_to([0.01, -0.02], (len(tips), 2)),
                               atol=1e-12)
    assert tips[:, 2].max() <= 1e-12 and tips[:, 2].min() >= -0.05 - 1e-12
    # Open loop: the replay does not stop at the surface; the distance is to the top face.
    distances = np.array([s.distance for s in states])
    np.testing.assert_allclose(distances, tips[:, 2] - TOP, atol=1e-12)
    assert distances.min() < -0.02
