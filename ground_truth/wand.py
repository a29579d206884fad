"""Independent ground truth for the wand driver tests: analytic rotations, shapes and a wall.

Nothing here imports haptic_wand_driver.
"""

import numpy as np

__all__ = [
    'Box',
    'Cylinder',
    'HalfSpace',
    'matrix_from_quaternion',
    'quaternion_from_matrix',
    'rotation_x',
    'rotation_y',
    'rotation_z',
    'wall_force',
]


def rotation_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rotation_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def matrix_from_quaternion(quaternion) -> np.ndarray:
    """Rotation matrix of a unit quaternion (x, y, z, w), by the textbook formula."""
    x, y, z, w = quaternion
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def quaternion_from_matrix(matrix) -> np.ndarray:
    """Return the unit quaternion (x, y, z, w) of a rotation whose trace is above -1."""
    w = 0.5 * np.sqrt(1.0 + np.trace(matrix))
    return np.array([matrix[2, 1] - matrix[1, 2], matrix[0, 2] - matrix[2, 0],
                     matrix[1, 0] - matrix[0, 1], 4.0 * w * w]) / (4.0 * w)


class HalfSpace:
    """Solid on the inner side of a plane through ``origin`` with outward ``normal``."""

    def __init__(self, origin, normal):
        self.origin = np.asarray(origin, dtype=float)
        self.normal = np.asarray(normal, dtype=float) / np.linalg.norm(normal)

    def signed_distance(self, point) -> float:
        return float(np.dot(np.asarray(point) - self.origin, self.normal))

    def outward_normal(self, point) -> np.ndarray:
        return self.normal

    def project(self, point):
        return point - self.signed_distance(point) * self.normal, self.normal


class Box:
    """Axis-aligned box; exact signed distance, normal of the nearest face (or corner region)."""

    def __init__(self, centre, size):
        self.centre = np.asarray(centre, dtype=float)
        self.half = 0.5 * np.asarray(size, dtype=float)

    def signed_distance(self, point) -> float:
        q = np.abs(np.asarray(point) - self.centre) - self.half
        return float(np.linalg.norm(np.maximum(q, 0.0)) + min(q.max(), 0.0))

    def outward_normal(self, point) -> np.ndarray:
        local = np.asarray(point) - self.centre
        q = np.abs(local) - self.half
        if q.max() > 0.0:
            outside = np.maximum(q, 0.0) * np.sign(local)
            return outside / np.linalg.norm(outside)
        axis = int(np.argmax(q))
        normal = np.zeros(3)
        normal[axis] = np.sign(local[axis]) or 1.0
        return normal

    def project(self, point):
        point = np.asarray(point, dtype=float)
        normal = self.outward_normal(point)
        return point - self.signed_distance(point) * normal, normal


class Cylinder:
    """Upright (z-axis) solid cylinder; exact signed distance, normal of the nearest feature."""

    def __init__(self, centre, radius, height):
        self.centre = np.asarray(centre, dtype=float)
        self.radius = radius
        self.half_height = 0.5 * height

    def _parts(self, point):
        local = np.asarray(point, dtype=float) - self.centre
        radial = np.hypot(local[0], local[1])
        return local, radial, radial - self.radius, abs(local[2]) - self.half_height

    def signed_distance(self, point) -> float:
        _, _, side, cap = self._parts(point)
        return float(np.hypot(max(side, 0.0), max(cap, 0.0)) + min(max(side, cap), 0.0))

    def outward_normal(self, point) -> np.ndarray:
        local, radial, side, cap = self._parts(point)
        across = local[:2] / radial if radial > 1e-12 else np.array([1.0, 0.0])
        radial_normal = np.array([*across, 0.0])
        cap_normal = np.array([0.0, 0.0, np.sign(local[2]) or 1.0])
        if side > 0.0 and cap > 0.0:
            edge = max(side, 0.0) * radial_normal + max(cap, 0.0) * cap_normal
            return edge / np.linalg.norm(edge)
        return radial_normal if side >= cap else cap_normal

    def project(self, point):
        point = np.asarray(point, dtype=float)
        normal = self.outward_normal(point)
        return point - self.signed_distance(point) * normal, normal


def wall_force(shape, position, velocity, stiffness=160.0, damping=0.8) -> np.ndarray:
    """Spring-damper along the outward normal while inside ``shape`` (the paper's gains)."""
    distance = shape.signed_distance(position)
    if distance >= 0.0:
        return np.zeros(3)
    normal = shape.outward_normal(position)
    return (-stiffness * distance - damping * np.dot(velocity, normal)) * normal
