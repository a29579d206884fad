"""The commanded wrench as the driver holds it: validated, fresh or zero, actuatable, saturated.

The force renderer sends a wrench per pose; the driver applies one per tick. Between the two sits
:class:`WrenchCommand`: it keeps the latest good wrench, lets it go to zero when it is older than
``timeout`` (the renderer or the link died), ignores wrenches with NaN/Inf (and zeroes the force,
rather than keep rendering one that may be wrong), drops the pitch torque a 5-DOF wand cannot
render, and saturates force and torque to the device limits without turning their direction.

It is pure: it reads no clock, ``now`` is passed in (seconds, the clock that stamps the wrenches).
"""

import math

import numpy as np

from haptic_contract.checks import finite_components, finite_number
from haptic_contract.plane_law import saturate_components
from haptic_contract.wand import roll_axis

__all__ = ['Refusal', 'WrenchCommand']

_ZERO = (0.0, 0.0, 0.0)


class Refusal(str):
    """Why a wrench was not taken: the sentence itself, and ``kind``, its fixed short class."""

    def __new__(cls, kind: str, sentence: str) -> 'Refusal':
        refusal = super().__new__(cls, sentence)
        refusal.kind = kind
        return refusal


class WrenchCommand:
    """The latest rendered wrench, as the device should apply it now.

    Parameters
    ----------
    force_limit : float, N
        Force norm the device renders at most (``HapticDevice.limits.force_limit``).
    torque_limit : float, N·m
        Norm of the actuated torque the device renders at most.
    timeout : float, s
        A wrench whose stamp is more than this older than ``now`` is stale and gives zero.
    """

    def __init__(self, *, force_limit: float, torque_limit: float, timeout: float = 0.010):
        self._force_limit = finite_number(force_limit, 'WrenchCommand force_limit', minimum=0.0)
        self._torque_limit = finite_number(torque_limit, 'WrenchCommand torque_limit',
                                           minimum=0.0)
        self._timeout = finite_number(timeout, 'WrenchCommand timeout', minimum=0.0)
        self._force = self._torque = _ZERO
        self._stamp: float | None = None

    def update(self, force, torque, stamp: float, now: float) -> Refusal | None:
        """Take a received wrench; return None if it is held, else why it was ignored.

        A wrench with NaN/Inf or the wrong shape also clears the held wrench, so the force goes
        to zero until a good one arrives. A wrench older than the held one (out of order) or
        stamped more than ``timeout`` in the future (clocks disagree) is ignored and the held one
        stays.

        Parameters
        ----------
        force : (3,) float, N, workspace frame
        torque : (3,) float, N·m, workspace frame, about the tip
        stamp : float, s
            The wrench's stamp (the stamp of the pose it was rendered for).
        now : float, s
            Receive time on the same clock.

        Returns
        -------
        reason : Refusal or None
            Why the wrench was not taken, or None when it was.
        """
        try:
            force_components = finite_components(force, 3, 'force')
            torque_components = finite_components(torque, 3, 'torque')
        except ValueError as error:
            self.clear()
            return Refusal('non-finite wrench', f'wrench ignored and force zeroed: {error}')
        if not (math.isfinite(stamp) and math.isfinite(now)):
            self.clear()
            return Refusal('non-finite stamp', f'wrench ignored and force zeroed: stamp '
                           f'{stamp!r} or now {now!r} is not finite')
        if self._stamp is not None and stamp < self._stamp:
            return Refusal('older than the held wrench', f'wrench ignored: stamp {stamp:.6f} s '
                           f'is older than the held wrench ({self._stamp:.6f} s)')
        if stamp > now + self._timeout:
            return Refusal('stamped ahead of now', f'wrench ignored: stamp {stamp:.6f} s is '
                           f'{stamp - now:.6f} s ahead of now; the clocks disagree')
        self._force, self._torque, self._stamp = force_components, torque_components, float(stamp)
        return None

    @property
    def expiry(self) -> float:
        """When the held wrench goes stale (s, the stamps' clock); -inf when none is held."""
        return -math.inf if self._stamp is None else self._stamp + self._timeout

    def clear(self) -> None:
        """Drop the held wrench: zero force until a good one arrives."""
        self._stamp = None

    def is_fresh(self, now: float) -> bool:
        """Whether a wrench is held and at most ``timeout`` old at ``now`` (s)."""
        return self._stamp is not None and now - self._stamp <= self._timeout

    def current(self, now: float, yaw: float,
                expiry: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Return the wrench to apply at ``now``: zero unless fresh; actuatable; saturated.

        Parameters
        ----------
        now : float, s
        yaw : float, rad
            The wand's current yaw, which sets its roll axis.
        expiry : float or None, s
            When the held wrench stops being fresh, if not ``timeout`` after its stamp (the
            driver's ``answer_deadline``).

        Returns
        -------
        force : (3,) float, N, workspace frame
        torque : (3,) float, N·m, workspace frame
            Only its components about the roll axis and z remain (no pitch torque).
        """
        fresh = (self.is_fresh(now) if expiry is None
                 else self._stamp is not None and now <= expiry)
        if not fresh:
            return np.zeros(3), np.zeros(3)
        x, y, z = roll_axis(yaw)
        torque_x, torque_y, torque_z = self._torque
        about_roll = x * torque_x + y * torque_y + z * torque_z
        actuated_torque = (about_roll * x, about_roll * y, about_roll * z + torque_z)
        return (np.array(saturate_components(self._force, self._force_limit)),
                np.array(saturate_components(actuated_torque, self._torque_limit)))
