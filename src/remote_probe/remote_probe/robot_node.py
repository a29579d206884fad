"""The simulated robot at the patient: ``robot/target_pose`` in; TCP pose and F/T wrench out.

It stands where a real arm's stack would (cartesian_controllers' ``target_pose``, the
force_torque_sensor_broadcaster's wrench): the impedance-controlled TCP
(``ImpedanceRobot``) presses the patient phantom's Hunt–Crossley tissue (``Tissue`` on the
scene's skin), and the wrist's sensor (``ForceTorqueSensor``) reads the force. Publishes
``robot/tcp_pose`` (PoseStamped) and ``robot/ft_sensor/wrench`` (WrenchStamped) at ``rate``.
A target in another frame, or with NaN, is refused (counted, reported at 1 Hz): the robot keeps
the last good one.
"""
import time
from typing import Sequence

from geometry_msgs.msg import PoseStamped, WrenchStamped
import numpy as np
from rclpy.node import Node

from collision_engine import load_scene
from haptic_util.cdr import MessageCodec
from haptic_util.diagnostics import Diagnostics, OK, Report
from haptic_util.executor import run_nodes, StartupError
from haptic_util.intra_process import stream_publisher, stream_subscription
from haptic_util.parameters import declare_parameters
from haptic_util.paths import resolve_path
from haptic_util.stamps import clock_ns
from haptic_util.tally import Tally
from remote_probe.ft_sensor import ForceTorqueSensor, ForceTorqueSensorConfig
from remote_probe.impedance_robot import ImpedanceRobot, ImpedanceRobotConfig
from remote_probe.params import SimulatedRobotParams
from remote_probe.tissue import HuntCrossley, SceneSurface, Tissue

__all__ = ['SimulatedRobotNode', 'main']

POSE = MessageCodec(PoseStamped)
WRENCH = MessageCodec(WrenchStamped)


class SimulatedRobotNode(Node):
    """An impedance-controlled arm holding the probe on the patient, with its F/T sensor."""

    def __init__(self, **kwargs):
        super().__init__('sim_robot', **kwargs)
        self.params = params = declare_parameters(self, SimulatedRobotParams)
        try:
            scene = load_scene(resolve_path(params.scene_file, what='parameter scene_file'),
                               announce=self.get_logger().info)
            law = HuntCrossley(params.tissue_stiffness, params.tissue_exponent,
                               params.tissue_damping)
            self.robot = ImpedanceRobot(ImpedanceRobotConfig(
                mass=params.mass, stiffness=params.stiffness, max_speed=params.max_speed,
                workspace_lower=np.array(params.workspace_lower),
                workspace_upper=np.array(params.workspace_upper),
                initial_position=np.array(params.initial_position)),
                environment=Tissue(law, SceneSurface(scene)))
            self.sensor = ForceTorqueSensor(ForceTorqueSensorConfig(
                force_bias=np.array(params.force_bias), force_noise=params.force_noise,
                bandwidth=params.sensor_bandwidth, seed=params.seed))
        except ValueError as error:
            raise StartupError(f'{self.get_name()}: {error}') from None
        self._start = time.monotonic()
        self._refused = Tally()
        self._published = 0
        self._pose_pub = stream_publisher(self, POSE, 'robot/tcp_pose')
        self._wrench_pub = stream_publisher(self, WRENCH, 'robot/ft_sensor/wrench')
        stream_subscription(self, POSE, 'robot/target_pose', self.on_target)
        self.create_timer(1.0 / params.rate, self.tick)
        self.diagnostics = Diagnostics(self, self.report, 1.0)

    def _now(self) -> float:
        """Return the robot's clock (s): monotonic, so a step of the system clock moves nothing."""
        return time.monotonic() - self._start

    def on_target(self, fields: Sequence) -> None:
        if fields[2] != self.params.frame_id:
            self._refused.add(f'target in frame {fields[2]!r}')
            return
        try:
            self.robot.advance(self._now())  # the old target up to now
            self.robot.command(fields[3:6], fields[6:10])
        except ValueError as error:  # NaN, a zero quaternion
            self._refused.add('target not finite', str(error))

    def tick(self) -> None:
        state = self.robot.read(self._now())
        reading = self.sensor.measure(state.time, state.external_force)
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
        return Report(OK, f'TCP at {np.round(state.position, 4).tolist()} m, patient force '
                      f'{np.linalg.norm(state.external_force):.2f} N',
                      {'published': self._published, 'refused': self._refused.total(),
                       'patient_force_n': float(np.linalg.norm(state.external_force))})

    def destroy_node(self) -> bool:
        self.diagnostics.final()
        return super().destroy_node()


def main(args=None) -> int:
    return run_nodes([SimulatedRobotNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
