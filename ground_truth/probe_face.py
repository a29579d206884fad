"""A linear probe's face pressed into a plane, in closed form: its force and roll torque.

A face of length L along its roll lever, rolled by theta with the tip a depth d under a plane of
stiffness k, spread evenly along its length: every point y of the face sits d - y sin(theta)
deep, and over the pressed part of [-L/2, L/2]

    F = k/L ∫ (d - y sin θ) dy,    tau = k cos θ / L ∫ y (d - y sin θ) dy.

The face's width along the roll axis does not enter. The limit a renderer's grid of points
converges to, and what the report compares the flat run's torque with.
"""

import math

__all__ = ['continuous_face']


def continuous_face(depth: float, roll: float, length: float,
                    stiffness: float) -> tuple[float, float]:
    """Force (N) and roll torque (N·m) of a continuous face (module docstring)."""
    s, c = math.sin(roll), math.cos(roll)
    lower, upper = -0.5 * length, 0.5 * length
    if s > 0.0:
        upper = min(upper, depth / s)
    elif s < 0.0:
        lower = max(lower, depth / s)
    elif depth <= 0.0:
        return 0.0, 0.0
    if upper <= lower:
        return 0.0, 0.0

    def force(y):
        return depth * y - 0.5 * s * y * y

    def moment(y):
        return 0.5 * depth * y * y - s * y ** 3 / 3.0
    return (stiffness / length * (force(upper) - force(lower)),
            stiffness * c / length * (moment(upper) - moment(lower)))
