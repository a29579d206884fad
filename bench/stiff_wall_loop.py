"""A stiff wall over the real ROS 2 loop: rebounds and energy, rendered locally or remotely.

    .venv/bin/python bench/stiff_wall_loop.py [--stiffness 160 1000 5000 20000 100000]
                                              [--duration 6] [--rendering local remote]
                                              [--layouts composed separate] [--json PATH]

The virtual-wall sweep (``stiffness_sweep.py``) checks the force law against a simulated device
with a zero-order hold. Here the whole loop runs over ROS 2 and the simulated wand taps the
cuboid's end face, in each layout: ``composed`` (one process, ``haptic_loop``'s and the launch
file's default) and ``separate`` (three processes over DDS, the baseline). A model that comes
later than its lifetime, or after the tip has left its ``valid_radius``, renders nothing, and
the device's passivity then keeps the wall where the hand fell to: a loop whose latency spikes
(the three processes' p99 is 12-16 ms here, ``bench_loop.py``) lets the hand fall millimetres
into a stiff wall on some taps. With ``remote`` rendering the device holds each wrench as it
arrives, about a millisecond after the pose it answers; with ``local`` rendering it renders the
contact model against its current position at its 4 kHz servo rate. Every figure comes from the
bag: contacts per tap (1 is a clean tap, more are rebounds), the net work of the force the device
applied (``wand/applied_wrench``) on the tip (> 0: the loop gave energy to the user's hand), the
deepest penetration with its ratio to that of a continuous wall (``ideal_depth``: the same
taps, the same device law given the exact plane at the tip at 50 kHz, no loop), and the peak
applied force. Both passivity controllers are on in both.
"""
import argparse
from dataclasses import replace
import math
import pathlib
import sys
import tempfile

from bench import machine, result_files, ros_domain
import numpy as np

from collision_engine import load_scene, surface_projection
from force_renderer.params import ForceRendererParams
from haptic_bringup.bag import typestore_with
from haptic_bringup.contacts import contact_intervals
from haptic_bringup.launcher import Loop, LoopConfig
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import applied_work, read_session
from haptic_contract.contact_model import ContactModel, Kind, Plane
from haptic_util.paths import package_file
from haptic_wand_driver.assembly import local_renderer, port_passivity, simulated_wand_config
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.params import WandDriverParams
from haptic_wand_driver.simulated import SimulatedWand
from simulated_operator.experiments import make_script
from simulated_operator.hand import OperatorHand

__all__ = ['compare', 'ideal_depth', 'run', 'main']

SCENE = 'package://collision_engine/scenes/cuboid.yaml'
TAP_PERIOD = 1.05  # [s] the cuboid script's taps come about this often
LAYOUTS = ('composed', 'separate')
IDEAL_RATE = 50_000.0  # [Hz] taken as continuous: the depth moves < 0.5 % from 20 kHz to 100 kHz


def run(stiffness: float, rendering: str, *, layout: str = 'composed', duration: float = 6.0,
        domain_id: int = 42) -> dict:
    """One session of the cuboid taps at ``stiffness`` N/m per axis; returns its figures."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        stats = folder / 'stats.npz'
        config = LoopConfig(
            composed=layout == 'composed', scene=SCENE, experiment='cuboid', duration=duration,
            record=str(folder / 'bag'), domain_id=domain_id, run_dir=folder / 'launch',
            overrides={'force_renderer': {'scene_file': '', 'stiffness': [stiffness] * 3},
                       'wand_driver': {'rendering': rendering, 'stats_file': str(stats)}})
        with Loop(config) as loop:
            if loop.wait(duration + 30.0) is None:
                raise RuntimeError(f'K = {stiffness}: the session did not end')
        session = read_session(folder / 'bag', typestore_with(custom_definitions()))
        record = np.load(stats)
        contacts = contact_intervals(session)
        taps = max(1, round((session.time[-1] - 0.5) / TAP_PERIOD))
        return {'stiffness': stiffness, 'rendering': rendering, 'layout': layout,
                'contacts_per_tap': len(contacts) / taps,
                'net_work_j': applied_work(session),
                'max_depth_m': max((c.max_depth for c in contacts), default=0.0),
                'peak_force_n': float(np.nanmax(np.linalg.norm(session.applied, axis=1))),
                'answered_percent': float(record['answered_percent'])}


def compare(stiffness: float, renderings=('local', 'remote'), layouts=LAYOUTS, *,
            duration: float = 6.0, domain_id: int = 42) -> list[dict]:
    """``run`` once per layout and rendering at ``stiffness``, with the continuous wall's depth."""
    ideal = ideal_depth(stiffness, duration=duration)
    return [{**run(stiffness, rendering, layout=layout, duration=duration, domain_id=domain_id),
             'ideal_depth_m': ideal} for layout in layouts for rendering in renderings]


