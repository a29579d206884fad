"""The operator's end of the bilateral schemes: wand → command, feedback → what the hand feels.

Why: the operator's site must stay safe and stable whatever the link does. The leader answers
every wand pose at once from the newest feedback it holds, never waiting on the link:

- ``direct``: the patient's force, scaled, as the wand's force (the baseline; with delay, the
  force acts on an old motion and gives energy back);
- ``tdpa``: the same force through the operator's passivity controller, which books the energy
  at this port against what the robot's port has sent into the link (``teleop_protocol.tdpa``),
  and reaches the wand through a virtual coupling that keeps the controller's switching off the
  hand (``teleop_leader.virtual_coupling``);
- ``model``: the remote site's estimated plane, mapped into the wand's workspace with the
  scaled gains, for the device to render at its own servo rate. Model updates are kept
  passive: an update that would store more energy in the wand's spring (the wand deeper in a
  stiffer one) is paid from a reserve, which holds what earlier updates took out (an estimate
  that moved out, a softer one); what the reserve cannot pay, the plane is shown moved out
  along its normal instead, and the robot's target with it. The first contact is where that
  matters: the estimate arrives a round trip after the robot touched, with the wand already
  that far in, and shown as it is it would throw the hand out (in lockstep at 250 ms: 45 mJ
  given, 18 N on the patient). Moving the robot's target out by the same shift keeps the
  patient pressed as the hand feels it; the shift is a position offset between the wand and
  the probe, the price of passivity (as TDPA's drift is), paid back as soon as the reserve
  allows. A reserve rather than a ratchet: refusing every rise while keeping every fall, the
  estimate's noise alone drove the shift out to tens of millimetres.

A silence keeps the books: what the shown spring held when it began stays in the reserve, so the
first model after it comes back storing no more than that, wherever the hand sank meanwhile: the
hand feels the force it left, and the robot's target, moved out by the same shift, presses the
patient as much. The device's port keeps the same books through the lapse (``port_passivity``), so
the two agree; a give-back of the shift beyond that energy would move the robot in while the port
held the hand's force where it was (in lockstep, a 1 s outage mid-press then left 4.4 N felt,
scaled, against 17 N at the patient). The clutch, or a free estimate, closes the books instead: the
device renders those as free, and its port closes its own books after a moment of zero force.
The device also moves the planes itself (its easing; after a lapse, the push the hand left,
where the hand sank), and says how far (``device_shift``): the robot's target takes that too.
Only the device knows of a lapse this end never saw, its tick stalled between a pose and its
answer (in lockstep, the robot then pressed 11.2 N where the hand felt 6.2 N, scaled).

Feedback older than ``link_timeout`` (on this site's clock: the sites share none) gives zero
force and no model, and no command is sent while it lasts: the robot then holds, as it does when
its commands stop, rather than follow an operator who feels nothing. Feedback is checked and
admitted at the door as the robot's end does with commands (``teleop.feedback_refusal``,
``teleop_protocol.admission``), and its echo must be of a command this end sent. The link's round
trip is measured from those echoes, as NTP does (``RoundTripEstimator``).
"""
from collections import OrderedDict
from dataclasses import dataclass
import math

import numpy as np

from haptic_contract.checks import finite_number
from haptic_contract.teleop import (Command, Feedback, feedback_refusal, new_session, RemotePlane,
                                    Scheme, SCHEMES)
from teleop_leader.virtual_coupling import CouplingConfig, VirtualCoupling
from teleop_leader.workspace_map import WorkspaceMap
from teleop_protocol.admission import Admission, Refusal
from teleop_protocol.round_trip import RoundTripEstimator
from teleop_protocol.tdpa import OperatorPassivity

__all__ = ['Leader', 'LeaderConfig']

_STAMP_ROUNDING = 1e-6  # [s] a stamp through the message's integer seconds and nanoseconds
_NO_SHIFT = np.zeros(3)


