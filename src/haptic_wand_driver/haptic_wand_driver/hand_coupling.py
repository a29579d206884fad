"""The hand holding the simulated wand, as the wand sees it: its gains, its target, its pull.

The wand integrates the pull itself, on every servo substep; what the hand aims at (a script, a
recording, a person's model) is the holder's business (the ``simulated_operator`` package ships
the scripted one), so the driver names only this interface.
"""

from typing import Protocol, Sequence

import numpy as np

__all__ = ['Hand', 'impedance']


class Hand(Protocol):
    """A spring-damper on the wand's five joints toward a target that moves in time."""

    stiffness: np.ndarray
    """(5,) float: N/m on x, y, z, N·m/rad on roll, yaw."""
    damping: np.ndarray
    """(5,) float: N·s/m on x, y, z, N·m·s/rad on roll, yaw."""

    def target_components(self, t: float) -> tuple[Sequence[float], Sequence[float]]:
        """Return the target's 5 coordinates and 5 rates at ``t`` (s), as finite floats."""


def impedance(stiffness, damping, target, target_rate, coordinate, rate):
    """Return the spring-damper effort pulling a joint toward a moving target.

    Plain arithmetic, so it takes floats (the simulated wand's substeps, one joint at a time)
    and arrays (:meth:`OperatorHand.effort`, every joint at once) alike.

    Parameters
    ----------
    stiffness : float or (5,) float, N/m or N·m/rad
    damping : float or (5,) float, N·s/m or N·m·s/rad
    target, coordinate : float or (5,) float, m or rad
    target_rate, rate : float or (5,) float, m/s or rad/s

    Returns
    -------
    effort : float or (5,) float, N or N·m
    """
    return stiffness * (target - coordinate) + damping * (target_rate - rate)
