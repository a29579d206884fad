"""The telerobotic scan in lockstep, without ROS: the schemes' physics alone, reproducibly.

    .venv/bin/python bench/teleop_lockstep.py [--delays 0 0.025 0.05 0.1 0.25] [--json PATH]

The same pieces as the ROS run, driven by one clock at 1 kHz: the simulated wand with its
scripted hand (the driver's ``SimulatedWand`` at 4 kHz, rendering the model locally or holding
the wrench), the leader, two ``EmulatedLink`` directions, the follower, the impedance robot on
the abdomen's Hunt–Crossley tissue (a flat skin at the phantom's front) and its F/T sensor.
What it shows is what the schemes do with a delay, free of a busy machine's timing; the ROS run
(``teleop_scan.py``) shows that the nodes do the same. Beside the launcher's three schemes it runs
``tdpa-plain``: TDPA's operator-side controller on the wand itself, without the virtual coupling
that ``tdpa`` puts between them, the baseline that chatters.
"""
import argparse
import math
import sys

import machine
import numpy as np
import result_files
import teleop_scan

from haptic_bringup.launcher import SCAN_DURATION
from haptic_util.paths import package_file
from haptic_wand_driver.contact_model import ContactModel, Kind, Plane
from haptic_wand_driver.device import DeviceLimits
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.operator import OperatorHand
from haptic_wand_driver.params import WandDriverParams
from haptic_wand_driver.port_passivity import PortPassivity
from haptic_wand_driver.scripts import WaypointScript
from haptic_wand_driver.simulated import SimulatedWand, SimulatedWandConfig
from remote_probe.follower import Follower, FollowerConfig
from remote_probe.ft_sensor import ForceTorqueSensor
from remote_probe.impedance_robot import ImpedanceRobot, ImpedanceRobotConfig
from remote_probe.leader import Leader, LeaderConfig
from remote_probe.link import EmulatedLink, LinkConfig
from remote_probe.model_estimation import ContactModelEstimator
from remote_probe.params import LeaderParams
from remote_probe.safety import PatientSafety, SafetyConfig
from remote_probe.teleop import CommandLimits, HAND_SPEED
from remote_probe.tissue import ABDOMEN, PlaneSurface, Tissue

__all__ = ['as_series', 'scan', 'SCHEMES']

PLAIN_TDPA = 'tdpa-plain'  # TDPA's controller on the wand itself: the baseline of the coupling
SCHEMES = ('direct', PLAIN_TDPA, 'tdpa', 'model')

SCAN = 'package://remote_probe/config/scan.yaml'
SKIN = -0.025  # [m] the phantom's front, under the probe's start
TICK = 1e-3  # [s]
MODEL_LIFETIME = LeaderParams().model_lifetime  # [s]
ZERO = np.zeros(3)


def _device(scheme: str):
    """Build the driver's simulated wand and hand, rendering as the launcher sets ``scheme``."""
    wand = WandDriverParams()
    limits = DeviceLimits(force_limit=wand.force_limit, torque_limit=wand.torque_limit)
    hand = OperatorHand(WaypointScript.from_file(package_file(SCAN)),
                        stiffness=wand.hand_stiffness, damping=wand.hand_damping)
    device = SimulatedWand(SimulatedWandConfig(
        mass=[wand.device_mass] * 3, damping=[wand.device_damping] * 3,
        step=1.0 / wand.servo_rate, limits=limits), operator=hand)
    renderer = None
    if scheme == 'model':
        renderer = LocalRenderer(
            force_limit=limits.force_limit, torque_limit=limits.torque_limit,
            passivity=PortPassivity(wand.passivity_max_damping), mass=[wand.device_mass] * 3,
            contact_damping_ratio=wand.contact_damping_ratio)
        device.render_locally(renderer)
    return device, renderer


def _model(time: float, plane, tip) -> ContactModel:
    planes = () if plane is None else (Plane(
        tuple(plane.point), tuple(plane.normal), (plane.stiffness,) * 3, (plane.damping,) * 3,
        (0.0, 0.0, 0.0)),)
    return ContactModel(time, Kind.PLANES if planes else Kind.FREE, planes, math.inf,
                        MODEL_LIFETIME, math.inf, tuple(tip), (0.0,) * 6)


