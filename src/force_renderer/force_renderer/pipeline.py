"""One servo step of force rendering: watchdog, law, passivity, saturation, in that order.

The node calls `ForcePipeline.step` once per servo tick with its latest collision state, so the
node stays a thin shell: everything that decides the force lives here, pure and testable.
"""

from dataclasses import dataclass
import math

import numpy as np

from force_renderer.contact import Contact, STATUS_INVALID_INPUT, STATUS_NO_OBJECT
from force_renderer.errors import non_negative, positive
from force_renderer.passivity import PassivityController
from force_renderer.spring_damper import ForceLaw
from force_renderer.velocity import VelocityEstimator
from force_renderer.watchdog import Reason, Watchdog
from haptic_contract.checks import floats3
from haptic_contract.plane_law import saturate_components

__all__ = ['ForcePipeline', 'PipelineConfig']

_ZERO = (0.0, 0.0, 0.0)
_UNANSWERED = {STATUS_NO_OBJECT: Reason.NO_OBJECT, STATUS_INVALID_INPUT: Reason.REFUSED}


@dataclass(frozen=True)
class PipelineConfig:
    """Settings of the pipeline, as the node reads them from its parameters (SI units).

    Attributes
    ----------
    force_limit : float, N
        The device's largest force magnitude; every output is saturated to it.
    passivity : bool
        Run the passivity observer and controller (on by default; off only to compare).
    max_damping : float, N·s/m
        Largest damping the passivity controller may add (below the device's m/T).
    servo_period : float, s
        Nominal servo period.
    timeout : float, s
        Input older than this sends the force to zero.
    max_lead : float, s
        Input stamped further ahead of `now` than this sends the force to zero.
    velocity_window : float, s
        Window of the velocity estimate used when no twist is given.
    """

    force_limit: float = 10.0
    passivity: bool = True
    max_damping: float = 100.0
    servo_period: float = 0.001
    timeout: float = 0.010
    max_lead: float = 0.010
    velocity_window: float = 0.005

    def __post_init__(self) -> None:
        non_negative(self.force_limit, 'PipelineConfig.force_limit')
        non_negative(self.max_damping, 'PipelineConfig.max_damping')
        for name in ('servo_period', 'timeout', 'max_lead', 'velocity_window'):
            positive(getattr(self, name), f'PipelineConfig.{name}')


class ForcePipeline:
    """Force on the tip from the latest collision state, safe to send to the device.

    Parameters
    ----------
    law : ForceLaw
        The rendering law (`SpringDamper`, `GodObjectProxy`, ...).
    config : PipelineConfig
        Limits, timeouts and the passivity switch.

    Attributes
    ----------
    last_reason : Reason
        Why the last force is what it is (anything but OK means it was zeroed).
    last_stamp : float, s
        Stamp of the state the last force answers (NaN when there was none), for the wrench.
    last_torque : (3,) float, N·m
        Torque about the tip that goes with the last force (a tool's face, ``probe``): the
        law's, scaled as the saturation scaled its force, zero whenever the force was zeroed.
        The passivity controller watches the force's port only.
    """

    def __init__(self, law: ForceLaw, config: PipelineConfig = PipelineConfig()) -> None:
        self.law = law
        self.config = config
        self.watchdog = Watchdog(config.timeout, max_lead=config.max_lead)
        self.velocity_estimator = VelocityEstimator(config.velocity_window)
        self.passivity = PassivityController(
            max_damping=config.max_damping, servo_period=config.servo_period) \
            if config.passivity else None
        self.last_reason = Reason.NO_STATE
        self.last_stamp = math.nan
        self.last_torque = _ZERO

    def step(self, contact: Contact | None, velocity, now: float) -> np.ndarray:
        """Render one servo step.

        Parameters
        ----------
        contact : Contact or None
            Latest collision state (the same one again when none newer arrived); None before the
            first one.
        velocity : (3,) float, m/s, or None
            Tip velocity from the driver's twist; None to estimate it from the contacts' tips.
        now : float, s
            Current time on the stamps' clock.

        Returns
        -------
        (3,) float, N
            Force on the tip in the contact's frame; zero when the watchdog rejects the input.
        """
        limit = self.config.force_limit
        twist = None if velocity is None else floats3(velocity)
        reason = self._screen(contact, twist, now)
        self.last_reason = reason
        self.last_stamp = math.nan if contact is None else contact.stamp
        position, force, axis = None, _ZERO, None
        self.last_torque = _ZERO
        if reason is Reason.OK or reason is Reason.STALE:
            position = floats3(contact.tip)
        else:
            twist = None
        if reason is Reason.OK:
            self.velocity_estimator.add(contact.stamp, position)
            if twist is None:
                twist = self.velocity_estimator.velocity_components()
            raw = floats3(self.law.force(contact, twist))
            force = saturate_components(raw, limit)
            axis = self.law.axis(contact)
            torque = self.law.torque(contact)
            if torque != _ZERO:
                self.last_torque = _scaled(torque, force, raw)
        if self.passivity is not None:
            force = saturate_components(
                self.passivity.control(force, twist, position, now, axis), limit)
            self.passivity.record(force)
        return np.array(force)

    def _screen(self, contact: Contact | None, twist, now: float) -> Reason:
        """Ask the watchdog about this step's input (None is no state at all).

        A state the engine could not answer (no object, a refused pose) gives zero force, once
        the watchdog has judged its stamp; a NOT_CONVERGED one is rendered: its distance is an
        upper bound, so the force is at most the exact one.
        """
        if contact is None:
            return Reason.NO_STATE
        unanswered = _UNANSWERED.get(contact.status)
        reason = self.watchdog.check(contact.stamp, now,
                                     unanswered is not None or _finite(contact, twist))
        return unanswered if reason is Reason.OK and unanswered is not None else reason


def _scaled(torque, force, raw) -> tuple[float, float, float]:
    """Return ``torque`` scaled by |force| / |raw|: the share of the law's force kept."""
    kept = math.hypot(*force)
    whole = math.hypot(*raw)
    scale = kept / whole if whole > 0.0 else 1.0
    return (torque[0] * scale, torque[1] * scale, torque[2] * scale)


def _finite(contact: Contact, velocity: tuple[float, float, float] | None) -> bool:
    """Tell whether every number of the contact (and of the velocity, if given) is finite."""
    isfinite = math.isfinite
    face = contact.face
    return (isfinite(contact.distance) and all(map(isfinite, contact.point.tolist()))
            and all(map(isfinite, contact.normal.tolist()))
            and all(map(isfinite, contact.tip.tolist()))
            and (velocity is None or all(map(isfinite, velocity)))
            and (face is None or bool(np.isfinite(face.distance).all()
                                      and np.isfinite(face.points).all()
                                      and np.isfinite(face.normals).all()
                                      and np.isfinite(face.rotation).all())))
