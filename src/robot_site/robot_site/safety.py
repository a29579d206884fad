"""Safety at the patient: a bounded pressing force, and a robot that lets go when the link fails.

Why: the operator is far away, behind a link that delays, drops and may go silent, so the limits
that protect the patient must hold at the robot's side, on its own measurements, whatever arrives.

- **Force bound.** An impedance-controlled robot presses with its spring, K·(x_t − x). Keeping
  the target within ``max_patient_force`` / K of the TCP bounds that spring in every direction,
  so no target, however deep, can press harder; it needs no model of the patient, whose
  stiffness the robot does not know. The force along the surface (a sweep's drag) is bounded
  with it, and ``force_margin`` keeps the spring that much below the limit.
  The bound is exact at rest. In motion, the robot's momentum adds an impact force of about
  v·sqrt(k·m) on a surface of stiffness k: nothing on soft, damped tissue (the abdomen peaks at
  the bound), tens of newtons on a stiff one (20 kN/m at 0.18 m/s), which this bound does not
  cover; a speed limit near contact would.
- **Link watchdog.** When nothing has come from the operator for longer than ``link_timeout``
  (never heard counts as silent), the robot stops following the operator: it holds the TCP where
  it is, not the last target (which lies up to the force bound's reach further in, and pressed
  on: 12.8 N became 16.5 N over a 0.5 s stall), so its spring lets go at once and the tissue
  pushes the probe back; and it draws that hold back along the measured force's direction (out
  of the patient, as the tissue pushes) at ``retract_speed`` while the measured force is above
  ``release_force``.
- **Rejoining.** When messages come again, the target goes from where the robot held to the
  operator's at ``rejoin_speed``, not in one step: the robot and the operator meet again without
  a jump, however far apart the silence left them.
- **The clinical envelope** (``robot_site.force_envelope``): in contact the spring rises at a
  bounded rate and under a ramp after the first touch; a measured force at the hard stop holds
  and retracts the robot as a silence does, until the operator re-engages (``re_engage``).
"""

from dataclasses import dataclass
import math

import numpy as np

from haptic_contract.checks import finite_number, finite_vector
from robot_site.force_envelope import EnvelopeConfig, ForceEnvelope, toward_within

__all__ = ['LinkWatchdog', 'PatientSafety', 'SafetyConfig', 'within_force_bound']


@dataclass(frozen=True)
class SafetyConfig:
    """Parameters of the patient-side safety.

    Parameters
    ----------
    robot_stiffness : float, N/m
        The impedance spring of the robot (``ImpedanceRobotConfig.stiffness``).
    max_patient_force : float, N
        The force the patient may feel at most.
    force_margin : float, N
        How far below ``max_patient_force`` the spring stays, for what the bound does not see
        (a stiffer spot, the robot's momentum).
    link_timeout : float, s
        Silence after which the robot holds and retracts.
    release_force : float, N
        The retraction stops once the measured force is below this.
    retract_speed : float, m/s
    rejoin_speed : float, m/s
        How fast the target goes back to the operator's once the link is heard again.
    envelope : EnvelopeConfig
        The hard stop, the rate of rise and the ramp at first contact.
    """

    robot_stiffness: float
    max_patient_force: float = 20.0
    force_margin: float = 1.0
    link_timeout: float = 0.1
    release_force: float = 1.0
    retract_speed: float = 0.02
    rejoin_speed: float = 0.05
    envelope: EnvelopeConfig = EnvelopeConfig()

    def __post_init__(self):
        for name in ('robot_stiffness', 'max_patient_force', 'link_timeout', 'retract_speed',
                     'rejoin_speed'):
            finite_number(getattr(self, name), f'SafetyConfig.{name}', minimum=0.0, strict=True)
        finite_number(self.force_margin, 'SafetyConfig.force_margin', minimum=0.0,
                      maximum=self.max_patient_force)
        finite_number(self.release_force, 'SafetyConfig.release_force', minimum=0.0,
                      maximum=self.max_patient_force)

    @property
    def spring_reach(self) -> float:
        """How far (m) the target may lie from the TCP: (max force − margin) / stiffness."""
        return (self.max_patient_force - self.force_margin) / self.robot_stiffness


def within_force_bound(target: np.ndarray, tcp: np.ndarray, reach: float) -> np.ndarray:
    """Return ``target`` (3,) m moved toward ``tcp`` (3,) m until it is within ``reach`` m."""
    offset = target - tcp
    length = float(np.linalg.norm(offset))
    if length <= reach:
        return target
    return tcp + offset * (reach / length)