@dataclass(frozen=True)
class LeaderConfig:
    """Parameters of the operator's end.

    Parameters
    ----------
    scheme : str
        One of ``SCHEMES``.
    force_scale : float
        Felt force per patient force.
    position_scale : float
        Robot motion per wand motion.
    link_timeout : float, s
        Feedback older than this (since it arrived) is not rendered.
    coupling : CouplingConfig or None
        ``tdpa``: between the link's port and the wand. None: the controller acts on the wand
        itself, as plain TDPA does (the baseline the coupling improves on: it chatters).
    """

    scheme: str = Scheme.MODEL.value
    force_scale: float = 0.3
    position_scale: float = 1.0
    link_timeout: float = 0.1
    coupling: CouplingConfig | None = CouplingConfig()

    def __post_init__(self):
        if self.scheme not in SCHEMES:
            raise ValueError(f'scheme {self.scheme!r} is not one of {list(SCHEMES)}')
        finite_number(self.link_timeout, 'link_timeout', minimum=0.0, strict=True)


class Leader:
    """The operator's end of the link.

    Parameters
    ----------
    config : LeaderConfig
    wand_start, robot_start : (3,) float, m
        Where the wand and the probe are when the session starts (the first anchors).
    admission : Admission
        Which feedback is taken.
    session : int or None
        This operator's session id in its commands; None: a random one.
    """

    SENT_KEPT = 8192  # commands whose stamps an echo may name: 8 s at 1 kHz

    def __init__(self, config: LeaderConfig, wand_start, robot_start, *,
                 admission: Admission | None = None, session: int | None = None) -> None:
        self.config = config
        self.admission = admission if admission is not None else Admission()
        self.session = new_session() if session is None else session
        self._sent = OrderedDict()  # sequence -> stamp of the latest commands
        self.map = WorkspaceMap(config.position_scale, config.force_scale, wand_start,
                                robot_start)
        self.passivity = OperatorPassivity()
        self.round_trip = RoundTripEstimator()
        self._feedback: Feedback | None = None
        self._heard = -math.inf  # this site's clock when the newest feedback came
        self._shown: RemotePlane | None = None  # the plane last shown, shift included
        self._shift = np.zeros(3)  # [m] wand frame: how far it is shown out from the estimate
        self._reserve = 0.0  # [J] energy model updates took out of the wand's spring, net
        self._coupling: VirtualCoupling | None = None  # tdpa, while the link is live

    def receive(self, now: float, feedback: Feedback) -> Refusal | None:
        """Take ``feedback`` arrived at ``now`` (s); return None, or why it was refused."""
        refusal = (feedback_refusal(feedback) or self._echo_refusal(now, feedback)
                   or self.admission.admit(now, feedback.session, feedback.sequence,
                                           feedback.stamp))
        if refusal is not None:
            return refusal
        self._feedback, self._heard = feedback, now
        self.passivity.books.receive(feedback.energy_in)
        if feedback.echo_sequence:
            replied = feedback.stamp
            self.round_trip.add(feedback.echo, replied - feedback.echo_hold, replied, now)
        return None

    def _echo_refusal(self, now: float, feedback: Feedback) -> Refusal | None:
        """Why ``feedback``'s echo cannot be of a command sent here, if it cannot."""
        if not feedback.echo_sequence:
            return None  # the far end has heard no command yet
        sent = self._sent.get(feedback.echo_sequence)
        if sent is None or abs(sent - feedback.echo) > _STAMP_ROUNDING:
            return Refusal('echo of no command sent here', f'sequence '
                           f'{feedback.echo_sequence} stamped {feedback.echo:.6f} s')
        if now - sent < feedback.echo_hold:
            return Refusal('echo held longer than its round trip',
                           f'{feedback.echo_hold:.3f} s in {now - sent:.3f} s')
        return None

    def live(self, now: float) -> bool:
        """Whether feedback came within ``link_timeout`` before ``now``."""
        return now - self._heard <= self.config.link_timeout

    def heard(self, now: float) -> bool:
        """Whether the feedback is live and says what the probe touches: its force was read.

        Unread (a stale or faulty sensor in a starved remote site) it is a silence: zero force, no
        command, no model, and the books kept. Taken for a free estimate, it closed them, and the
        hand that sank meanwhile (60 mm through a flood) lost the patient for good.
        """
        return self.live(now) and self._feedback.measured

    def command(self, stamp: float, wand, wand_velocity,
                device_shift=_NO_SHIFT) -> Command | None:
        """Return the command for the wand's pose stamped ``stamp`` (s, this site's clock).

        ``device_shift`` (3,) m: how far out of the planes sent the device renders them (its
        easing, its port's bound after a lapse), which the robot's target takes too. None while
        the feedback is silent: the robot holds rather than follow an operator who feels nothing.
        """
        if not self.heard(stamp):
            return None
        target = self.map.to_robot(wand) + self.map.position_scale * (self._shift + device_shift)
        sequence = next(reversed(self._sent), 0) + 1
        self._sent[sequence] = stamp
        if len(self._sent) > self.SENT_KEPT:
            self._sent.popitem(last=False)
        return Command(stamp, target, self.map.velocity_to_robot(wand_velocity),
                       self.passivity.books.energy_in, self.session, sequence)

    def force(self, now: float, wand, wand_velocity, dt: float) -> np.ndarray:
        """Return what the wand at ``wand`` (3,) m should push with over the next ``dt`` s, N.

        Not for ``model``. Zero while the link is silent or the clutch is engaged: for ``tdpa``
        the coupling is then let go, and starts again at rest where the wand is.
        """
        if not self.heard(now) or self.map.clutched:
            self._coupling = None
            return np.zeros(3)
        patient = self._feedback.force
        if self.config.scheme != Scheme.TDPA:
            return self.config.force_scale * patient
        if self.config.coupling is None:
            return self.config.force_scale * self.passivity.control(
                patient, self.map.velocity_to_robot(wand_velocity), dt)
        if self._coupling is None:
            self._coupling = VirtualCoupling(self.config.coupling, wand)
        count, step = self._coupling.steps(dt)
        for _ in range(count):  # the controller books each step's work on the mass
            port = self.passivity.control(
                patient, self.map.velocity_to_robot(self._coupling.velocity), step)
            felt = self._coupling.step(self.config.force_scale * port, wand, wand_velocity, step)
        return felt

    def plane(self, now: float, wand) -> RemotePlane | None:
        """Return the contact plane to show the wand at ``wand`` (3,) m (``model``); None: free.

        In the wand's frame, with the felt gains, moved out as far as a passive update needs.
        None too while the link is silent or the clutch is engaged.
        """
        if not self.heard(now) or self.map.clutched or self._feedback.plane is None:
            if not self.heard(now):  # the spring lapses: its energy stays booked
                self._reserve += 0.0 if self._shown is None else _stored(self._shown, wand)
            else:  # rendered free: the books close
                self._reserve = 0.0
            self._shown, self._shift = None, np.zeros(3)
            return None
        remote = self._feedback.plane
        stiffness = self.map.felt_gain(remote.stiffness)
        point = self.map.to_wand(remote.point)
        held = 0.0 if self._shown is None else _stored(self._shown, wand)
        affordable = held + self._reserve  # [J] the most the new spring may hold
        depth = _depth(point, remote.normal, wand)
        allowed = (math.sqrt(2.0 * max(affordable, 0.0) / stiffness) if stiffness > 0.0
                   else math.inf)
        shift = max(depth - allowed, 0.0)  # [m] the least a passive update is shown moved out
        self._shift = shift * remote.normal
        self._shown = RemotePlane(point - self._shift, remote.normal, stiffness,
                                  self.map.felt_gain(remote.damping))
        self._reserve = max(affordable - _stored(self._shown, wand), 0.0)
        return self._shown

    def model(self, now: float, wand) -> tuple[bool, RemotePlane | None]:
        """Return whether the leader knows what the wand touches, and the plane to show it.

        Unknown while the feedback is silent: then no model goes out, so the device's last one
        lapses to zero force and its port keeps the books of the contact the silence
        interrupted, which a free model would close.
        """
        plane = self.plane(now, wand)
        return plane is not None or self.heard(now), plane


def _stored(plane: RemotePlane, wand) -> float:
    """Energy (J) in ``plane``'s spring with the wand at ``wand``."""
    return 0.5 * plane.stiffness * max(_depth(plane.point, plane.normal, wand), 0.0) ** 2


def _depth(point, normal, wand) -> float:
    """How far (m) ``wand`` lies behind the plane through ``point`` with outward ``normal``."""
    return float(np.dot(np.asarray(point) - wand, normal))
