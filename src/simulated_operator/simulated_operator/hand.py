"""The operator's hand on the simulated wand: an impedance pulling the tip to a scripted target.

A hand holding a haptic handle behaves, to first order, like a spring and damper to where the user
means the tip to be (Hogan's impedance model of the arm). With the hand at ~50 N/m aiming 1 cm
inside a 160 N/m virtual wall, the rendered force balances the hand about 2.4 mm inside the
surface, k_hand · 0.01 / (k_hand + k_wall), and the tip rests on the wall; without the force it
would follow the hand to the target.
"""

from typing import Callable

import numpy as np

from haptic_contract.checks import finite_components, finite_number, read_only_vector
from haptic_wand_driver.hand_coupling import impedance
from simulated_operator.scripts import Script, TargetComponents

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
        stiffness, damping, rotational_stiffness, rotational_damping = (
            finite_number(value, f'OperatorHand {name}', minimum=0.0)
            for name, value in (('stiffness', stiffness), ('damping', damping),
                                ('rotational_stiffness', rotational_stiffness),
                                ('rotational_damping', rotational_damping)))
        self._script = script
        self._target_components = _float_target(script)
        self._stiffness = read_only_vector([stiffness] * 3 + [rotational_stiffness] * 2)
        self._damping = read_only_vector([damping] * 3 + [rotational_damping] * 2)

    @property
    def script(self) -> Script:
        """The script the hand follows."""
        return self._script

    @property
    def stiffness(self) -> np.ndarray:
        """(5,) float, read-only: N/m on x, y, z, N·m/rad on roll, yaw."""
        return self._stiffness

    @property
    def damping(self) -> np.ndarray:
        """(5,) float, read-only: N·s/m on x, y, z, N·m·s/rad on roll, yaw."""
        return self._damping

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
        target = self._script.target(t)
        return impedance(self._stiffness, self._damping, target.coordinates, target.rates,
                         coordinates, rates)

    def target_components(self, t: float) -> TargetComponents:
        """Return the script's target at ``t`` (s) as finite floats, for the wand's substeps.

        A waypoint script's targets are finite by construction; any other script's are checked.
        """
        return self._target_components(t)


def _float_target(script: Script) -> Callable[[float], TargetComponents]:
    """Return the script's own ``target_components``, or its ``target`` as checked floats."""
    components = getattr(script, 'target_components', None)
    if components is not None:
        return components

    def checked_target(t: float) -> TargetComponents:
        target = script.target(t)
        name = f'{type(script).__name__}.target({t!r})'
        return (finite_components(target.coordinates, 5, f'{name}.coordinates'),
                finite_components(target.rates, 5, f'{name}.rates'))
    return checked_target
