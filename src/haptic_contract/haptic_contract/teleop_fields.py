"""The link's messages as the CDR codec's flat tuples, and back, each field found by its name.

Why one module: what crosses between the two sites (``haptic_msgs/TeleopCommand``,
``TeleopFeedback``) and what the robot says of itself (``RobotImpedance``) is read and written
here only, with every field looked up by its name in the message definition, so that a field
added to a message moves no literal index anywhere. The values are those of
``haptic_contract.teleop``; what they may hold is checked there.
"""
from typing import NamedTuple

import numpy as np

from haptic_contract.fields import span
from haptic_contract.teleop import Command, CommandLimits, Feedback, RemotePlane
from haptic_msgs.msg import RobotImpedance, TeleopCommand, TeleopFeedback
from haptic_util.cdr import MessageCodec

__all__ = ['COMMAND', 'FEEDBACK', 'RobotReport', 'command_fields', 'command_from_fields',
           'command_session',
           'feedback_fields', 'feedback_from_fields', 'impedance_message', 'impedance_report']

COMMAND = MessageCodec(TeleopCommand)
FEEDBACK = MessageCodec(TeleopFeedback)
_SECOND = 1_000_000_000
_FRAME = COMMAND.index('header.frame_id')  # the same in every stamped message here
_COMMAND_IDS = span(COMMAND, 'session', 'sequence')
_COMMAND_NUMBERS = span(COMMAND, 'position.x', 'energy_in')
_FEEDBACK_IDS = span(FEEDBACK, 'session', 'sequence')
_FEEDBACK_ECHO = span(FEEDBACK, 'echo.sec', 'echo_sequence')
_FEEDBACK_NUMBERS = span(FEEDBACK, 'echo_hold', 'energy_in')
_FEEDBACK_KIND = FEEDBACK.index('kind')
_FEEDBACK_PLANE = span(FEEDBACK, 'plane.point.x', 'plane.tool_point.z')
_PLANE = {name: FEEDBACK.index(f'plane.{name}') - _FEEDBACK_PLANE.start
          for name in ('point.x', 'normal.x', 'stiffness.x', 'damping.x')}
_NO_PLANE = (0.0,) * (_FEEDBACK_PLANE.stop - _FEEDBACK_PLANE.start)


def _stamp(fields, first: int = 0) -> float:
    return fields[first] + fields[first + 1] * 1e-9


def _time(stamp: float) -> tuple:
    return divmod(round(stamp * 1e9), _SECOND)


def _header(stamp: float, frame: str) -> tuple:
    return (*_time(stamp), frame)


def command_session(fields) -> int:
    """Return the session of a TeleopCommand's fields, before anything else is read of it."""
    return fields[_COMMAND_IDS.start]


def command_from_fields(fields) -> tuple[str, Command]:
    """Return the frame and the ``Command`` of a TeleopCommand's fields."""
    numbers = np.array(fields[_COMMAND_NUMBERS], dtype=np.float64)
    return fields[_FRAME], Command(_stamp(fields), numbers[0:3], numbers[3:6], float(numbers[6]),
                                   *fields[_COMMAND_IDS])


def command_fields(command: Command, frame: str) -> tuple:
    """Return the TeleopCommand fields of ``command`` in ``frame``."""
    return (*_header(command.stamp, frame), command.session, command.sequence,
            *command.position.tolist(), *command.velocity.tolist(), command.energy_in)


def feedback_from_fields(fields) -> tuple[str, Feedback]:
    """Return the frame and the ``Feedback`` of a TeleopFeedback's fields."""
    numbers = np.array(fields[_FEEDBACK_NUMBERS], dtype=np.float64)
    plane = None
    if fields[_FEEDBACK_KIND] == TeleopFeedback.KIND_PLANE:
        values = np.array(fields[_FEEDBACK_PLANE], dtype=np.float64)
        point, normal = _PLANE['point.x'], _PLANE['normal.x']
        plane = RemotePlane(values[point:point + 3], values[normal:normal + 3],
                            float(values[_PLANE['stiffness.x']]),
                            float(values[_PLANE['damping.x']]))
    echo = fields[_FEEDBACK_ECHO]
    return fields[_FRAME], Feedback(_stamp(fields), _stamp(echo), float(numbers[0]),
                                    numbers[1:4], numbers[4:7], float(numbers[7]), plane,
                                    *fields[_FEEDBACK_IDS], echo[2],
                                    fields[_FEEDBACK_KIND] != TeleopFeedback.KIND_UNKNOWN)


def feedback_fields(feedback: Feedback, frame: str) -> tuple:
    """Return the TeleopFeedback fields of ``feedback`` in ``frame``."""
    plane = feedback.plane
    kind = (TeleopFeedback.KIND_UNKNOWN if not feedback.measured else
            TeleopFeedback.KIND_FREE if plane is None else TeleopFeedback.KIND_PLANE)
    plane_fields = _NO_PLANE if plane is None else (
        *plane.point.tolist(), *plane.normal.tolist(), *[plane.stiffness] * 3,
        *[plane.damping] * 3, 0.0, 0.0, 0.0)
    return (*_header(feedback.stamp, frame), feedback.session, feedback.sequence,
            *_time(feedback.echo), feedback.echo_sequence, feedback.echo_hold,
            *feedback.force.tolist(), *feedback.tcp.tolist(), feedback.energy_in, kind,
            *plane_fields)


class RobotReport(NamedTuple):
    """What a robot says of itself (``RobotImpedance``).

    Its spring (N/m), its force bound (N), what a command may ask of it, and its TCP's top
    speed (m/s).
    """

    stiffness: float
    max_patient_force: float
    limits: CommandLimits
    max_speed: float


def impedance_report(message: RobotImpedance, hand_speed: float) -> tuple[str, RobotReport]:
    """Return the frame and the ``RobotReport`` of a RobotImpedance message.

    ``hand_speed`` (m/s) bounds the commands' speed, beside the robot's workspace.
    """
    lower, upper = message.workspace_lower, message.workspace_upper
    limits = CommandLimits(np.array([lower.x, lower.y, lower.z]),
                           np.array([upper.x, upper.y, upper.z]), hand_speed)
    return message.header.frame_id, RobotReport(message.stiffness, message.max_patient_force,
                                                limits, message.max_speed)


def impedance_message(frame: str, *, stiffness: float, max_speed: float, workspace_lower,
                      workspace_upper, max_patient_force: float) -> RobotImpedance:
    """Return the RobotImpedance message of a robot with these properties."""
    message = RobotImpedance(stiffness=float(stiffness), max_speed=float(max_speed),
                             max_patient_force=float(max_patient_force))
    message.header.frame_id = frame
    message.workspace_lower.x, message.workspace_lower.y, message.workspace_lower.z = \
        map(float, workspace_lower)
    message.workspace_upper.x, message.workspace_upper.y, message.workspace_upper.z = \
        map(float, workspace_upper)
    return message
