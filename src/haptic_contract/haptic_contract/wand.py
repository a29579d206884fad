"""Orientation of a 5-DOF wand: roll and yaw only, pitch is not a degree of freedom.

The wand's orientation is R = Rz(yaw) · Rx(roll), the REP-103 roll-pitch-yaw convention with pitch
fixed at zero: yaw turns about the world z axis, roll turns about the wand's own x axis after yaw.
Quaternions are (x, y, z, w), as in geometry_msgs. Angles are in radians.

Because roll is measured about a yawed axis, the world angular velocity and the torques that reach
the two joints both go through the same (3, 2) Jacobian, :func:`roll_yaw_jacobian`.
"""

import math

import numpy as np

__all__ = [
    'PITCH_TOLERANCE',
    'PitchError',
    'quaternion_from_roll_yaw',
    'roll_axis',
    'roll_yaw_from_quaternion',
    'roll_yaw_jacobian',
    'rotate',
]

PITCH_TOLERANCE = 1e-4
"""Largest pitch (rad) read back as zero: room for quaternions printed with a few decimals."""

_UNIT_NORM_TOLERANCE = 1e-3


class PitchError(ValueError):
    """A quaternion has a pitch that a 5-DOF wand cannot take, or is not a rotation at all."""


def quaternion_from_roll_yaw(roll: float, yaw: float) -> np.ndarray:
    """Return the unit quaternion of Rz(yaw) · Rx(roll).

    Parameters
    ----------
    roll : float, rad
        Turn about the wand's x axis (after yaw).
    yaw : float, rad
        Turn about the world z axis.

    Returns
    -------
    quaternion : (4,) float
        (x, y, z, w), with w >= 0 for |roll|, |yaw| < pi.
    """
    sin_roll, cos_roll = math.sin(0.5 * roll), math.cos(0.5 * roll)
    sin_yaw, cos_yaw = math.sin(0.5 * yaw), math.cos(0.5 * yaw)
    return np.array([cos_yaw * sin_roll, sin_yaw * sin_roll, sin_yaw * cos_roll,
                     cos_yaw * cos_roll])


def roll_yaw_from_quaternion(quaternion: np.ndarray, *,
                             pitch_tolerance: float = PITCH_TOLERANCE) -> tuple[float, float]:
    """Return (roll, yaw) of a quaternion, refusing any pitch a 5-DOF wand cannot have.

    Parameters
    ----------
    quaternion : (4,) float
        (x, y, z, w); must be of unit norm within 1e-3.
    pitch_tolerance : float, rad
        Largest |pitch| accepted (and dropped).

    Returns
    -------
    roll, yaw : float, rad
        In (-pi, pi].

    Raises
    ------
    PitchError
        If the quaternion is not finite, not of unit norm, or has |pitch| > pitch_tolerance.
    """
    q = np.asarray(quaternion, dtype=np.float64)
    if q.shape != (4,) or not np.all(np.isfinite(q)):
        raise PitchError(f'quaternion must be 4 finite numbers (x, y, z, w), got {quaternion!r}')
    norm = np.linalg.norm(q)
    if abs(norm - 1.0) > _UNIT_NORM_TOLERANCE:
        raise PitchError(f'quaternion {q.tolist()} has norm {norm:.6g}, not 1')
    x, y, z, w = q / norm
    pitch = np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))
    if abs(pitch) > pitch_tolerance:
        raise PitchError(f'quaternion {q.tolist()} has pitch {pitch:.6g} rad; a 5-DOF wand has '
                         f'none (tolerance {pitch_tolerance:g} rad)')
    roll = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    yaw = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return float(roll), float(yaw)


def rotate(vector, roll: float, yaw: float) -> tuple[float, float, float]:
    """Return R · vector for the wand's orientation R = Rz(yaw) · Rx(roll); (3,) floats."""
    x, y, z = vector
    c, s = math.cos(roll), math.sin(roll)
    y, z = c * y - s * z, s * y + c * z
    c, s = math.cos(yaw), math.sin(yaw)
    return (c * x - s * y, s * x + c * y, z)


def roll_axis(yaw: float) -> tuple[float, float, float]:
    """Return the roll joint's world axis at this yaw, (cos yaw, sin yaw, 0), as floats.

    The first column of :func:`roll_yaw_jacobian` (the second is z), for the per-tick paths,
    where building a (3, 2) array costs more than the arithmetic it carries.
    """
    return math.cos(yaw), math.sin(yaw), 0.0


def roll_yaw_jacobian(yaw: float) -> np.ndarray:
    """Return the world axes of the roll and yaw joints at this yaw.

    World angular velocity is ``J @ (roll_rate, yaw_rate)``; the joint torques produced by a world
    torque are ``J.T @ torque``. Its columns are orthonormal, and the pitch axis they leave out,
    Rz(yaw) · y, is what a 5-DOF wand cannot actuate.

    Parameters
    ----------
    yaw : float, rad

    Returns
    -------
    jacobian : (3, 2) float
        Columns: the roll axis (cos yaw, sin yaw, 0) and the yaw axis (0, 0, 1), world frame.
    """
    x, y, z = roll_axis(yaw)
    return np.array([[x, 0.0],
                     [y, 0.0],
                     [z, 1.0]])
