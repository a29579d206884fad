"""Exact signed-distance fields for the renderer's tests, written independently of the code.

Each field is a callable point (3,) -> (signed distance m, outward unit normal (3,)), negative
inside, like the collision engine's query. `closest_point` gives the matching surface point.
"""

import numpy as np

__all__ = ['Box', 'Sphere', 'Union', 'closest_point', 'contact_with', 'inflated']


class Box:
    """Axis-aligned box from `low` to `high` (m): exact distance and nearest-feature normal."""

    def __init__(self, low, high) -> None:
        self.low = np.asarray(low, dtype=float)
        self.high = np.asarray(high, dtype=float)

    def __call__(self, point) -> tuple[float, np.ndarray]:
        point = np.asarray(point, dtype=float)
        clamped = np.clip(point, self.low, self.high)
        if np.any(clamped != point):
            offset = point - clamped
            distance = float(np.linalg.norm(offset))
            return distance, offset / distance
        gaps = np.concatenate([point - self.low, self.high - point])
        face = int(np.argmin(gaps))
        normal = np.zeros(3)
        normal[face % 3] = -1.0 if face < 3 else 1.0
        return -float(gaps[face]), normal


class Sphere:
    """Ball of `radius` (m) about `centre` (m)."""

    def __init__(self, centre, radius: float) -> None:
        self.centre = np.asarray(centre, dtype=float)
        self.radius = float(radius)

    def __call__(self, point) -> tuple[float, np.ndarray]:
        offset = np.asarray(point, dtype=float) - self.centre
        length = float(np.linalg.norm(offset))
        return length - self.radius, offset / length


class Union:
    """The union of disjoint solids: the field of whichever is nearest (exact outside them)."""

    def __init__(self, *fields) -> None:
        self.fields = fields

    def __call__(self, point) -> tuple[float, np.ndarray]:
        return min((field(point) for field in self.fields), key=lambda answer: answer[0])


def closest_point(field, point) -> np.ndarray:
    """Surface point nearest `point` (3,) m, from the field's distance and normal."""
    distance, normal = field(point)
    return np.asarray(point, dtype=float) - distance * normal


def inflated(field, radius: float):
    """Return the field a sphere tip of ``radius`` (m) sees: the distance of its surface."""
    def distance(point) -> tuple[float, np.ndarray]:
        d, normal = field(point)
        return d - radius, normal
    return distance


def contact_with(field, tip, *, radius: float = 0.0, name: str = 'object', stamp: float = 0.0):
    """Return the Contact the engine reports for a tip (a sphere of ``radius``) at ``tip``.

    ``point`` stays the surface point nearest the centre, as in the engine.
    """
    from force_renderer.contact import Contact
    distance, normal = field(tip)
    return Contact(distance - radius, closest_point(field, tip), normal, tip, name, stamp)
