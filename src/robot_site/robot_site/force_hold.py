"""Force-hold: the remote site keeps a set pressing force while the operator slides.

Why: robotic scanners hold a set force to half a newton (Bao et al., IEEE TIM 2023: 0.57 N) while
the sonographer moves the probe along the skin; over a delayed link the operator's own hand does
that only as well as the link lets it (issue 28, item 4). Held, the target follows the operator
along the surface only; along the contact's normal (the measured force's direction) it sits where
the robot's impedance spring presses the set force, F/K from the TCP, corrected by an integral
of the force error measured by the F/T sensor (the tissue's own damping, the robot's drag). The
patient's safety still bounds every target (``PatientSafety``).
"""
from dataclasses import dataclass

import numpy as np

from haptic_contract.checks import finite_number

__all__ = ['ForceHold', 'HoldConfig']


@dataclass(frozen=True)
class HoldConfig:
    """Parameters of the force-hold.

    Parameters
    ----------
    integral_rate : float, 1/s
        How fast the integral takes up a force error (its reach grows by error / K this often).
    min_force : float, N
        A hold is set only in contact: at least this force measured, or asked.
    integral_band : float, N
        The integral learns only from errors within this band: a step of the set force is the
        feed-forward's (F/K), and an integral wound up while the robot rises to it overshot
        (8 to 12 N: 13.5 N, settled in 0.69 s).
    """

    integral_rate: float = 5.0
    min_force: float = 1.0
    integral_band: float = 1.0

    def __post_init__(self):
        finite_number(self.integral_rate, 'HoldConfig.integral_rate', minimum=0.0)
        finite_number(self.min_force, 'HoldConfig.min_force', minimum=0.0, strict=True)
        finite_number(self.integral_band, 'HoldConfig.integral_band', minimum=0.0, strict=True)


class ForceHold:
    """The held force and its integral; ``target`` turns the operator's position into the hold's.

    Parameters
    ----------
    config : HoldConfig
    stiffness : float, N/m
        The robot's impedance spring.
    limit : float, N
        The most the spring may press (the patient's working limit): the integral stops there,
        rather than wind up against a bound that will not let it through.
    """

    def __init__(self, config: HoldConfig, stiffness: float, limit: float) -> None:
        self.config = config
        self.stiffness = finite_number(stiffness, 'ForceHold stiffness', minimum=0.0, strict=True)
        self.limit = finite_number(limit, 'ForceHold limit', minimum=0.0, strict=True)
        self.force: float | None = None  # [N] the set force; None: not holding
        self._integral = 0.0  # [m] along the normal, in

    def set(self, force: float | None, measured) -> bool:
        """Hold ``force`` N (None: the force measured now; <= 0: release); return if holding.

        Refused (not holding) out of contact, below ``min_force``, or above the limit.
        """
        if force is not None and force <= 0.0:
            self.force = None
            return False
        wanted = float(np.linalg.norm(measured)) if force is None else float(force)
        if not self.config.min_force <= wanted <= self.limit:
            self.force = None
            return False
        if self.force is None:
            self._integral = 0.0
        self.force = wanted
        return True

    def target(self, operator, tcp, measured, dt: float) -> np.ndarray:
        """Return where the robot aims, m: the operator's along the surface, the set force in."""
        operator, tcp = np.asarray(operator, dtype=float), np.asarray(tcp, dtype=float)
        magnitude = float(np.linalg.norm(measured))
        if self.force is None or magnitude < self.config.min_force:
            return operator  # out of contact: nothing to hold against
        normal = np.asarray(measured, dtype=float) / magnitude  # out of the patient
        error = self.force - magnitude
        if abs(error) <= self.config.integral_band:
            self._integral = min(max(self._integral + self.config.integral_rate * dt * error
                                     / self.stiffness, -self.force / self.stiffness),
                                 (self.limit - self.force) / self.stiffness)
        along = (operator - tcp) @ normal
        return operator - (along + self.force / self.stiffness + self._integral) * normal
