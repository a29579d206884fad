"""The robot site's end of the link: ``teleop/command`` in, a safe ``robot/target_pose`` out.

Takes the operator's commands (through the link), the robot's TCP pose and its F/T wrench, and
at ``rate`` commands the robot a target that the patient's safety allows (``Follower``). Sends
``teleop/feedback`` back over the link at ``feedback_rate``: the measured force, the energy books
and the estimated contact plane. A TCP pose or wrench older than ``sensor_timeout`` feeds back no
force; a command older or repeated is ignored by its stamp. ``scene_file`` is the patient's
surface as this site sees it (a depth camera's, here the phantom's mesh), for the model out of
contact.
"""
import math
from typing import Sequence

from geometry_msgs.msg import PoseStamped, WrenchStamped
import numpy as np
from rclpy.node import Node

from collision_engine import load_scene
from haptic_msgs.msg import TeleopCommand, TeleopFeedback
from haptic_util.cdr import MessageCodec
from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import run_nodes, StartupError
from haptic_util.intra_process import stream_publisher, stream_subscription
from haptic_util.parameters import declare_parameters
from haptic_util.paths import resolve_path
from haptic_util.stamps import clock_ns
from haptic_util.tally import Tally
from haptic_wand_driver.experiments import surface_projection
from remote_probe.follower import Follower, FollowerConfig
from remote_probe.model_estimation import ContactModelEstimator
from remote_probe.params import FollowerParams
from remote_probe.safety import PatientSafety, SafetyConfig
from remote_probe.teleop import Command

__all__ = ['FollowerNode', 'main']

COMMAND = MessageCodec(TeleopCommand)
FEEDBACK = MessageCodec(TeleopFeedback)
POSE = MessageCodec(PoseStamped)
WRENCH = MessageCodec(WrenchStamped)
MODEL_FEEDBACK_RATE, FORCE_FEEDBACK_RATE = 100.0, 1000.0  # [Hz] what each scheme's content needs
_IDENTITY = (0.0, 0.0, 0.0, 1.0)


class FollowerNode(Node):
    """Commands the robot from the link, safely, and feeds the contact back."""

    def __init__(self, **kwargs):
        super().__init__('teleop_follower', **kwargs)
        self.params = params = declare_parameters(self, FollowerParams)
        try:
            safety = PatientSafety(SafetyConfig(
                robot_stiffness=params.robot_stiffness,
                max_patient_force=params.max_patient_force, force_margin=params.force_margin,
                link_timeout=params.link_timeout, release_force=params.release_force,
                retract_speed=params.retract_speed))
            surface = None
            if params.scene_file:
                surface = surface_projection(load_scene(
                    resolve_path(params.scene_file, what='parameter scene_file'),
                    announce=self.get_logger().info))
            self.follower = Follower(
                FollowerConfig(params.scheme, params.robot_stiffness, params.drift_rate),
                safety, ContactModelEstimator(), surface=surface)
        except ValueError as error:
            raise StartupError(f'{self.get_name()}: {error}') from None
        self._period = 1.0 / params.rate
        self._tcp = self._tcp_velocity = None
        self._tcp_time = self._force_time = -math.inf
        self._force = np.zeros(3)
        self._refused = Tally()
        self._sent = 0
        self._target_pub = stream_publisher(self, POSE, 'robot/target_pose')
        self._feedback_pub = stream_publisher(self, FEEDBACK, 'teleop/feedback')
        stream_subscription(self, COMMAND, 'teleop/command', self.on_command)
        stream_subscription(self, POSE, 'robot/tcp_pose', self.on_tcp)
        stream_subscription(self, WRENCH, 'robot/ft_sensor/wrench', self.on_wrench)
        self.create_timer(self._period, self.tick)
        rate = params.feedback_rate or (MODEL_FEEDBACK_RATE if params.scheme == 'model'
                                        else FORCE_FEEDBACK_RATE)
        self.create_timer(1.0 / rate, self.send_feedback)
        self.diagnostics = Diagnostics(self, self.report, 1.0)
        self.get_logger().info(f'{params.scheme} scheme: targets at {params.rate:g} Hz, '
                               f'feedback at {rate:g} Hz, patient force at most '
                               f'{params.max_patient_force:g} N')

    def _now(self) -> float:
        return clock_ns(self.get_clock()) * 1e-9

    def on_command(self, fields: Sequence) -> None:
        if fields[2] != self.params.frame_id:
            self._refused.add(f'command in frame {fields[2]!r}')
            return
        values = np.array(fields[3:10], dtype=np.float64)
        if not np.all(np.isfinite(values)):
            self._refused.add('command not finite')
            return
        command = Command(fields[0] + fields[1] * 1e-9, values[:3], values[3:6], values[6])
        if not self.follower.receive(self._now(), command):
            self._refused.add('command older than the held one')

    def on_tcp(self, fields: Sequence) -> None:
        now = self._now()
        position = np.array(fields[3:6], dtype=np.float64)
        if self._tcp is not None and now > self._tcp_time:
            self._tcp_velocity = (position - self._tcp) / (now - self._tcp_time)
        self._tcp, self._tcp_time = position, now

    def on_wrench(self, fields: Sequence) -> None:
        self._force, self._force_time = np.array(fields[3:6], dtype=np.float64), self._now()
        if not np.all(np.isfinite(self._force)):
            self._refused.add('F/T wrench not finite')

    def tick(self) -> None:
        now = self._now()
        if self._tcp is None:
            return  # the robot has not spoken yet
        fresh = (now - self._force_time <= self.params.sensor_timeout
                 and now - self._tcp_time <= self.params.sensor_timeout)
        force = self._force if fresh else np.full(3, np.nan)
        velocity = self._tcp_velocity if self._tcp_velocity is not None else np.zeros(3)
        target = self.follower.target(now, self._tcp, velocity, force, self._period)
        sec, nanosec = divmod(clock_ns(self.get_clock()), 1_000_000_000)
        self._target_pub.publish((sec, nanosec, self.params.frame_id,
                                  *target.tolist(), *_IDENTITY))

    def send_feedback(self) -> None:
        if self._tcp is None:
            return
        now_ns = clock_ns(self.get_clock())
        feedback = self.follower.feedback(now_ns * 1e-9)
        echo = round(feedback.echo * 1e9)
        plane = feedback.plane
        kind = TeleopFeedback.KIND_FREE if plane is None else TeleopFeedback.KIND_PLANE
        plane_fields = ((0.0,) * 15 if plane is None else
                        (*plane.point.tolist(), *plane.normal.tolist(), *[plane.stiffness] * 3,
                         *[plane.damping] * 3, 0.0, 0.0, 0.0))
        self._feedback_pub.publish((
            *divmod(now_ns, 1_000_000_000), self.params.frame_id, *divmod(echo, 1_000_000_000),
            feedback.echo_hold, *feedback.force.tolist(), *feedback.tcp.tolist(),
            feedback.energy_in, kind, *plane_fields))
        self._sent += 1

    def report(self) -> Report:
        self._refused.log_new(lambda line: self.get_logger().warn(f'refused: {line}'))
        holding = self.follower.safety.holding
        return Report(WARN if holding else OK,
                      'link silent: holding and retracting' if holding else 'following',
                      {'published': self._sent, 'holding': holding,
                       'refused': self._refused.total(),
                       **{f'refused: {kind}': n for kind, n in self._refused.counts.items()}})

    def destroy_node(self) -> bool:
        self.diagnostics.final()
        return super().destroy_node()


def main(args=None) -> int:
    return run_nodes([FollowerNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
