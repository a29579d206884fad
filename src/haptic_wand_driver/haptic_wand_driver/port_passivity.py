"""A passivity observer and controller at the device's port (Hannaford and Ryu, 2002).

Why here as well as in the force renderer: the renderer sees the force it computes, but the
wand feels that force a round trip later (about a millisecond over ROS 2), held until the next
one arrives. That delay makes a stiff wall return more energy on the way out than it took on
the way in, and the wand bounces. Only the device side knows the force actually applied and the
motion it did work on, so only here can that energy be observed and removed.

Sign rule: ``energy`` is what the environment has absorbed through the port, the negative of the
work its force did on the tip (a spring's stored energy counts as absorbed). A passive
environment keeps it >= 0. Each period the controller predicts the energy left once the force
has done its work at the present velocity; if that would be negative, it adds a damping along
the applied force's own axis, on the tip's speed along it, just large enough to keep the energy
at zero and capped at ``max_damping``. It only ever lowers that force, at most to zero: it
creates no direction the force did not have (damping along the velocity pushed sideways on a
tip sliding off a wall), amplifies nothing, and never pulls the tip in.

The books close once the force has been zero for ``BOOKS_CLOSE_AFTER``, the same policy as the
renderer's controller; ``force_renderer.passivity`` says why. A lapse does not count: a force
that is zero because the watchdog let no law through (a late tick, a stalled loop) has not left
the contact, and what the hand put in before stays on the books.

A switch of law is bounded by the same books (``bounded_shift``). A law that renders springs (a
contact model's planes) taken with the tip already behind them would store energy the hand never
put in, and give it back as the tip is pushed out. That is what a late tick does: the model held
expires before the next one comes, the force drops to zero, the hand pushes the tip in, and the
next model meets it deeper (a hand pressing a wall through late ticks got 58-120 mJ back). So at a
switch the planes are moved out along their normals until they store no more than the port has
absorbed in this contact, as passive set-position modulation does (Lee and Huang, IEEE T-RO
2010): what the hand put in comes back at most, however late the switch.
"""
import math

import numpy as np

from haptic_contract.checks import finite_number

__all__ = ['BOOKS_CLOSE_AFTER', 'PortPassivity', 'bounded_shift']

BOOKS_CLOSE_AFTER = 0.05  # [s] of zero force that ends a contact's books (a bounce is shorter)

Vector3 = tuple


class PortPassivity:
    """Keep the force applied at the device passive, against loop delay, jitter and drops.

    Parameters
    ----------
    max_damping : float, N·s/m
        Largest damping added; keep it below mass / servo period (a sampled damper oscillates
        beyond).
    """

    def __init__(self, max_damping: float) -> None:
        self.max_damping = finite_number(max_damping, 'max_damping', minimum=0.0, unit='N·s/m')
        self.energy = 0.0  # [J] absorbed by the environment in this contact
        self.net_work = 0.0  # [J] done on the tip by the applied force since the start
        self._force = (0.0, 0.0, 0.0)
        self._position = None
        self._free = 0.0  # [s] since the force went to zero

    def control(self, force: Vector3, position: Vector3, velocity: Vector3,
                period: float, lapsed: bool = False) -> Vector3:
        """Return the force to apply now, given the rendered one and the tip's motion.

        Parameters
        ----------
        force : (3,) float, N
            The force the renderer asks for.
        position : (3,) float, m
            The tip now.
        velocity : (3,) float, m/s
            The tip's velocity now.
        period : float, s
            Time until the next call (the servo period).
        lapsed : bool
            Whether the force is zero because the device's watchdog let nothing through (no law
            alive): the contact has not ended, so the period does not count toward closing the
            books.
        """
        self.observe(position)
        # Products, not ** 2: glibc's pow(x, 2) differs from x * x in the last bit now and then
        # (1,647 of 2e6 draws here), and the compiled loop multiplies.
        magnitude = math.sqrt(force[0] * force[0] + force[1] * force[1] + force[2] * force[2])
        if magnitude == 0.0:
            self._free += 0.0 if lapsed else period
            if self._free >= BOOKS_CLOSE_AFTER:
                self.energy = 0.0
            self._force = (0.0, 0.0, 0.0)
            return self._force
        self._free = 0.0
        speed = (force[0] * velocity[0] + force[1] * velocity[1]
                 + force[2] * velocity[2]) / magnitude  # along the force
        # The energy left after the coming period if the force did its work at this velocity.
        predicted = self.energy - magnitude * speed * period
        scale = 1.0
        if predicted < 0.0 and speed > 0.0 and period > 0.0:
            alpha = min(-predicted / (period * speed * speed), self.max_damping)
            scale = max(0.0, 1.0 - alpha * speed / magnitude)  # lowered, never turned round
        self._force = (force[0] * scale, force[1] * scale, force[2] * scale)
        return self._force

    def books(self) -> np.ndarray:
        """Return the controller's state as floats, for a compiled servo loop (``servo_loop``).

        Energy, net work, the held force (3), the last position (3), whether there is one, the
        time since the force went to zero, and ``max_damping``.
        """
        position = self._position or (0.0, 0.0, 0.0)
        return np.array((self.energy, self.net_work, *self._force, *position,
                         float(self._position is not None), self._free, self.max_damping))

    def restore(self, books: np.ndarray) -> None:
        """Take back the state ``books`` returned, once a compiled loop has run on it."""
        self.energy, self.net_work, fx, fy, fz, px, py, pz, known, self._free, _ = books.tolist()
        self._force = (fx, fy, fz)
        self._position = (px, py, pz) if known else None

    def observe(self, position: Vector3) -> None:
        """Book the work the held force did on the tip since the last call (again: nothing)."""
        if self._position is not None:
            f, p, q = self._force, self._position, position
            work = f[0] * (q[0] - p[0]) + f[1] * (q[1] - p[1]) + f[2] * (q[2] - p[2])
            self.energy -= work
            self.net_work += work
        self._position = (position[0], position[1], position[2])


def bounded_shift(springs, energy: float) -> float:
    """Return how far (m) to move planes out so that they store at most ``energy`` (J).

    ``springs`` are each plane's (depth, stiffness along its normal), m and N/m; every plane moves
    out by the same shift s >= 0, the least for which sum(k max(d - s, 0)^2 / 2) <= energy. The
    deepest planes are taken first: while m of them are behind the shifted planes the sum is a
    quadratic in s, whose smaller root is the shift if it lies before the next plane's depth.
    """
    behind = sorted(((d, k) for d, k in springs if d > 0.0 and k > 0.0), reverse=True)
    a = b = c = 0.0
    for m, (depth, stiffness) in enumerate(behind):
        a += stiffness
        b += stiffness * depth
        c += stiffness * depth * depth
        shift = (b - math.sqrt(max(b * b - a * (c - 2.0 * energy), 0.0))) / a
        if m + 1 == len(behind) or shift >= behind[m + 1][0]:
            return max(shift, 0.0)
    return 0.0