class LinkWatchdog:
    """Whether the link has been silent for longer than ``timeout`` seconds."""

    def __init__(self, timeout: float) -> None:
        self.timeout = finite_number(timeout, 'LinkWatchdog.timeout', minimum=0.0, strict=True)
        self._last_heard = -math.inf

    def heard(self, time: float) -> None:
        """Note a message received at ``time`` s (a stale one does not move the time back)."""
        time = finite_number(time, 'LinkWatchdog.heard time')
        self._last_heard = max(self._last_heard, time)

    @property
    def heard_any(self) -> bool:
        """Whether anything was ever heard."""
        return self._last_heard > -math.inf

    def silent(self, now: float) -> bool:
        """Whether nothing was heard in the ``timeout`` before ``now`` s (or ever)."""
        return now - self._last_heard > self.timeout


class PatientSafety:
    """Turns the operator's target into one that is safe for the patient, at every control tick.

    Parameters
    ----------
    config : SafetyConfig
    """

    def __init__(self, config: SafetyConfig) -> None:
        self.config = config
        self.watchdog = LinkWatchdog(config.link_timeout)
        self._hold: np.ndarray | None = None  # the held target while the link is silent
        self._rejoin: np.ndarray | None = None  # the target on its way back to the operator's
        self._last_tick: float | None = None
        self.envelope = ForceEnvelope(config.envelope,
                                      config.max_patient_force - config.force_margin)
        self._measured = math.inf  # [N] the last force measured
        self._target: np.ndarray | None = None  # the last target commanded

    @property
    def holding(self) -> bool:
        """True while the robot holds (and retracts): the link is silent, or it stopped."""
        return self._hold is not None

    def re_engage(self) -> bool:
        """Follow the operator again after a hard stop, once the probe has let go.

        Return whether it follows (False while the measured force is above the contact's).
        """
        return self.envelope.re_engage(self._measured)

    def heard(self, time: float) -> None:
        """Note a message from the operator received at ``time`` s."""
        self.watchdog.heard(time)

    def safe_target(self, now: float, target, tcp, measured_force) -> np.ndarray:
        """Return the target (3,) m to command now.

        Parameters
        ----------
        now : float, s
        target : (3,) float, m
            The operator's latest target.
        tcp : (3,) float, m
            The TCP's position now.
        measured_force : (3,) float, N
            The F/T sensor's force on the probe (pointing out of the patient).
        """
        now = finite_number(now, 'PatientSafety.safe_target now')
        target = finite_vector(target, 3, 'PatientSafety.safe_target target')
        tcp = finite_vector(tcp, 3, 'PatientSafety.safe_target tcp')
        measured_force = finite_vector(measured_force, 3, 'PatientSafety.safe_target force')
        elapsed = 0.0 if self._last_tick is None else max(now - self._last_tick, 0.0)
        self._last_tick = now
        self._measured = float(np.linalg.norm(measured_force))
        stopped = self.envelope.trip(self._measured)
        if stopped or self.watchdog.silent(now):
            self._hold = tcp if self._hold is None else self._hold
            self._hold = target = self._retracted(self._hold, measured_force, elapsed)
            if self.watchdog.heard_any or stopped:  # not the start: rejoin from here
                self._rejoin = self._hold
        else:
            self._hold = None
            if self._rejoin is not None:
                # From the target last commanded: the envelope may have held it short.
                self._rejoin = _toward(self._target if self._target is not None
                                       else self._rejoin, target,
                                       self.config.rejoin_speed * elapsed)
                target = target if self._rejoin is None else self._rejoin
        target = within_force_bound(target, tcp, self.config.spring_reach)
        reach = self.envelope.allowed(now, elapsed, self._measured) / self.config.robot_stiffness
        previous = tcp if self._target is None else self._target
        self._target = target = toward_within(previous, target, tcp, reach)
        self.envelope.commanded(self.config.robot_stiffness * float(np.linalg.norm(target - tcp)))
        return target

    def _retracted(self, hold: np.ndarray, measured_force: np.ndarray,
                   elapsed: float) -> np.ndarray:
        """Move ``hold`` out along the force while the force is above the release threshold."""
        magnitude = float(np.linalg.norm(measured_force))
        if magnitude <= self.config.release_force:
            return hold
        return hold + measured_force * (self.config.retract_speed * elapsed / magnitude)


def _toward(start: np.ndarray, goal: np.ndarray, step: float) -> np.ndarray | None:
    """Return ``start`` moved ``step`` m toward ``goal``; None once it is there."""
    offset = goal - start
    length = float(np.linalg.norm(offset))
    if length <= step:
        return None
    return start + offset * (step / length)
