"""One collision state, as the renderer sees it.

Sign rule: `distance` is negative inside the object, so the tip penetrates when distance < 0; the
penetration vector then points from the tip to the closest surface point, along the outward
normal, and its length is -distance.
"""

from dataclasses import dataclass

import numpy as np

from force_renderer._checks import vector3

__all__ = ['Contact']


@dataclass(frozen=True, eq=False)
class Contact:
    """What the renderer needs from one CollisionState, all in the state's frame (SI, REP-103).

    Components may be NaN: a Contact carries what arrived, and the watchdog decides whether to
    trust it. Only a wrong shape raises `ForceRendererError`.

    Attributes
    ----------
    distance : float, m
        Signed distance from the tip to the nearest object, negative inside.
    point : (3,) float, m
        Closest point on that object's surface.
    normal : (3,) float
        Unit outward surface normal at `point`.
    tip : (3,) float, m
        Tip position the state was computed for.
    object : str
        Name of the nearest object, as in the scene file.
    stamp : float, s
        Stamp of the pose the state answers; carried through to the wrench.
    """

    distance: float
    point: np.ndarray
    normal: np.ndarray
    tip: np.ndarray
    object: str = ''
    stamp: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, 'distance', float(self.distance))
        object.__setattr__(self, 'stamp', float(self.stamp))
        for name in ('point', 'normal', 'tip'):
            object.__setattr__(self, name, vector3(getattr(self, name), f'Contact.{name}'))

    @property
    def in_contact(self) -> bool:
        """True when the tip is strictly inside the object (touching the surface is no contact)."""
        return self.distance < 0.0

    @property
    def penetration(self) -> np.ndarray:
        """(3,) float, m: `point - tip` in contact, zero outside."""
        if self.in_contact:
            return self.point - self.tip
        return np.zeros(3)
