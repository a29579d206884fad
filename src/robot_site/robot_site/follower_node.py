"""The robot site's end of the link: ``teleop/command`` in, a safe ``robot/target_pose`` out.

Takes the operator's commands (through the link), the robot's TCP pose and its F/T wrench, and
at ``rate`` commands the robot a target that the patient's safety allows (``Follower``). Sends
``teleop/feedback`` back over the link at ``feedback_rate``: the measured force, the energy books
and the estimated contact plane. A TCP pose or wrench older than ``sensor_timeout`` feeds back no
force. A TCP pose the robot cannot have, outside its workspace or farther from the last one
than its top speed allows, is refused (``TcpGate``): a stranger on the robot's network could
otherwise teach the contact model what it likes. ``scene_file`` is the patient's surface as
this site sees it (a depth camera's, here the phantom's mesh), for the model out of contact.

It follows only once the robot has said what it is (``robot/impedance``, latched): the force
bound holds only for the robot's own stiffness, so a robot whose stiffness is not this node's
``robot_stiffness`` is not commanded at all (an error says so), and commands are checked against
its workspace. Every refused command is counted and logged once a second with its reason.
Commands are taken in its tick, at most ``LINK_INTAKE_RATE`` a second (at the default 1 kHz
tick), whoever sends them.
"""
import math
from typing import Sequence

import numpy as np
from rclpy.node import Node
from std_msgs.msg import Empty, Float64

from collision_engine import load_scene, surface_projection
from haptic_contract.graph import (ROBOT_FT_WRENCH, ROBOT_IMPEDANCE, ROBOT_TARGET_POSE,
                                   ROBOT_TCP_POSE, TELEOP_COMMAND, TELEOP_FEEDBACK, TELEOP_HOLD,
                                   TELEOP_RE_ENGAGE)
from haptic_contract.streams import POSE, POSE_POSITION, WRENCH, WRENCH_FORCE
from haptic_contract.teleop import Scheme
from haptic_contract.teleop_fields import (COMMAND, command_from_fields, command_session, FEEDBACK,
                                           feedback_fields, impedance_report)
from haptic_msgs.msg import RobotImpedance
from haptic_util.diagnostics import Diagnostics, ERROR, OK, Report, WARN
from haptic_util.executor import run_nodes, StartupError
from haptic_util.intra_process import (link_subscription, stream_publisher,
                                       stream_subscription)
from haptic_util.parameters import declare_parameters
from haptic_util.paths import resolve_path
from haptic_util.qos import LATCHED_QOS
from haptic_util.stamps import clock_ns
from haptic_util.tally import Tally
from robot_site.assembly import admission_config, follower, follower_config, follower_safety
from robot_site.follower import Follower
from robot_site.params import FollowerParams
from robot_site.tcp_gate import TcpGate
from teleop_protocol.admission import Refusal

__all__ = ['FollowerNode', 'main', 'take_command']

MODEL_FEEDBACK_RATE, FORCE_FEEDBACK_RATE = 100.0, 1000.0  # [Hz] what each scheme's content needs
_IDENTITY = (0.0, 0.0, 0.0, 1.0)
STIFFNESS_TOLERANCE = 0.01  # relative: the robot's reported stiffness against robot_stiffness


