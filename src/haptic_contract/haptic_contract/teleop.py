"""What crosses the link between the two sites, as plain values (the messages' content).

``Command`` goes from the operator to the robot with every wand pose; ``Feedback`` comes back.
Both are in the robot's base frame and SI units; the ROS nodes read them from and write them to
``haptic_msgs/TeleopCommand`` and ``TeleopFeedback`` (``teleop_fields``).

What arrives is checked at the door (``command_refusal``, ``feedback_refusal``) before anything
uses it: finite, and within what the physics allows. A number far outside that is not a fast
operator or a hard press but a broken or hostile peer, and one absurd value (a speed of 1e308
m/s) used once poisons every energy book after it.
"""
import enum
import math
import secrets
from typing import NamedTuple

import numpy as np

from haptic_contract.checks import within_box

__all__ = ['Command', 'CommandLimits', 'Feedback', 'HAND_SPEED', 'Refusal', 'RemotePlane',
           'SCHEMES', 'Scheme', 'command_refusal', 'feedback_refusal', 'new_session']


class Scheme(enum.StrEnum):
    """The bilateral schemes, by the names a parameter and the command line give them.

    Direct force reflection (the baseline), time-domain passivity on both ports (Artigas et al.
    2011), and model-mediated teleoperation (the device renders the remote site's estimate of
    the contact).
    """

    DIRECT = 'direct'
    TDPA = 'tdpa'
    MODEL = 'model'


SCHEMES = tuple(scheme.value for scheme in Scheme)  # the names, as plain strings

HAND_SPEED = 5.0  # [m/s] no hand moves a wand faster (fast jabs reach 1-2 m/s)
MAX_FEEDBACK_FORCE = 500.0  # [N] beyond the range of any F/T sensor that holds a probe
MAX_FEEDBACK_REACH = 10.0  # [m] a TCP or contact point farther from the robot's base
MAX_PLANE_STIFFNESS = 1e6  # [N/m] stiffer than bone under a probe
MAX_PLANE_DAMPING = 1e4  # [N·s/m]
MAX_ECHO_HOLD = 60.0  # [s] a command held longer than this at the robot is no echo
UNIT_TOLERANCE = 1e-6  # how far from unit length a normal may be


class Refusal(NamedTuple):
    """Why a message was not taken: ``kind`` a short fixed text (counted), ``detail`` its case."""

    kind: str
    detail: str = ''


def new_session() -> int:
    """Return a session id: 63 random bits, never 0 (which says "none")."""
    return secrets.randbits(63) | 1


class Command(NamedTuple):
    """The operator's command: a target for the probe's TCP.

    Attributes
    ----------
    stamp : float, s
        The wand pose's stamp, on the operator's clock.
    position : (3,) float, m
    velocity : (3,) float, m/s
    energy_in : float, J
        Energy into the link at the operator's port so far.
    session, sequence : int
        The operator's session, and the command's number in it (from 1).
    """

    stamp: float
    position: np.ndarray
    velocity: np.ndarray
    energy_in: float
    session: int = 0
    sequence: int = 0


class RemotePlane(NamedTuple):
    """The contact as the robot's site estimates it: a plane, and gains seen from the command."""

    point: np.ndarray
    normal: np.ndarray
    stiffness: float
    damping: float


class Feedback(NamedTuple):
    """The robot's answer.

    Attributes
    ----------
    stamp : float, s
        When it was sent, on the robot site's clock.
    echo : float, s
        The newest command's stamp heard there (the operator's clock); 0 before any.
    echo_hold : float, s
        From receiving that command to sending this.
    force : (3,) float, N
        The patient's force on the probe, as measured (zero while the sensor is faulty).
    tcp : (3,) float, m
    energy_in : float, J
        Energy into the link at the robot's port so far.
    plane : RemotePlane or None
        The latest contact estimate; None before any contact.
    session, sequence : int
        The remote site's session, and the feedback's number in it (from 1).
    echo_sequence : int
        The echoed command's sequence; 0 before any.
    measured : bool
        Whether the sensor read the force well: if not, the force is zero and the plane None,
        and neither says the contact ended (a stale or faulty reading in a starved site).
    """

    stamp: float
    echo: float
    echo_hold: float
    force: np.ndarray
    tcp: np.ndarray
    energy_in: float
    plane: RemotePlane | None
    session: int = 0
    sequence: int = 0
    echo_sequence: int = 0
    measured: bool = True


class CommandLimits(NamedTuple):
    """What a command may ask of the robot: its workspace box (m) and a speed (m/s).

    The speed bounds the operator's hand, not the robot: the robot moves no faster than it can
    whatever it is asked, but a hand never moves a wand at 1e308 m/s, and ``tdpa`` integrates it.
    """

    workspace_lower: np.ndarray
    workspace_upper: np.ndarray
    max_speed: float


def command_refusal(command: Command, limits: CommandLimits) -> Refusal | None:
    """Return why ``command`` must not be used, or None if it is within ``limits``."""
    values = (command.stamp, *command.position, *command.velocity, command.energy_in)
    if not all(map(math.isfinite, values)):
        return Refusal('not finite', _numbers(values))
    if not within_box(command.position, limits.workspace_lower, limits.workspace_upper):
        return Refusal('outside the workspace', _numbers(command.position))
    speed = math.hypot(*command.velocity)
    if speed > limits.max_speed:
        return Refusal('faster than a hand', f'{speed:.3g} m/s')
    if command.energy_in < 0.0:
        return Refusal('negative energy', f'{command.energy_in:.3g} J')
    return None


def feedback_refusal(feedback: Feedback) -> Refusal | None:
    """Return why ``feedback`` must not be used, or None if it is physically plausible."""
    plane = feedback.plane
    values = (feedback.stamp, feedback.echo, feedback.echo_hold, *feedback.force, *feedback.tcp,
              feedback.energy_in,
              *(() if plane is None else (*plane.point, *plane.normal, plane.stiffness,
                                          plane.damping)))
    if not all(map(math.isfinite, values)):
        return Refusal('not finite', _numbers(values))
    if _length(feedback.force) > MAX_FEEDBACK_FORCE:
        return Refusal('force beyond any sensor', _numbers(feedback.force))
    if _length(feedback.tcp) > MAX_FEEDBACK_REACH:
        return Refusal('TCP out of reach', _numbers(feedback.tcp))
    if feedback.energy_in < 0.0:
        return Refusal('negative energy', f'{feedback.energy_in:.3g} J')
    if not 0.0 <= feedback.echo_hold <= MAX_ECHO_HOLD:
        return Refusal('echo held impossibly long', f'{feedback.echo_hold:.3g} s')
    if plane is not None:
        if abs(_length(plane.normal) - 1.0) > UNIT_TOLERANCE:
            return Refusal('plane normal not unit', _numbers(plane.normal))
        if _length(plane.point) > MAX_FEEDBACK_REACH:
            return Refusal('plane out of reach', _numbers(plane.point))
        if not (0.0 <= plane.stiffness <= MAX_PLANE_STIFFNESS
                and 0.0 <= plane.damping <= MAX_PLANE_DAMPING):
            return Refusal('plane gains out of range',
                           f'{plane.stiffness:.3g} N/m, {plane.damping:.3g} N·s/m')
    return None


def _length(vector) -> float:
    return math.hypot(*vector)


def _numbers(values) -> str:
    return ', '.join(f'{float(v):.6g}' for v in values)
