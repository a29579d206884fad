"""The robot's end of the bilateral schemes: command → a safe target, sensor → feedback.

Why: the patient must be safe whatever the link does, so every target the robot gets passes the
patient's safety here (``robot_site.safety``: a bounded spring, hold and retract when the link
is silent), on this site's measurements alone. Per scheme:

- ``direct`` and ``model``: the target is the operator's position;
- ``tdpa``: the target moves at the operator's velocity through the robot's passivity
  controller, which yields along the port's force when the link would otherwise deliver more
  energy than the operator put in, and drifts back toward the operator's position with the
  energy it can spare (``teleop_protocol.tdpa``). The port's force is the one conjugate to the
  commanded motion: the reaction of the robot's impedance spring, K·(x − x_target), which the
  robot's controller knows exactly. It is what the patient pushes with once the probe is at
  rest, but in motion the arm's mass and damping lie between the two, and energy booked with
  the sensor's force instead let the link give energy (30 mJ over the scan at 50 ms, in
  lockstep). So ``tdpa`` feeds that force back; ``direct`` and ``model`` the sensor's.

For ``model``, the contact is learnt online from the sensor and the TCP's motion
(``ContactModelEstimator``) and sent as a plane whose gains are those the command meets: the
tissue in series with the robot's own impedance spring (a target δ deeper presses the patient
by k·K/(k + K)·δ, not k·δ). Out of contact, and before any, the plane is the patient's surface
under the probe as the site sees it (``surface``: a depth camera's, here the phantom's mesh),
with the gains last learnt (the estimator's prior before any contact): without it the first
model would reach the operator a round trip after the touch, with the wand already that far
in (18 mm at 100 ms in the scripted scan), and the hand would first feel the patient there.

Force-hold (``hold_force``, ``robot_site.force_hold``): the target follows the operator along
the surface and presses the set force along the contact's normal, until released.

A sensor reading with NaN is not used: the feedback carries zero force and no plane until a good
reading comes, and the safety goes on with the last good force.

Every command is checked at the door before anything uses it (``teleop.command_refusal``: finite,
in the robot's workspace, at a hand's speed) and admitted (``teleop_protocol.admission``): one
operator session at a time, in order, on time, at a sane rate. A refused command changes
nothing, not even the link's watchdog; ``receive`` says why it was refused.
"""
from dataclasses import dataclass
import math
from typing import Callable

import numpy as np

from haptic_contract.checks import finite_number
from haptic_contract.teleop import (Command, command_refusal, CommandLimits, Feedback, new_session,
                                    RemotePlane, Scheme, SCHEMES)
from robot_site.force_hold import ForceHold, HoldConfig
from robot_site.model_estimation import ContactModelEstimator
from robot_site.safety import PatientSafety
from teleop_protocol.admission import Admission, Refusal
from teleop_protocol.tdpa import RobotPassivity

__all__ = ['Follower', 'FollowerConfig']


@dataclass(frozen=True)
class FollowerConfig:
    """Parameters of the robot's end.

    Parameters
    ----------
    scheme : str
        One of ``SCHEMES``.
    robot_stiffness : float, N/m
        The impedance spring of the robot, for the gains the command meets.
    drift_rate : float, 1/s
        ``tdpa``: how fast the target drifts back toward the operator's position.
    """

    scheme: str = Scheme.MODEL.value
    robot_stiffness: float = 1500.0
    drift_rate: float = 2.0

    def __post_init__(self):
        if self.scheme not in SCHEMES:
            raise ValueError(f'scheme {self.scheme!r} is not one of {list(SCHEMES)}')
        finite_number(self.robot_stiffness, 'robot_stiffness', minimum=0.0, strict=True)
        finite_number(self.drift_rate, 'drift_rate', minimum=0.0)