class FollowerNode(Node):
    """Commands the robot from the link, safely, and feeds the contact back."""

    def __init__(self, **kwargs):
        super().__init__('teleop_follower', **kwargs)
        self.params = params = declare_parameters(self, FollowerParams)
        try:
            self._safety = follower_safety(params)
            self._surface = None
            if params.scene_file:
                self._surface = surface_projection(load_scene(
                    resolve_path(params.scene_file, what='parameter scene_file'),
                    announce=self.get_logger().info))
            follower_config(params), admission_config(params)  # checked now, used later
        except ValueError as error:
            raise StartupError(f'{self.get_name()}: {error}') from None
        self.follower: Follower | None = None  # once the robot has said what it is
        self._robot_problem = (WARN, 'waiting for the robot\'s robot/impedance')
        self._period = 1.0 / params.rate
        self._tcp: TcpGate | None = None  # once the robot has said what it is
        self._force_time = -math.inf
        self._force = np.zeros(3)
        self._refused = Tally()
        self._sent = 0
        self._target_pub = stream_publisher(self, POSE, ROBOT_TARGET_POSE)
        self._feedback_pub = stream_publisher(self, FEEDBACK, TELEOP_FEEDBACK)
        self._commands = link_subscription(self, COMMAND, TELEOP_COMMAND, self.on_command,
                                           refused=self._refused, in_tick=True)
        for codec, topic, callback in ((POSE, ROBOT_TCP_POSE, self.on_tcp),
                                       (WRENCH, ROBOT_FT_WRENCH, self.on_wrench)):
            stream_subscription(self, codec, topic, callback, refused=self._refused)
        self.create_subscription(RobotImpedance, ROBOT_IMPEDANCE, self.on_impedance,
                                 LATCHED_QOS)
        self.create_subscription(Empty, TELEOP_RE_ENGAGE, self.on_re_engage, 1)
        self.create_subscription(Float64, TELEOP_HOLD, self.on_hold, 1)
        self.create_timer(self._period, self.tick)
        rate = params.feedback_rate or (MODEL_FEEDBACK_RATE if params.scheme == Scheme.MODEL
                                        else FORCE_FEEDBACK_RATE)
        self.create_timer(1.0 / rate, self.send_feedback)
        self.diagnostics = Diagnostics(self, self.report, 1.0)
        self.get_logger().info(f'{params.scheme} scheme: targets at {params.rate:g} Hz, '
                               f'feedback at {rate:g} Hz, patient force at most '
                               f'{params.max_patient_force:g} N')

    def _now(self) -> float:
        return clock_ns(self.get_clock()) * 1e-9

    def on_command(self, fields: Sequence) -> None:
        if self.follower is None:
            self._refused.add('command before the robot is known', self._robot_problem[1])
            return
        refusal = take_command(self.follower, self._now(), fields, self.params.frame_id)
        if refusal is not None:
            self._refused.add(f'command {refusal.kind}', refusal.detail)

    def on_impedance(self, message: RobotImpedance) -> None:
        """Follow once the robot says it is the one the force bound was set for; else stop."""
        frame, report = impedance_report(message, self.params.max_command_speed)
        expected = self.params.robot_stiffness
        if frame != self.params.frame_id:
            problem = f'the robot reports in frame {frame!r}, not {self.params.frame_id!r}'
        elif not abs(report.stiffness - expected) <= STIFFNESS_TOLERANCE * expected:
            problem = (f'the robot\'s stiffness is {report.stiffness:g} N/m, not '
                       f'robot_stiffness {expected:g} N/m: the force bound would not hold')
        elif not (math.isfinite(report.max_speed) and report.max_speed > 0.0):
            problem = (f'the robot reports a top speed of {report.max_speed:g} m/s: its TCP '
                       'poses could not be checked')
        else:
            problem = None
        if problem is not None:
            self.follower, self._robot_problem = None, (ERROR, problem)
            self.get_logger().error(f'not commanding the robot: {problem}')
            return
        limits = (report.limits.workspace_lower, report.limits.workspace_upper, report.max_speed)
        if self._tcp is None:
            self._tcp = TcpGate(*limits)
        else:
            self._tcp.bound(*limits)  # its last pose kept: the robot is where it was
        if self.follower is None:
            self.follower = follower(self.params, report.limits, self._surface,
                                     safety=self._safety)
            self.get_logger().info(f'the robot is as expected ({report.stiffness:g} N/m): '
                                   'following')
        else:
            self.follower.limits = report.limits

    def on_re_engage(self, _: Empty) -> None:
        """Follow again after a hard stop, once the probe has let go (a deliberate act)."""
        if self._safety.envelope.stopped:
            following = self._safety.re_engage()
            self.get_logger().warn('re-engaged: following' if following else
                                   're-engage refused: the probe still presses')

    def on_hold(self, message: Float64) -> None:
        """Hold the asked force (N) at the patient while the operator slides; <= 0 releases."""
        if self.follower is None:
            return
        force = message.data if math.isfinite(message.data) else 0.0
        holding = self.follower.hold_force(force)
        self.get_logger().info(f'holding {force:g} N' if holding else
                               'force-hold released' if force <= 0.0 else
                               f'force-hold of {force:g} N refused: not in contact, or past '
                               'the working limit')

    def on_tcp(self, fields: Sequence) -> None:
        if self._tcp is None:
            self._refused.add('TCP pose before the robot is known', self._robot_problem[1])
            return
        refusal = self._tcp.take(self._now(), fields[POSE_POSITION])
        if refusal is not None:
            self._refused.add(refusal.kind, refusal.detail)

    def on_wrench(self, fields: Sequence) -> None:
        self._force = np.array(fields[WRENCH_FORCE], dtype=np.float64)
        self._force_time = self._now()
        if not np.all(np.isfinite(self._force)):
            self._refused.add('F/T wrench not finite')

    def tick(self) -> None:
        self._commands.take()  # the link is read here, in the tick, not by a timer of its own
        now = self._now()
        tcp = self._tcp  # made with the follower, or before it
        if self.follower is None or tcp.position is None:
            return  # the robot has not spoken yet, or is not the one expected
        fresh = (now - self._force_time <= self.params.sensor_timeout
                 and now - tcp.time <= self.params.sensor_timeout)
        force = self._force if fresh else np.full(3, np.nan)
        target = self.follower.target(now, tcp.position, tcp.velocity, force, self._period)
        sec, nanosec = divmod(clock_ns(self.get_clock()), 1_000_000_000)
        self._target_pub.publish((sec, nanosec, self.params.frame_id,
                                  *target.tolist(), *_IDENTITY))

    def send_feedback(self) -> None:
        if self.follower is None or self._tcp.position is None:
            return
        feedback = self.follower.feedback(clock_ns(self.get_clock()) * 1e-9)
        self._feedback_pub.publish(feedback_fields(feedback, self.params.frame_id))
        self._sent += 1

    def report(self) -> Report:
        self._refused.log_new(lambda line: self.get_logger().warn(f'refused: {line}'))
        values = {'published': self._sent, 'refused': self._refused.total(),
                  **{f'refused: {kind}': n for kind, n in self._refused.counts.items()}}
        if self.follower is None:
            return Report(*self._robot_problem, values)
        holding, stopped = self.follower.safety.holding, self.follower.safety.envelope.stopped
        values.update(holding=holding, hard_stop=stopped, force_hold=self.follower.hold.force,
                      session=f'{self.follower.admission.session:#x}')
        if stopped:
            return Report(ERROR, 'hard stop: holding and retracting until teleop/re_engage',
                          values)
        return Report(WARN if holding else OK,
                      'link silent: holding and retracting' if holding else 'following', values)

    def destroy_node(self) -> bool:
        self.diagnostics.final()
        self._commands.destroy()
        return super().destroy_node()


def take_command(follower: Follower, now: float, fields: Sequence,
                 frame_id: str) -> Refusal | None:
    """Give ``follower`` a TeleopCommand's fields arrived at ``now`` (s); return why not taken.

    A stranger's is refused on its session alone, before anything else of it is read: a flood
    then costs the site the least it can.
    """
    refusal = follower.admission.stranger(now, command_session(fields))
    if refusal is not None:
        return refusal
    frame, command = command_from_fields(fields)
    if frame != frame_id:
        return Refusal('in another frame', repr(frame))
    return follower.receive(now, command)


def main(args=None) -> int:
    return run_nodes([FollowerNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
