"""The simulated robot at the patient: ``robot/target_pose`` in; TCP pose and F/T wrench out.

It stands where a real arm's stack would (cartesian_controllers' ``target_pose``, the
force_torque_sensor_broadcaster's wrench): the impedance-controlled TCP
(``ImpedanceRobot``) presses the patient phantom's Hunt–Crossley tissue (``Tissue`` on the
scene's skin), and the wrist's sensor (``ForceTorqueSensor``) reads the force. Publishes
``robot/tcp_pose`` (PoseStamped) and ``robot/ft_sensor/wrench`` (WrenchStamped) at ``rate``.
A target in another frame, or with NaN, is refused (counted, reported at 1 Hz): the robot keeps
the last good one.

The patient's force bound is enforced here again, on the robot's own state, whatever the node
commanding it heard (``PatientSafety``): each target is kept within the reach of the TCP at which
the spring presses ``max_patient_force`` less ``force_margin``, so a forged target, or a
commanding node fed a forged TCP pose, cannot press harder; and when targets stop coming for
``target_timeout`` the robot holds its TCP, then retracts along its own sensor's force. It says
what it is on ``robot/impedance`` (latched), so the commanding node can check its assumptions.
"""
import time
from typing import Sequence

import numpy as np
from rclpy.node import Node

from collision_engine import load_scene
from haptic_contract.checks import finite_components, nonzero_components
from haptic_contract.graph import (ROBOT_FT_WRENCH, ROBOT_IMPEDANCE, ROBOT_TARGET_POSE,
                                   ROBOT_TCP_POSE)
from haptic_contract.streams import frame, POSE, POSE_ORIENTATION, POSE_POSITION, WRENCH
from haptic_contract.teleop_fields import impedance_message
from haptic_msgs.msg import RobotImpedance
from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import run_nodes, StartupError
from haptic_util.intra_process import stream_publisher, stream_subscription
from haptic_util.parameters import declare_parameters
from haptic_util.paths import resolve_path
from haptic_util.qos import LATCHED_QOS
from haptic_util.stamps import clock_ns
from haptic_util.tally import Tally
from robot_site.assembly import ft_sensor, impedance_robot, robot_safety, tissue
from robot_site.params import SimulatedRobotParams
from robot_site.tissue import SceneSurface

__all__ = ['SimulatedRobotNode', 'main']


class SimulatedRobotNode(Node):
    """An impedance-controlled arm holding the probe on the patient, with its F/T sensor."""

    def __init__(self, **kwargs):
        super().__init__('sim_robot', **kwargs)
        self.params = params = declare_parameters(self, SimulatedRobotParams)
        try:
            scene = load_scene(resolve_path(params.scene_file, what='parameter scene_file'),
                               announce=self.get_logger().info)
            self.robot = impedance_robot(params, tissue(params, SceneSurface(scene)))
            self.sensor = ft_sensor(params)
            self.guard = robot_safety(params)
        except ValueError as error:
            raise StartupError(f'{self.get_name()}: {error}') from None
        self._start = time.monotonic()
        self._asked = self.robot.config.initial_position  # the latest target received
        self._measured = np.zeros(3)  # the sensor's latest force
        self._refused = Tally()
        self._published = 0
        self._pose_pub = stream_publisher(self, POSE, ROBOT_TCP_POSE)
        self._wrench_pub = stream_publisher(self, WRENCH, ROBOT_FT_WRENCH)
        stream_subscription(self, POSE, ROBOT_TARGET_POSE, self.on_target,
                            refused=self._refused)
        self.create_timer(1.0 / params.rate, self.tick)
        config = self.robot.config
        self.create_publisher(RobotImpedance, ROBOT_IMPEDANCE, LATCHED_QOS).publish(
            impedance_message(params.frame_id, stiffness=config.stiffness,
                              max_speed=config.max_speed,
                              workspace_lower=config.workspace_lower,
                              workspace_upper=config.workspace_upper,
                              max_patient_force=params.max_patient_force))
        self.diagnostics = Diagnostics(self, self.report, 1.0)

    def _now(self) -> float:
        """Return the robot's clock (s): monotonic, so a step of the system clock moves nothing."""
        return time.monotonic() - self._start

    def on_target(self, fields: Sequence) -> None:
        if frame(fields) != self.params.frame_id:
            self._refused.add(f'target in frame {frame(fields)!r}')
            return
        try:
            asked = finite_components(fields[POSE_POSITION], 3, 'target position')
            nonzero_components(fields[POSE_ORIENTATION], 4, 'target orientation')
        except ValueError as error:  # NaN, a zero quaternion
            self._refused.add('target not finite', str(error))
            return
        now = self._now()
        self.robot.advance(now)  # the old target up to now
        self._asked = asked
        self.guard.heard(now)
        self._command(now)

    def _command(self, now: float) -> None:
        """Command what the patient's bound leaves of the latest target, from the TCP now."""
        self.robot.command(self.guard.safe_target(now, self._asked, self.robot.position,
                                                  self._measured))

    def tick(self) -> None:
        now = self._now()
        state = self.robot.read(now)
        reading = self.sensor.measure(state.time, state.external_force)
        self._measured = reading.force
        if self.guard.watchdog.silent(now):
            self._command(now)  # hold, then retract
        sec, nanosec = divmod(clock_ns(self.get_clock()), 1_000_000_000)
        header = (sec, nanosec, self.params.frame_id)
        self._pose_pub.publish((*header, *state.position.tolist(),
                                *state.orientation.tolist()))
        self._wrench_pub.publish((*header, *reading.force.tolist(),
                                  *reading.torque.tolist()))
        self._published += 1

    def report(self) -> Report:
        self._refused.log_new(lambda line: self.get_logger().warn(f'targets refused: {line}'))
        state = self.robot.state()
        holding = self.guard.holding
        return Report(WARN if holding else OK, ('no target: holding and retracting; ' if holding
                                                else '') +
                      f'TCP at {np.round(state.position, 4).tolist()} m, patient force '
                      f'{np.linalg.norm(state.external_force):.2f} N',
                      {'published': self._published, 'refused': self._refused.total(),
                       'holding': holding,
                       'patient_force_n': float(np.linalg.norm(state.external_force))})

    def destroy_node(self) -> bool:
        self.diagnostics.final()
        return super().destroy_node()


def main(args=None) -> int:
    return run_nodes([SimulatedRobotNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