class Follower:
    """The robot's end of the link.

    Parameters
    ----------
    config : FollowerConfig
    safety : PatientSafety
    limits : CommandLimits
        What a command may ask of this robot.
    estimator : ContactModelEstimator or None
        Needed for ``model``; ignored otherwise.
    surface : callable or None
        ``surface(position) -> (point, outward normal)``: the patient's skin nearest a point,
        for the model out of contact; None: only what contact has taught.
    admission : Admission
        Which commands are taken.
    session : int or None
        This site's session id in its feedback; None: a random one.
    """

    def __init__(self, config: FollowerConfig, safety: PatientSafety, limits: CommandLimits,
                 estimator: ContactModelEstimator | None = None, *,
                 surface: Callable | None = None, admission: Admission | None = None,
                 session: int | None = None) -> None:
        if config.scheme == Scheme.MODEL and estimator is None:
            raise ValueError('the model scheme needs a contact estimator')
        self.config = config
        self.safety = safety
        self.limits = limits
        self.admission = admission if admission is not None else Admission()
        self.session = new_session() if session is None else session
        self._sent = 0  # feedback so far
        self.estimator = estimator if config.scheme == Scheme.MODEL else None
        self.passivity = RobotPassivity(config.drift_rate)
        self._command: Command | None = None
        self._command_heard = -math.inf  # this site's clock when the newest command came
        self._target: np.ndarray | None = None
        self._force = np.zeros(3)  # the last good reading
        self._force_good = True
        self._tcp = np.zeros(3)
        self._plane: RemotePlane | None = None
        self._surface = surface
        self.hold = ForceHold(HoldConfig(), config.robot_stiffness,
                              safety.envelope.working_limit)
        if self.estimator is not None:
            prior = self.estimator.config
            self._gains = self._as_commanded(prior.initial_stiffness, prior.initial_damping)

    def receive(self, now: float, command: Command) -> Refusal | None:
        """Take ``command`` arrived at ``now`` (s); return None, or why it was refused."""
        refusal = (command_refusal(command, self.limits)
                   or self.admission.admit(now, command.session, command.sequence,
                                           command.stamp))
        if refusal is not None:
            return refusal
        self._command, self._command_heard = command, now
        self.safety.heard(now)
        self.passivity.books.receive(command.energy_in)
        return None

    def target(self, now: float, tcp, tcp_velocity, force, dt: float) -> np.ndarray:
        """Return the robot's target position (3,) m for the next ``dt`` s, from its state now.

        ``tcp``, ``tcp_velocity`` (3,) are the TCP's; ``force`` (3,) N the sensor's reading.
        """
        self._tcp = np.asarray(tcp, dtype=np.float64)
        self._force_good = bool(np.all(np.isfinite(force)))
        if self._force_good:
            self._force = np.asarray(force, dtype=np.float64)
            if self.estimator is not None:
                self._learn(now, tcp_velocity)
        if self._target is None:
            self._target = self._tcp.copy()
        goal = self.hold.target(self._goal(dt), self._tcp, self._force, dt)
        self._target = self.safety.safe_target(now, goal, self._tcp, self._force)
        return self._target

    def hold_force(self, force: float | None) -> bool:
        """Hold ``force`` N at the patient (None: the force measured now; <= 0: release).

        Return whether it holds (refused out of contact or past the working limit).
        """
        return self.hold.set(force, self._force)

    def _goal(self, dt: float) -> np.ndarray:
        """Return where the operator's command asks the TCP to be."""
        command = self._command
        if command is None:
            return self._target
        if self.config.scheme != Scheme.TDPA:
            return command.position
        velocity = self.passivity.control(command.velocity, self._port_force(), dt,
                                          command.position - self._target)
        return self._target + velocity * dt

    def _port_force(self) -> np.ndarray:
        """Return the impedance spring's reaction to the commanded target, N (``tdpa``'s port)."""
        if self._target is None:
            return np.zeros(3)  # nothing commanded yet
        return self.config.robot_stiffness * (self._tcp - self._target)

    def _learn(self, now: float, tcp_velocity) -> None:
        normal = None if self._surface is None else lambda: self._surface(self._tcp)[1]
        estimate = self.estimator.update(now, self._force, self._tcp, tcp_velocity, normal)
        if estimate is not None and estimate.stiffness > 0.0:
            self._gains = self._as_commanded(estimate.stiffness, estimate.damping)
            self._plane = RemotePlane(estimate.point, estimate.normal, *self._gains)
        elif self._surface is not None:
            point, normal = self._surface(self._tcp)
            self._plane = RemotePlane(np.asarray(point), np.asarray(normal), *self._gains)

    def _as_commanded(self, stiffness: float, damping: float) -> tuple[float, float]:
        """Return the tissue's gains as a command meets them: in series with the robot's."""
        robot = self.config.robot_stiffness
        share = robot / (stiffness + robot)  # of a target step the tissue takes
        return stiffness * share, damping * share * share

    def feedback(self, now: float) -> Feedback:
        """Return the feedback to send at ``now`` (s)."""
        command = self._command
        echo, hold, echoed = ((0.0, 0.0, 0) if command is None else
                              (command.stamp, now - self._command_heard, command.sequence))
        good = self._force_good
        force = self._port_force() if self.config.scheme == Scheme.TDPA else self._force
        self._sent += 1
        return Feedback(now, echo, hold, force if good else np.zeros(3), self._tcp,
                        self.passivity.books.energy_in, self._plane if good else None,
                        self.session, self._sent, echoed, good)
