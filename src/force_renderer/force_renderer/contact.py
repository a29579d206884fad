"""One collision state, as the renderer sees it.

Sign rule: `distance` is negative inside the object, so the tip penetrates when distance < 0; the
penetration vector is then the depth -distance along the outward normal. For a point tip that is
the vector from the tip to the closest surface point; for a sphere tip (the scene's
``tip_radius``) the closest point lies beyond the sphere's centre by r - depth, while the depth is
what the spring must push back.
"""

from dataclasses import dataclass

import numpy as np

from force_renderer.errors import vector3
from haptic_contract.collision_state import STATUS_INVALID_INPUT, STATUS_NO_OBJECT, \
    STATUS_NOT_CONVERGED, STATUS_OK

__all__ = ['Contact', 'FaceContact', 'STATUS_OK', 'STATUS_NOT_CONVERGED', 'STATUS_NO_OBJECT',
           'STATUS_INVALID_INPUT']


@dataclass(frozen=True, eq=False)
class FaceContact:
    """The tool's face against the scene, from one collision state (scene frame, SI).

    Attributes
    ----------
    distance : (n,) float, m
        Signed distance of each face point to the nearest surface, negative inside.
    points : (n, 3) float, m
        The face points, on the tool's surface.
    normals : (n, 3) float
        Unit outward normal of the surface nearest each point.
    rotation : (3, 3) float
        The tip's orientation (its frame's axes as columns), for the tool points of the model.
    """

    distance: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    rotation: np.ndarray

    @property
    def depth(self) -> np.ndarray:
        """(n,) float, m: each point's depth in the surface, zero outside."""
        return np.maximum(-self.distance, 0.0)


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
    status : int
        The engine's status (``STATUS_*``).
    face : FaceContact or None
        The tool's face against the scene when the scene has a tool (``probe``), else None.
    """

    distance: float
    point: np.ndarray
    normal: np.ndarray
    tip: np.ndarray
    object: str = ''
    stamp: float = 0.0
    status: int = STATUS_OK
    face: FaceContact | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, 'distance', float(self.distance))
        object.__setattr__(self, 'stamp', float(self.stamp))
        object.__setattr__(self, 'status', int(self.status))
        for name in ('point', 'normal', 'tip'):
            object.__setattr__(self, name, vector3(getattr(self, name), f'Contact.{name}'))

    @classmethod
    def from_floats(cls, distance: float, point: tuple, normal: tuple, tip: tuple, name: str,
                    stamp: float, status: int, face: FaceContact | None) -> 'Contact':
        """Build from a CollisionState's leaves: floats, 3-tuples of floats and an int.

        The renderer's per-answer constructor: its three vectors share one array, and it skips
        the checks of values a decoded message already has the types of.
        """
        vectors = np.array((*point, *normal, *tip))
        vectors.flags.writeable = False
        contact = object.__new__(cls)
        contact.__dict__.update(distance=distance, point=vectors[0:3], normal=vectors[3:6],
                                tip=vectors[6:9], object=name, stamp=stamp, status=status,
                                face=face)
        return contact

    @property
    def in_contact(self) -> bool:
        """True when the tip is strictly inside the object (touching the surface is no contact)."""
        return self.distance < 0.0

    @property
    def penetration(self) -> np.ndarray:
        """(3,) float, m: ``-distance * normal`` in contact, zero outside."""
        if self.in_contact:
            return -self.distance * self.normal
        return np.zeros(3)
