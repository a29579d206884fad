"""God-object proxy (Zilles and Salisbury 1995) on a signed-distance field.

The proxy is where the tip would be if the object were perfectly rigid: it follows the tip in free
space, stops on the first surface it meets, and then slides (without friction) to the point of the
touched surfaces nearest the tip. The force is a spring from the tip to the proxy, so its direction
comes from the surface that was entered, not from the surface nearest the tip: pushing through a
thin plate, or deep into one finger next to another, never flips it.

Moving the proxy is conservative advancement (sphere tracing) along the segment to its goal: a
step never exceeds the distance to the nearest surface, except that it is at least `min_step` so
that sliding along a surface makes progress. A step of `min_step` can overshoot a surface by at
most that much; crossing is detected (the field turns negative) and located, so only features
thinner than `min_step` can be tunnelled.
"""

from typing import Callable

import numpy as np

from force_renderer.contact import Contact
from force_renderer.errors import count, per_axis, positive, vector3
from force_renderer.spring_damper import nearest_plane
from haptic_contract.checks import floats3
from haptic_contract.contact_model import MAX_PLANES
from haptic_contract.plane_law import unilateral_spring_damper

__all__ = ['GodObjectProxy']

SignedDistance = Callable[[np.ndarray], tuple[float, np.ndarray]]
# A move along a tangent plane must not count as heading into it because of rounding: only a
# direction whose cosine with the outward normal is below this does.
_INTO_SURFACE = -1e-6


