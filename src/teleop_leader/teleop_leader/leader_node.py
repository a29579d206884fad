"""The operator site's end of the link: the wand's pose out as a command, its feeling back.

With every wand pose (and its twist, same stamp) it sends ``teleop/command`` over the link and
answers the driver at once from the newest ``teleop/feedback`` (``Leader``): ``wand/wrench`` for
``direct`` and ``tdpa`` (the driver applies it), ``wand/contact_model`` for ``model`` (the driver
renders it at its servo rate). Each answer carries the pose's stamp and a short lifetime, so a
leader that dies leaves no force behind. The session starts at the first feedback, whose TCP is
the robot's anchor, and the wand's latest pose is the wand's. No pose is answered before it: the
driver starts its experiment at the first answer to its probe, and a scripted hand that set off
before the robot was found pressed from an anchor it had already left (the first feedback came
2.2-2.4 s after the scan began over the gateways, the wand 18-20 mm down: the probe tracked that
far above it, and the patient was pressed 5.1 N instead of 7.2). ``teleop/clutch`` (Bool, true:
engaged) re-centres the wand without moving the robot. With ``model``, ``wand/model_shift`` (how
far out the device renders the planes) moves the robot's target out as far.

The feedback is taken in that tick, before the answer (``link_subscription``, ``in_tick``): at
most ``LINK_INTAKE_RATE`` a second, so a flood of feedback on the site's network leaves the
wand's loop its rate, and in the site's process the gateway hands it over in the leader's tick
rather than by a 1 ms timer of its own.
"""
import math
from typing import Sequence

import numpy as np
from rclpy.node import Node
from std_msgs.msg import Bool

from haptic_contract.contact_model import Kind, MODEL, model_fields
from haptic_contract.graph import (TELEOP_CLUTCH, TELEOP_COMMAND, TELEOP_FEEDBACK,
                                   WAND_CONTACT_MODEL, WAND_MODEL_SHIFT, WAND_POSE, WAND_TWIST,
                                   WAND_WRENCH)
from haptic_contract.streams import (frame, POSE, POSE_POSITION, stamp_ns, TWIST, TWIST_LINEAR,
                                     VECTOR, VECTOR_VALUE, WRENCH)
from haptic_contract.teleop import feedback_refusal, Scheme
from haptic_contract.teleop_fields import COMMAND, command_fields, FEEDBACK, feedback_from_fields
from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import run_nodes, StartupError
from haptic_util.intra_process import link_subscription, stream_publisher, stream_subscription
from haptic_util.parameters import declare_parameters
from haptic_util.qos import LATCHED_QOS
from haptic_util.stamps import clock_ns
from haptic_util.tally import Tally
from teleop_leader.leader import Leader, LeaderConfig
from teleop_leader.params import LeaderParams
from teleop_leader.virtual_coupling import CouplingConfig
from teleop_protocol.admission import Admission, AdmissionConfig, Refusal

__all__ = ['LeaderNode', 'main']

_ZERO_WRENCH = (0.0,) * 6