def scan(scheme: str, delay: float, *, jitter: float = 0.0, loss: float = 0.0,
         duration: float = SCAN_DURATION, seed: int = 0) -> dict:
    """Run the scan; return per-tick arrays: time, wand, felt (applied), patient, tcp.

    ``scheme`` is one of ``SCHEMES``: the launcher's, or ``tdpa-plain``.
    """
    leader_config = (LeaderConfig('tdpa', coupling=None) if scheme == PLAIN_TDPA
                     else LeaderConfig(scheme))
    scheme = leader_config.scheme
    device, renderer = _device(scheme)
    robot_config = ImpedanceRobotConfig()
    robot = ImpedanceRobot(robot_config, environment=Tissue(
        ABDOMEN, PlaneSurface([0.0, 0.0, SKIN], [0.0, 0.0, 1.0])))
    sensor = ForceTorqueSensor()
    skin = PlaneSurface([0.0, 0.0, SKIN], [0.0, 0.0, 1.0])
    follower = Follower(FollowerConfig(scheme, robot_config.stiffness),
                        PatientSafety(SafetyConfig(robot_stiffness=robot_config.stiffness)),
                        CommandLimits(robot_config.workspace_lower,
                                      robot_config.workspace_upper, HAND_SPEED),
                        ContactModelEstimator(), surface=lambda tcp: (skin.point, skin.normal))
    leader = Leader(leader_config, ZERO, robot_config.initial_position)
    link = LinkConfig(delay, jitter, loss, seed=seed)
    to_robot, to_operator = EmulatedLink(link), EmulatedLink(LinkConfig(
        delay, jitter, loss, seed=seed + 1))
    rows = []
    state, remote = device.read(0.0), robot.read(0.0)
    for k in range(1, round(duration / TICK)):
        now = k * TICK
        command = leader.command(now, state.position, state.linear_velocity)
        if command is not None:  # none until the feedback is heard
            to_robot.send(now, command)
        for delivery in to_robot.deliver(now):
            follower.receive(now, delivery.payload)
        reading = sensor.measure(now, remote.external_force).force
        robot.command(follower.target(now, remote.position, remote.velocity, reading, TICK))
        to_operator.send(now, follower.feedback(now))
        for delivery in to_operator.deliver(now):
            leader.receive(now, delivery.payload)
        if renderer is not None:
            renderer.take(_model(now, leader.plane(now, state.position), state.position),
                          now + MODEL_LIFETIME)
        else:
            device.apply(leader.force(now, state.position, state.linear_velocity, TICK), ZERO,
                         until=now + MODEL_LIFETIME)
        state, remote = device.read(now + TICK), robot.read(now + TICK)
        rows.append((now, *state.position, *device.applied()[0], *remote.external_force,
                     *remote.position))
    table = np.array(rows)
    return {'time': table[:, 0], 'wand': table[:, 1:4], 'felt': table[:, 4:7],
            'patient': table[:, 7:10], 'tcp': table[:, 10:13]}


def as_series(run: dict) -> dict:
    """Return the run as ``teleop_scan.read_scan`` gives a bag: topic → (times, vectors)."""
    return {'/wand/pose': (run['time'], run['wand']),
            '/wand/applied_wrench': (run['time'], run['felt']),
            '/remote/robot/ft_sensor/wrench': (run['time'], run['patient']),
            '/remote/robot/tcp_pose': (run['time'], run['tcp'])}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--schemes', nargs='+', default=list(SCHEMES), choices=SCHEMES)
    parser.add_argument('--delays', nargs='+', type=float,
                        default=[0.0, 0.01, 0.025, 0.05, 0.1, 0.25])
    parser.add_argument('--jitter', type=float, default=0.1, help='fraction of the delay')
    parser.add_argument('--loss', type=float, default=0.01)
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    print(f'machine: {machine.line("numpy")} (no ROS: one clock, lockstep)')
    teleop_scan.print_header()
    rows = []
    for delay in args.delays:
        for scheme in args.schemes:
            run = scan(scheme, delay, jitter=args.jitter * delay, loss=args.loss)
            rows.append({'scheme': scheme, **teleop_scan.figures(as_series(run), delay)})
            teleop_scan.print_row(rows[-1])
    result_files.write(args.json, rows)
    return 0


if __name__ == '__main__':
    sys.exit(main())