class GodObjectProxy:
    """A `ForceLaw` whose spring pulls the tip towards a proxy kept on the surface.

    Stateful: the proxy remembers where it is between calls, so call `force` (or `update`) once
    per servo step, in order, and `reset` when the scene or the tracking restarts.

    Parameters
    ----------
    stiffness : float or (3,) float, N/m
        Spring K per world axis.
    damping : float or (3,) float, N·s/m
        Damper C per world axis, in contact only and never pulling the tip in.
    signed_distance : callable point (3,) -> (distance m, outward unit normal (3,))
        The scene's signed distance (negative inside), e.g. the collision engine's query.
    iterations : int
        Constraint iterations per step (each: one move, then a new goal on the touched planes).
    min_step : float, m
        Smallest sphere-tracing step; keep it below half the thinnest feature to be felt.
    max_steps : int
        Sphere-tracing steps per move; the proxy stops short (still outside) when they run out.
    tolerance : float, m
        Distance within which a point counts as on the surface.
    """

    def __init__(self, stiffness, damping, signed_distance: SignedDistance, *,
                 iterations: int = 4, min_step: float = 2e-4, max_steps: int = 64,
                 tolerance: float = 1e-8) -> None:
        self.stiffness = per_axis(stiffness, 'stiffness')
        self.damping = per_axis(damping, 'damping')
        self.signed_distance = signed_distance
        self.iterations = count(iterations, 'iterations')
        self.min_step = positive(min_step, 'min_step')
        self.max_steps = count(max_steps, 'max_steps')
        self.tolerance = positive(tolerance, 'tolerance')
        self._proxy: np.ndarray | None = None
        self._touching = False
        self._planes: list[tuple[np.ndarray, np.ndarray]] = []

    @property
    def proxy(self) -> np.ndarray | None:
        """(3,) float, m: the proxy position, None before the first update."""
        return None if self._proxy is None else self._proxy.copy()

    @property
    def touching(self) -> bool:
        """True when a surface held the proxy back from the tip at the last update.

        A proxy that merely lags in free space (its tracing steps ran out) is not touching, and
        exerts no force.
        """
        return self._touching

    def reset(self) -> None:
        """Forget the proxy; the next update starts it at the tip (or on the surface near it)."""
        self._proxy = None
        self._touching = False
        self._planes = []

    def force(self, contact: Contact, velocity) -> np.ndarray:
        """Force on the tip, (3,) float, N: K⊙(proxy − tip) − C⊙v while touching, else zero.

        Only `contact.tip` is used: the proxy queries `signed_distance` itself.
        """
        tip = contact.tip
        proxy = self.update(tip)
        if not self._touching:
            return np.zeros(3)
        stretch = proxy - tip
        length = float(np.linalg.norm(stretch))
        return np.array(unilateral_spring_damper(
            stretch.tolist(), (stretch / length).tolist(), floats3(velocity),
            self.stiffness.tolist(), self.damping.tolist()))

    def torque(self, contact: Contact) -> tuple[float, float, float]:
        """Return zero: the proxy pulls the tip itself; see `ForceLaw.torque`."""
        return (0.0, 0.0, 0.0)

    def axis(self, contact: Contact) -> tuple[float, float, float] | None:
        """Return the direction from the tip to the proxy while touching; see `ForceLaw.axis`."""
        if not self._touching:
            return None
        stretch = self._proxy - contact.tip
        return tuple((stretch / float(np.linalg.norm(stretch))).tolist())

    def planes(self, contact: Contact) -> list:
        """Return the planes holding the proxy, or the nearest one; see `ForceLaw.planes`.

        Touching, the planes that stopped the proxy (up to three) carry its spring: each pushes
        the tip by its depth behind it. Else the tangent plane at the closest point.
        """
        gains = (tuple(self.stiffness.tolist()), tuple(self.damping.tolist()))
        if not self._planes:
            return [nearest_plane(contact) + gains]
        return [(tuple(point.tolist()), tuple(normal.tolist())) + gains
                for point, normal in self._planes]

    def update(self, tip) -> np.ndarray:
        """Move the proxy towards `tip` (3,) m and return its new position (3,) m."""
        tip = vector3(tip, 'tip')
        if self._proxy is None:
            self._proxy = self._onto_surface(tip)
        proxy = self._onto_surface(self._proxy)
        planes: list[tuple[np.ndarray, np.ndarray]] = []
        goal, hit = tip, None
        for iteration in range(self.iterations):
            proxy, hit = self._advance(proxy, goal)
            if hit is not None:
                planes = (planes + [hit])[-MAX_PLANES:]
                goal = _nearest_feasible(tip, planes, proxy, self.tolerance)
            elif goal is tip or iteration == self.iterations - 1:
                break
            else:
                # On a curved surface the tangent planes' goal lies off the surface: aim at the
                # tip again, which finds the surface a little further along.
                planes.clear()
                goal = tip
        self._proxy = proxy
        held_back = hit is not None or goal is not tip
        self._touching = held_back and float(np.linalg.norm(proxy - tip)) > self.tolerance
        self._planes = list(planes) if self._touching else []
        return proxy.copy()

    def _onto_surface(self, point: np.ndarray) -> np.ndarray:
        """`point` if outside the object, else its projection onto the nearest surface."""
        distance, normal = self.signed_distance(point)
        if distance >= 0.0:
            return point
        return point - distance * np.asarray(normal, dtype=np.float64)

    def _advance(self, start: np.ndarray,
                 goal: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray] | None]:
        """Sphere-trace from `start` towards `goal`.

        Returns the stopping point and, if a surface stopped it, that surface's tangent plane as
        (point on it, outward unit normal); None when the goal was reached (or the steps ran out).
        """
        offset = goal - start
        length = float(np.linalg.norm(offset))
        if length <= self.tolerance:
            return goal, None
        direction = offset / length
        point, travelled = start, 0.0
        distance, normal = self.signed_distance(point)
        for _ in range(self.max_steps):
            normal = np.asarray(normal, dtype=np.float64)
            if distance <= self.tolerance and float(direction @ normal) < _INTO_SURFACE:
                return point, (point, normal)
            step = min(max(distance, self.min_step), length - travelled)
            candidate = goal if travelled + step >= length else point + step * direction
            next_distance, next_normal = self.signed_distance(candidate)
            if next_distance < -self.tolerance:
                return self._crossing(point, distance, candidate, next_distance)
            point, travelled = candidate, travelled + step
            distance, normal = next_distance, next_normal
            if candidate is goal:
                return goal, None
        return point, None

    def _crossing(self, outside: np.ndarray, outside_distance: float, inside: np.ndarray,
                  inside_distance: float) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]:
        """Return the surface point where the segment outside→inside enters, and its plane."""
        fraction = outside_distance / (outside_distance - inside_distance)
        estimate = outside + fraction * (inside - outside)
        distance, normal = self.signed_distance(estimate)
        normal = np.asarray(normal, dtype=np.float64)
        surface = estimate - distance * normal
        return surface, (surface, normal)


def _nearest_feasible(tip: np.ndarray, planes: list[tuple[np.ndarray, np.ndarray]],
                      fallback: np.ndarray, tolerance: float) -> np.ndarray:
    """Return the point nearest `tip` on the outer side of every plane (point, normal).

    With at most three planes, the answer lies on some subset of them: try the tip itself, then
    its projection onto each plane, each pair's line and the triple's point, and keep the
    nearest one that satisfies every plane. `fallback` when none does.
    """
    normals = np.array([normal for _, normal in planes])
    offsets = np.array([float(normal @ point) for point, normal in planes])
    best, best_distance = fallback, np.inf
    for mask in range(1 << len(planes)):
        active = [i for i in range(len(planes)) if mask >> i & 1]
        candidate = tip
        if len(active) == 1:
            normal = normals[active[0]]
            candidate = tip - (float(normal @ tip) - offsets[active[0]]) * normal
        elif active:
            rows = normals[active]
            multipliers = np.linalg.lstsq(rows @ rows.T, rows @ tip - offsets[active],
                                          rcond=None)[0]
            candidate = tip - rows.T @ multipliers
        distance = float(np.linalg.norm(candidate - tip))
        if distance < best_distance and np.all(normals @ candidate - offsets >= -tolerance):
            best, best_distance = candidate, distance
    return best
