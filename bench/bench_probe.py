"""The mounted probe's cost per loop tick: the collision node's half and the force node's half.

    .venv/bin/python bench/bench_probe.py [--poses 2000]

Per scene with a tool (``probe_flat``, ``probe_phantom``), at poses drawn near the surface below
the start (the face within +-5 mm of it, rolled and yawed up to 20 degrees), the median and p99
time of what each node does per pose beyond a point tip's work: the collision node's
``query_probe`` (the tool and its 16 face points) with the state's leaves and their CDR bytes,
and the force node's decoding of them, the face law with torque and its three-plane model.
Times from a Python loop, as the nodes make the calls, after a warm-up.
"""

import argparse
import math
from pathlib import Path
import time

from bench import machine
import numpy as np

from collision_engine import load_scene
from collision_engine.conversions import STATE, tool_state
from collision_engine.probe import query_probe
from force_renderer.assembly import state_contact
from force_renderer.probe import ProbeSpringDamper

__all__ = ['main', 'run']

SCENES = Path(__file__).resolve().parents[1] / 'src' / 'collision_engine' / 'scenes'
WARM_UP = 100


def _poses(count: int, rng) -> list:
    roll, yaw = rng.uniform(-0.35, 0.35, (2, count))
    heights = -0.025 + rng.uniform(-0.005, 0.005, count)
    return [((0.0, 0.0, z), (math.cos(0.5 * w) * math.sin(0.5 * r),
                             math.sin(0.5 * w) * math.sin(0.5 * r), math.sin(0.5 * w)
                             * math.cos(0.5 * r), math.cos(0.5 * w) * math.cos(0.5 * r)))
            for z, r, w in zip(heights, roll, yaw)]


def _timed(work, items) -> np.ndarray:
    times = []
    for item in items[:WARM_UP]:
        work(item)
    for item in items:
        start = time.perf_counter()
        work(item)
        times.append(time.perf_counter() - start)
    return np.array(times)


def run(poses: int = 2000) -> list[dict]:
    """Time both halves on each scene; one row per scene and half."""
    rows = []
    rng = np.random.default_rng(0)
    for name in ('probe_flat', 'probe_phantom'):
        scene = load_scene(SCENES / f'{name}.yaml')
        material = scene.objects[0].material
        law = ProbeSpringDamper(material.stiffness, material.damping)
        pose_list = _poses(poses, rng)

        def collision(pose):
            tip, orientation = pose
            probe = query_probe(scene, tip, orientation)
            return STATE.encode(tool_state((0, 0, 'world'), probe, tip, orientation, 0.0, 0))
        states = [collision(pose) for pose in pose_list]

        def force(data):
            fields = STATE.decode(data)
            _, _, contact = state_contact(fields)
            law.force(contact, (0.0, 0.0, 0.0))
            law.torque(contact)
            law.planes(contact)
        for half, work, items in (('collision node', collision, pose_list),
                                  ('force node', force, states)):
            times = _timed(work, items)
            rows.append({'scene': name, 'half': half, 'median_us': 1e6 * np.median(times),
                         'p99_us': 1e6 * np.percentile(times, 99)})
    return rows


def main(argv=None) -> None:
    """Print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--poses', type=int, default=2000)
    args = parser.parse_args(argv)
    print('machine:', machine.line('numpy', 'numba'))
    for row in run(args.poses):
        print(f'{row["scene"]:14s} {row["half"]:15s} median {row["median_us"]:6.1f} us, '
              f'p99 {row["p99_us"]:6.1f} us')


if __name__ == '__main__':
    main()