class _ContinuousWall:
    """The device's own law, handed the exact plane at the tip every servo period: no loop."""

    def __init__(self, renderer: LocalRenderer, scene, stiffness: float, damping) -> None:
        self.renderer, self.scene = renderer, scene
        self.gains = ((stiffness,) * 3, tuple(damping))

    def wrench(self, time, coordinates, rates, period):
        face = self.scene.query(coordinates[:3])
        wall = Plane(tuple(face.point), tuple(face.normal), *self.gains, (0.0, 0.0, 0.0))
        self.renderer.take(ContactModel(time, Kind.PLANES, (wall,), self.renderer.force_limit,
                                        math.inf, math.inf, tuple(coordinates[:3]), (0.0,) * 6),
                           deadline=math.inf)
        return self.renderer.wrench(time, coordinates, rates, period)


def ideal_depth(stiffness: float, *, duration: float = 6.0, rate: float = IDEAL_RATE) -> float:
    """Deepest penetration of the same taps against a continuous wall: the loop at no cost.

    The simulated wand, its hand and the cuboid script as the driver builds them (its default
    parameters), rendering the exact plane at its tip with the device's own law (the force
    renderer's default damping, contact damping, passivity, saturation) at ``rate``, sampled at
    1 kHz as the loop's states are.
    """
    wand, force = WandDriverParams(), ForceRendererParams()
    scene = load_scene(package_file(SCENE))
    hand = OperatorHand(make_script('cuboid', surface_projection(scene)),
                        stiffness=wand.hand_stiffness, damping=wand.hand_damping)
    config = replace(simulated_wand_config(wand), step=1.0 / rate)
    device = SimulatedWand(config, operator=hand)
    device.render_locally(_ContinuousWall(local_renderer(wand, config.limits,
                                                         port_passivity(wand)),
                                          scene, stiffness, force.damping))
    return max(-scene.query(device.read(t).position).distance
               for t in np.arange(0.0, duration, 1e-3))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--stiffness', nargs='+', type=float,
                        default=[160.0, 1e3, 5e3, 2e4, 1e5])
    parser.add_argument('--rendering', nargs='+', default=['local', 'remote'],
                        choices=['local', 'remote'])
    parser.add_argument('--duration', type=float, default=6.0)
    parser.add_argument('--layouts', nargs='+', default=list(LAYOUTS), choices=LAYOUTS)
    ros_domain.add_option(parser)
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    ros_domain.keep_local()
    print(f'machine: {machine.line("ros-jazzy-rclpy", "numba")}')
    print(f'{"K N/m":>8} {"layout":>9} {"rendering":>9} {"contacts/tap":>12} '
          f'{"net work mJ":>11} {"depth mm":>8} {"/ ideal":>7} {"peak N":>7} {"answered":>8}')
    rows = []
    for stiffness in args.stiffness:
        measured = compare(stiffness, args.rendering, args.layouts, duration=args.duration,
                           domain_id=args.domain_id)
        for r in measured:
            print(f'{stiffness:8.0f} {r["layout"]:>9} {r["rendering"]:>9} '
                  f'{r["contacts_per_tap"]:12.1f} {1e3 * r["net_work_j"]:11.2f} '
                  f'{1e3 * r["max_depth_m"]:8.2f} {r["max_depth_m"] / r["ideal_depth_m"]:7.2f} '
                  f'{r["peak_force_n"]:7.2f} {r["answered_percent"]:8.2f}', flush=True)
        rows += measured
    result_files.write(args.json, rows)
    return 0


if __name__ == '__main__':
    sys.exit(main())
