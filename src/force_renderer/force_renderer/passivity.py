"""Passivity of the rendered contact: the Colgate–Schenkel bound and the Hannaford–Ryu controller.

Sign convention, used throughout this package: the port energy E is the energy that has flowed
from the device INTO the rendering, E = −∫ F·v dt, where F (N) is the force the rendering commands
on the device and v (m/s) the tip velocity. A passive rendering can only store or dissipate what
it was given, so E ≥ 0; E < 0 means the rendering has generated energy, which is what makes a stiff
virtual wall buzz.

Three refinements of Hannaford and Ryu's scheme (bench/stiffness_sweep.py runs both forms):

- The observer books each servo interval as −F·Δx, the force actually held on the device times the
  tip's displacement over the interval: the exact work under a zero-order hold. Their −F(k)·v(k)·T
  pairs a force with a velocity of the same instant and cannot see the energy the hold itself
  generates (K|Δx|²/2 per interval for a spring, whose held force lags the position).
- The controller compares that work with what the same law, rendered continuously along the same
  path, would have done (the trapezoid rule on the law's force), not with zero. Against zero, the
  energy stored in the wall and dissipated on the way in forms a reserve that pays for a sustained
  buzz long before E reaches zero; against the continuous law, the energy the sampling generates
  shows up in the interval it is generated.
- The damping is predicted for the coming interval (as Hannaford and Ryu include the current
  force's power) and acts only along the law's spring axis (`ForceLaw.axis`: the surface normal,
  or the proxy's spring), on the tip's speed along it. It changes only the push along that axis,
  never below zero (no pulling): up when the tip moves in (entering a wall: the sampled spring's
  missing K·T/2 damping), down when it moves out. Whatever else the law's force holds, such as
  the damper's tangential residue as a contact ends, passes unchanged: the controller creates no
  direction the law did not push along, and amplifies no residue. (Damping along the law's whole
  force, as first built, scaled such a residue into sideways kicks of up to 0.13 N.)

When the books close, for this controller and the device port's (`haptic_wand_driver.
port_passivity`) alike: a deficit is carried across a short break in contact, and dropped once the
tip has been free for `BOOKS_CLOSE_AFTER`. A stiff wall that the tip bounces off makes a string of
contacts a few milliseconds apart, each generating energy by the sampling: closing the books at
every break forgave each bounce its energy, and at K = 1e5 N/m the rendering then gave the hand
+8.8 mJ (tests/force_renderer/test_passivity.py). A new touch after a real break is another
contact: a deficit carried into it cancels its push until paid, and the tip sinks into a soft
wall (seen at the port when the deficit was kept for good).
"""

import math

from force_renderer.errors import non_negative, per_axis, positive

__all__ = ['BOOKS_CLOSE_AFTER', 'PassivityController', 'passivity_bound', 'passivity_warning']

BOOKS_CLOSE_AFTER = 0.05  # [s] of free space that ends a contact's books (a bounce is shorter)

Vector3 = tuple[float, float, float]
_AXES = 'xyz'


def passivity_bound(device_damping: float, servo_period: float, damping: float = 0.0) -> float:
    """Largest virtual-wall stiffness that is passive when sampled (Colgate and Schenkel, 1997).

    A wall K, B sampled every T seconds on a device with physical damping b is passive when
    b > K·T/2 + |B|, that is K < 2(b − |B|)/T.

    Parameters
    ----------
    device_damping : float, N·s/m
        The device's own viscous damping b (what the mechanism dissipates).
    servo_period : float, s
        Sampling period T of the force loop.
    damping : float, N·s/m
        Virtual damping B of the wall.

    Returns
    -------
    float, N/m
        K_max = 2(b − |B|)/T, or 0.0 when |B| ≥ b (then no stiffness is guaranteed passive).
    """
    b = non_negative(device_damping, 'device_damping')
    period = positive(servo_period, 'servo_period')
    return max(0.0, 2.0 * (b - abs(float(damping))) / period)


def passivity_warning(stiffness, device_damping: float, servo_period: float,
                      damping=0.0) -> str | None:
    """Return a message for the log when a per-axis stiffness exceeds the bound, else None.

    Parameters
    ----------
    stiffness, damping : float or (3,) float, N/m and N·s/m
        The wall's per-axis gains (as in `SpringDamper`).
    device_damping : float, N·s/m
        The device's physical damping b.
    servo_period : float, s
        Force-loop period T.
    """
    stiffness = per_axis(stiffness, 'stiffness')
    damping = per_axis(damping, 'damping')
    excess = []
    for axis, k, c in zip(_AXES, stiffness.tolist(), damping.tolist()):
        bound = passivity_bound(device_damping, servo_period, c)
        if k > bound:
            excess.append(f'{axis}: K = {k:g} N/m > K_max = {bound:g} N/m')
    if not excess:
        return None
    return ('stiffness above the passivity bound 2(b - C)/T with b = '
            f'{float(device_damping):g} N*s/m, T = {float(servo_period):g} s ('
            + '; '.join(excess) + '): the wall may buzz unless the passivity controller is on')