class LeaderNode(Node):
    """Sends the wand to the robot and renders the robot's answer on the wand."""

    def __init__(self, **kwargs):
        super().__init__('teleop_leader', **kwargs)
        self.params = params = declare_parameters(self, LeaderParams)
        try:
            self.config = LeaderConfig(params.scheme, params.force_scale,
                                       params.position_scale, params.link_timeout,
                                       CouplingConfig(params.coupling_mass,
                                                      params.coupling_stiffness,
                                                      params.coupling_damping,
                                                      params.coupling_ground_damping))
            self._admission = AdmissionConfig(
                max_age=params.max_feedback_age, max_lead=params.max_stamp_lead,
                session_timeout=params.session_timeout)
        except ValueError as error:
            raise StartupError(f'{self.get_name()}: {error}') from None
        self.leader: Leader | None = None  # from the first feedback on
        self._pending = None  # (stamp ns, position) of the latest pose
        self._twist = None  # (stamp ns, velocity) of the latest twist
        self._model_shift = np.zeros(3)  # [m] the device's, beyond the planes sent
        self._answered_ns = None  # the stamp of the pose answered last
        self._answered_at = None  # [s] when it was, on this node's clock
        self._last_stamp_ns = None
        self._clutch = False
        self._refused = Tally()
        self._answers = 0
        self._withheld = 0  # poses whose command was not sent: the feedback was silent
        self._unknown = 0  # poses given no model: the feedback was silent
        self._command_pub = stream_publisher(self, COMMAND, TELEOP_COMMAND)
        answer = ((MODEL, WAND_CONTACT_MODEL) if params.scheme == Scheme.MODEL
                  else (WRENCH, WAND_WRENCH))
        self._answer_pub = stream_publisher(self, *answer)
        streams = [(POSE, WAND_POSE, self.on_pose), (TWIST, WAND_TWIST, self.on_twist)]
        if params.scheme == Scheme.MODEL:
            streams.append((VECTOR, WAND_MODEL_SHIFT, self.on_model_shift))
        for codec, topic, callback in streams:
            stream_subscription(self, codec, topic, callback, refused=self._refused)
        self._feedback = link_subscription(self, FEEDBACK, TELEOP_FEEDBACK, self.on_feedback,
                                           refused=self._refused, in_tick=True)
        self.create_subscription(Bool, TELEOP_CLUTCH, self.on_clutch, LATCHED_QOS)
        self.diagnostics = Diagnostics(self, self.report, 1.0)
        self.get_logger().info(f'{params.scheme} scheme: force x{params.force_scale:g}, '
                               f'motion x{params.position_scale:g}; waiting for the robot')

    def _now(self) -> float:
        return clock_ns(self.get_clock()) * 1e-9

    def on_feedback(self, fields: Sequence) -> None:
        frame, feedback = feedback_from_fields(fields)
        if frame != self.params.robot_frame:
            self._refuse(Refusal('in another frame', repr(frame)))
        elif self.leader is not None:
            self._refuse(self.leader.receive(self._now(), feedback))
        elif self._pending is not None:  # the wand's start is known: the session starts
            refusal = feedback_refusal(feedback)
            if refusal is not None:
                self._refuse(refusal)
                return
            self.leader = Leader(self.config, self._pending[1], feedback.tcp,
                                 admission=Admission(self._admission))
            self.get_logger().info(f'robot found at {np.round(feedback.tcp, 4).tolist()} m: '
                                   f'following the wand (session {self.leader.session:#x})')
            self._refuse(self.leader.receive(self._now(), feedback))

    def _refuse(self, refusal: Refusal | None) -> None:
        if refusal is not None:
            self._refused.add(f'feedback {refusal.kind}', refusal.detail)

    def on_pose(self, fields: Sequence) -> None:
        if frame(fields) != self.params.frame_id:
            self._refused.add(f'pose in frame {frame(fields)!r}')
            return
        self._pending = (stamp_ns(fields), np.array(fields[POSE_POSITION], dtype=np.float64))
        self._answer_when_paired()

    def on_twist(self, fields: Sequence) -> None:
        self._twist = (stamp_ns(fields), fields[TWIST_LINEAR])
        self._answer_when_paired()

    def on_model_shift(self, fields: Sequence) -> None:
        shift = np.array(fields[VECTOR_VALUE], dtype=np.float64)
        if frame(fields) != self.params.frame_id or not np.all(np.isfinite(shift)):
            self._refused.add('model shift not finite or in another frame')
            return
        self._model_shift = shift

    def _answer_when_paired(self) -> None:
        """Answer the pose once the twist of its stamp is in too, whichever came first; once."""
        if (self._pending is None or self._twist is None or self._twist[0] != self._pending[0]
                or self._pending[0] == self._answered_ns):
            return
        stamp_ns, position = self._pending
        velocity = np.array(self._twist[1], dtype=np.float64)
        self._answered_ns, self._answered_at = stamp_ns, self._now()
        self._feedback.take()  # what came over the link since the last pose
        if not (np.all(np.isfinite(position)) and np.all(np.isfinite(velocity))):
            self._refused.add('wand pose or twist not finite')
            self._answer(stamp_ns, None)
            return
        if self.leader is None:  # unanswered: the driver's probe of the loop waits for the robot
            self._unknown += 1
            return
        period = (stamp_ns - self._last_stamp_ns) * 1e-9 if self._last_stamp_ns else 1e-3
        self._last_stamp_ns = stamp_ns
        command = self.leader.command(stamp_ns * 1e-9, position, velocity, self._model_shift)
        now = self._now()
        if self.params.scheme == Scheme.MODEL:
            known, plane = self.leader.model(now, position)
            if known:
                self._answer(stamp_ns, plane, position)
            else:
                self._unknown += 1
        else:
            self._answer(stamp_ns, self.leader.force(now, position, velocity,
                                                     max(period, 1e-6)))
        # After the hand's answer: sending it to the other site (the gateway's encoding and
        # put, when the gateway is in this process) never delays what the hand feels.
        if command is None:
            self._withheld += 1
        else:
            self._command_pub.publish(command_fields(command, self.params.robot_frame))

    def _answer(self, stamp_ns: int, answer, position=None) -> None:
        """Publish the wrench or model for the pose ``stamp_ns``; None: zero force, no model."""
        header = (*divmod(stamp_ns, 1_000_000_000), self.params.frame_id)
        self._answers += 1
        if self.params.scheme != Scheme.MODEL:
            force = (0.0, 0.0, 0.0) if answer is None else tuple(answer.tolist())
            self._answer_pub.publish((*header, *force, 0.0, 0.0, 0.0))
            return
        tip = (0.0, 0.0, 0.0) if position is None else tuple(position.tolist())
        planes = () if answer is None else ((
            answer.point.tolist(), answer.normal.tolist(), (answer.stiffness,) * 3,
            (answer.damping,) * 3),)
        self._answer_pub.publish(model_fields(
            header, 'patient', Kind.PLANES if planes else Kind.FREE, planes,
            self.params.force_limit, self.params.model_lifetime, self.params.model_valid_radius,
            tip, _ZERO_WRENCH))

    def on_clutch(self, msg: Bool) -> None:
        if self.leader is None or self._pending is None:
            return
        if msg.data:
            self.leader.map.engage(self._pending[1])
        else:
            self.leader.map.release(self._pending[1])

    def report(self) -> Report:
        self._refused.log_new(lambda line: self.get_logger().warn(f'refused: {line}'))
        leader, now = self.leader, self._now()
        live = leader is not None and leader.live(now)
        # The feedback is read at the wand's poses: with the wand silent, so is the link.
        wand_live = self._answered_at is not None and \
            now - self._answered_at <= self.config.link_timeout
        round_trip = leader.round_trip.round_trip if leader is not None else None
        values = {'published': self._answers, 'wand_live': wand_live, 'link_live': live,
                  'round_trip_s': math.nan if round_trip is None else round_trip,
                  'clutched': leader is not None and leader.map.clutched,
                  'withheld': self._withheld, 'unanswered': self._unknown,
                  'refused': self._refused.total(),
                  **{f'refused: {kind}': n for kind, n in self._refused.counts.items()}}
        if leader is not None:
            values['operator_energy_out_j'] = leader.passivity.books.energy_out
        if leader is None:
            message = 'waiting for the robot'
        elif not wand_live:
            message = 'the wand is silent: the link is read at its poses'
        else:
            message = (f'link {"live" if live else "silent"}, round trip '
                       f'{1e3 * values["round_trip_s"]:.1f} ms')
        return Report(OK if live and wand_live else WARN, message, values)

    def destroy_node(self) -> bool:
        self.diagnostics.final()
        self._feedback.destroy()
        return super().destroy_node()


def main(args=None) -> int:
    return run_nodes([LeaderNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
