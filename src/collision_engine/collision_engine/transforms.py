"""Rigid poses of the scene objects: local frame to world frame.

``x_world = rotation @ x_local + translation``. Angles follow REP-103: roll, pitch and yaw are
rotations about the fixed x, y and z axes, applied in that order (``R = Rz(yaw) Ry(pitch)
Rx(roll)``); quaternions are in ROS order (x, y, z, w).
"""

import numpy as np
from scipy.spatial.transform import Rotation

from haptic_contract.checks import finite_vector

__all__ = ['Pose']

_ORTHONORMAL_TOLERANCE = 1e-9


class Pose:
    """A rigid transform from an object's local frame to the world frame.

    Parameters
    ----------
    rotation : (3, 3) float, optional
        Proper rotation matrix (orthonormal, determinant +1); identity by default.
    translation : (3,) float, m, optional
        Position of the local origin in the world frame; zero by default.
    """

    __slots__ = ('rotation', 'translation')

    def __init__(self, rotation=None, translation=None) -> None:
        rotation = np.eye(3) if rotation is None else np.array(rotation, dtype=np.float64)
        if rotation.shape != (3, 3) or not np.all(np.isfinite(rotation)):
            raise ValueError(f'rotation must be a finite 3x3 matrix, got {rotation!r}')
        if (np.abs(rotation @ rotation.T - np.eye(3)).max() > _ORTHONORMAL_TOLERANCE
                or np.linalg.det(rotation) < 0.0):
            raise ValueError('rotation must be orthonormal with determinant +1')
        translation = np.zeros(3) if translation is None else translation
        self.translation = finite_vector(translation, 3, 'translation').copy()
        self.rotation = rotation
        self.rotation.setflags(write=False)
        self.translation.setflags(write=False)

    @classmethod
    def from_rpy(cls, position=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0)) -> 'Pose':
        """Pose from a position (3,) m and fixed-axis roll, pitch, yaw (3,) rad."""
        angles = finite_vector(rpy, 3, 'rpy')
        return cls(Rotation.from_euler('xyz', angles).as_matrix(), position)

    @classmethod
    def from_quaternion(cls, position=(0.0, 0.0, 0.0),
                        quaternion=(0.0, 0.0, 0.0, 1.0)) -> 'Pose':
        """Pose from a position (3,) m and a quaternion (x, y, z, w), normalised here."""
        q = finite_vector(quaternion, 4, 'quaternion')
        if np.linalg.norm(q) < 1e-12:
            raise ValueError(f'quaternion must be non-zero, got {quaternion!r}')
        return cls(Rotation.from_quat(q).as_matrix(), position)

    def to_local(self, points) -> np.ndarray:
        """World-frame points (3,) or (n, 3), m, expressed in the local frame."""
        return (np.asarray(points, dtype=np.float64) - self.translation) @ self.rotation

    def to_world(self, points) -> np.ndarray:
        """Local-frame points (3,) or (n, 3), m, expressed in the world frame."""
        return np.asarray(points, dtype=np.float64) @ self.rotation.T + self.translation

    def vector_to_world(self, vectors) -> np.ndarray:
        """Local-frame directions (3,) or (n, 3) rotated into the world frame."""
        return np.asarray(vectors, dtype=np.float64) @ self.rotation.T

    def __repr__(self) -> str:
        rpy = Rotation.from_matrix(self.rotation).as_euler('xyz')
        return f'Pose(position={self.translation.tolist()}, rpy={rpy.tolist()})'