class PassivityController:
    """Time-domain passivity observer and controller (Hannaford and Ryu 2002), impedance causality.

    State: the port energy E, and a deficit (J, never below zero) of work done on the device
    beyond what the continuous law would have done. Each step: book the interval that just ended
    into both, predict the deficit after the coming interval, and if positive add a damping
    α = deficit/(T·v_a²) along the law's axis a (v_a: tip speed along a), at most `max_damping`.
    Out of contact (no axis) nothing is added; the deficit is dropped once the tip has been free
    for `BOOKS_CLOSE_AFTER` (see the module docstring).

    Use, every servo step: `control(...)` with the law's force already saturated (the continuous
    reference) and its axis, then `record(...)` with the force actually sent.

    Parameters
    ----------
    max_damping : float, N·s/m
        Largest α; keep it below the device's m/T (a larger sampled damper oscillates itself).
    servo_period : float, s
        Nominal period T over which a deficit is dissipated.
    """

    def __init__(self, *, max_damping: float = 100.0, servo_period: float = 0.001) -> None:
        self.max_damping = non_negative(max_damping, 'max_damping')
        self.servo_period = positive(servo_period, 'servo_period')
        self.reset()

    def reset(self) -> None:
        """Forget all history: zero energy and deficit, no last force, position or time."""
        self._energy = 0.0
        self._deficit = 0.0
        self._damping = 0.0
        self._applied: Vector3 = (0.0, 0.0, 0.0)
        self._reference: Vector3 = (0.0, 0.0, 0.0)
        self._position: Vector3 | None = None
        self._time: float | None = None
        self._free_since: float | None = None

    @property
    def energy(self) -> float:
        """Observed port energy E, J (positive: absorbed by the rendering)."""
        return self._energy

    @property
    def deficit(self) -> float:
        """Energy generated beyond the continuous law in this contact, not yet dissipated, J."""
        return self._deficit

    @property
    def damping(self) -> float:
        """The α added at the last step, N·s/m."""
        return self._damping

    def control(self, force: Vector3, velocity: Vector3 | None, position: Vector3 | None,
                now: float, axis: Vector3 | None = None) -> Vector3:
        """Book the last interval, then return the law's force plus the passivity damping.

        Parameters
        ----------
        force : (3,) float, N
            The law's force on the tip, within the device limit.
        velocity : (3,) float, m/s, or None
            Tip velocity; None when unknown (then no damping can be added).
        position : (3,) float, m, or None
            Tip position; None when unknown (the interval is then booked as v·Δt).
        now : float, s
            Time of this step.
        axis : (3,) float or None
            Unit axis of the law's spring (`ForceLaw.axis`); None out of contact.

        Returns
        -------
        (3,) float, N
            Force to saturate and send.
        """
        self._observe(force, velocity, position, now)
        previous, self._reference = self._reference, tuple(force)
        self._damping = 0.0
        fx, fy, fz = force
        if axis is None:
            self._close_books_after_a_break(now)
            return fx, fy, fz
        self._free_since = None
        ax, ay, az = axis
        push = fx * ax + fy * ay + fz * az
        if velocity is None or push <= 0.0:
            return fx, fy, fz
        speed = velocity[0] * ax + velocity[1] * ay + velocity[2] * az
        excess = self._deficit + _hold_excess(force, previous, velocity, self.servo_period)
        if excess <= 0.0 or speed == 0.0:
            return fx, fy, fz
        self._damping = min(self.max_damping, excess / (self.servo_period * speed * speed))
        change = max(-push, -self._damping * speed)  # the push along the axis stays >= 0
        return fx + change * ax, fy + change * ay, fz + change * az

    def _close_books_after_a_break(self, now: float) -> None:
        if self._free_since is None:
            self._free_since = now
        elif now - self._free_since >= BOOKS_CLOSE_AFTER:
            self._deficit = 0.0

    def record(self, applied: Vector3) -> None:
        """Remember the force actually sent this step, (3,) float, N, for the next booking."""
        self._applied = tuple(applied)

    def _observe(self, force: Vector3, velocity: Vector3 | None, position: Vector3 | None,
                 now: float) -> None:
        """Book the interval since the last step into the energy and the deficit."""
        if self._time is not None:
            if position is not None and self._position is not None:
                (px, py, pz), (qx, qy, qz) = position, self._position
                dx, dy, dz = px - qx, py - qy, pz - qz
            elif velocity is not None:
                elapsed = now - self._time
                dx, dy, dz = velocity[0] * elapsed, velocity[1] * elapsed, velocity[2] * elapsed
            else:
                dx = dy = dz = 0.0
            (ax, ay, az), (rx, ry, rz) = self._applied, self._reference
            work = ax * dx + ay * dy + az * dz
            continuous = 0.5 * ((rx + force[0]) * dx + (ry + force[1]) * dy
                                + (rz + force[2]) * dz)
            if math.isfinite(work - continuous):
                self._energy -= work
                self._deficit = max(0.0, self._deficit + work - continuous)
        self._time = now
        self._position = position


def _hold_excess(force: Vector3, previous: Vector3, velocity: Vector3, period: float) -> float:
    """Predicted work, J, of holding `force` for one period beyond what the continuous law does.

    The continuous force is extrapolated linearly from `previous` through `force`; when the
    extrapolation reverses it (the tip is leaving the surface) it is taken to fall to zero where
    its component along `force` crosses zero, and to stay there.
    """
    (fx, fy, fz), (px, py, pz), (vx, vy, vz) = force, previous, velocity
    held = (fx * vx + fy * vy + fz * vz) * period
    ex, ey, ez = 2.0 * fx - px, 2.0 * fy - py, 2.0 * fz - pz
    strength = fx * fx + fy * fy + fz * fz
    along = ex * fx + ey * fy + ez * fz
    if along < 0.0:
        return held - 0.5 * held * strength / (strength - along)
    return 0.5 * held - 0.5 * (ex * vx + ey * vy + ez * vz) * period
