"""The force law of one plane, and saturation to a force limit: once, for every renderer.

Why here: the force renderer renders a contact with this law, and the device renders the
renderer's planes (``contact_model``) with it again at its servo rate; both must give the same
force for the same depth. The compiled servo loop (``haptic_wand_driver.servo_loop``) repeats
the arithmetic in the same order, and its tests hold it to these functions, its reference.

One rule for what is not finite: a force with a NaN or Inf component has no direction to keep
and saturates to zero, so nothing non-finite ever reaches a device; a finite force whose squares
pass the float range is scaled, not zeroed.
"""

import math
from typing import Sequence

import numpy as np

from haptic_contract.checks import finite_number, vector3

__all__ = ['damped_along', 'saturate', 'saturate_components', 'unilateral_spring_damper']

Vector3 = tuple[float, float, float]


def unilateral_spring_damper(displacement: Vector3, normal: Vector3, velocity: Vector3,
                             stiffness: Vector3, damping: Vector3) -> Vector3:
    """K⊙x − C⊙v with its component along `normal` clipped at zero, as plain floats.

    Why clip: on the way out of a surface the damper opposes the outward motion and can outweigh
    the spring near the surface; the clip keeps it from pulling the tip back in (a sticky wall).

    Parameters
    ----------
    displacement : (3,) float, m
        Spring extension x, pointing out of the surface (towards where the tip should be).
    normal : (3,) float
        Unit outward normal that decides what "attractive" means.
    velocity : (3,) float, m/s
        Tip velocity.
    stiffness, damping : (3,) float, N/m and N·s/m
        Per-axis gains along the frame's axes.
    """
    fx = stiffness[0] * displacement[0] - damping[0] * velocity[0]
    fy = stiffness[1] * displacement[1] - damping[1] * velocity[1]
    fz = stiffness[2] * displacement[2] - damping[2] * velocity[2]
    pushing = fx * normal[0] + fy * normal[1] + fz * normal[2]
    if pushing < 0.0:
        fx -= pushing * normal[0]
        fy -= pushing * normal[1]
        fz -= pushing * normal[2]
    return fx, fy, fz


def damped_along(force: Vector3, normal: Vector3, velocity: Sequence[float],
                 damping: float) -> Vector3:
    """``force`` minus ``damping`` times the normal speed, along the normal, never pulling."""
    push = force[0] * normal[0] + force[1] * normal[1] + force[2] * normal[2]
    speed = velocity[0] * normal[0] + velocity[1] * normal[1] + velocity[2] * normal[2]
    change = max(-push, -damping * speed)
    return (force[0] + change * normal[0], force[1] + change * normal[1],
            force[2] + change * normal[2])


def saturate_components(vector: Sequence[float], limit: float) -> Vector3:
    """Scale three floats down to norm ``limit`` if longer, keeping their direction; floats.

    Plain floats: numpy is slow on 3-vectors at 1 kHz. Zero if a component is not finite.
    """
    x, y, z = vector
    norm = math.sqrt(x * x + y * y + z * z)  # as numpy's norm: a vector too small to square is 0
    if norm == math.inf or norm != norm:  # a NaN or Inf, or squares past the float range
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            return 0.0, 0.0, 0.0
        largest = max(abs(x), abs(y), abs(z))
        a, b, c = x / largest, y / largest, z / largest
        norm = largest * math.sqrt(a * a + b * b + c * c)
    if norm <= limit:
        return x, y, z
    scale = limit / norm
    return x * scale, y * scale, z * scale


def saturate(vector, limit: float, *, error: type[ValueError] = ValueError) -> np.ndarray:
    """Return :func:`saturate_components` of a (3,) vector as a new array, both checked.

    ``limit`` must be finite and >= 0 (same unit as ``vector``); else ``error`` is raised.
    """
    components = vector3(vector, 'force', error=error).tolist()
    return np.array(saturate_components(components, finite_number(limit, 'limit', minimum=0.0,
                                                                  error=error)))
