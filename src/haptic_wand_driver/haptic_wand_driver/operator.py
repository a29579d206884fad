"""The operator's hand on the simulated wand: an impedance pulling the tip to a scripted target.

A hand holding a haptic handle behaves, to first order, like a spring and damper to where the user
means the tip to be (Hogan's impedance model of the arm). With the hand at ~50 N/m aiming 1 cm
inside a 160 N/m virtual wall, the rendered force balances the hand about 2.4 mm inside the
surface, k_hand · 0.01 / (k_hand + k_wall), and the tip rests on the wall; without the force it
would follow the hand to the target.
"""

import numpy as np

from haptic_wand_driver._checks import checked_number
from haptic_wand_driver.scripts import Script

__all__ = ['OperatorHand']


class OperatorHand:
    """Spring-damper from the wand's joint coordinates to a script's target.

    Parameters
    ----------
    script : Script
        The target as a function of time (s since the wand's clock started).
    stiffness : float, N/m
        Translational stiffness, the same on x, y, z.
    damping : float, N·s/m
        Acts on the velocity error to the target's velocity, so a moving target is followed
        without lag.
    rotational_stiffness : float, N·m/rad
        On roll and yaw.
    rotational_damping : float, N·m·s/rad
    """

    def __init__(self, script: Script, *, stiffness: float = 50.0, damping: float = 3.5,
                 rotational_stiffness: float = 0.3, rotational_damping: float = 0.017):
        for name, value in (('stiffness', stiffness), ('damping', damping),
                            ('rotational_stiffness', rotational_stiffness),
                            ('rotational_damping', rotational_damping)):
            checked_number(value, f'OperatorHand {name}', minimum=0.0)
        self.script = script
        self.stiffness = np.array([stiffness] * 3 + [rotational_stiffness] * 2, dtype=float)
        """(5,) float: N/m on x, y, z, N·m/rad on roll, yaw."""
        self.damping = np.array([damping] * 3 + [rotational_damping] * 2, dtype=float)
        """(5,) float: N·s/m on x, y, z, N·m·s/rad on roll, yaw."""

    def effort(self, t: float, coordinates: np.ndarray, rates: np.ndarray) -> np.ndarray:
        """Return the hand's generalized force on the wand's joints.

        Parameters
        ----------
        t : float, s
            Time since the wand's clock started.
        coordinates : (5,) float
            x, y, z [m], roll, yaw [rad].
        rates : (5,) float
            Their time derivatives [m/s, rad/s].

        Returns
        -------
        effort : (5,) float
            Force on x, y, z [N] and torque on roll, yaw [N·m].
        """
        target = self.script.target(t)
        return (self.stiffness * (target.coordinates - coordinates)
                + self.damping * (target.rates - rates))
