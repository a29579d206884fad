"""Penalty force laws: a spring-damper along the surface normal, and the paper's law.

Both follow one small interface, `ForceLaw`: `force(contact, velocity) -> (3,)` in the contact's
frame, zero out of contact. The renderer's law (`SpringDamper`) is unilateral: a surface can push
the tip out but never pull it in. `CentroidSpringDamper` is the paper's law, kept only to compare
against (it pushes away from the object's vertex centroid, up to 45 degrees off a cube face).
"""

import math
from typing import Protocol

import numpy as np

from force_renderer.contact import Contact
from force_renderer.errors import ForceRendererError, per_axis, vector3
from haptic_contract.checks import floats3
from haptic_contract.plane_law import unilateral_spring_damper

__all__ = ['CentroidSpringDamper', 'ForceLaw', 'SpringDamper', 'nearest_plane']

Vector3 = tuple[float, float, float]
_ZERO = (0.0, 0.0, 0.0)


class ForceLaw(Protocol):
    """A rendering law: the force on the tip for one collision state."""

    def force(self, contact: Contact, velocity) -> np.ndarray:
        """Force on the tip, (3,) float, N, in the contact's frame; zero out of contact.

        `velocity` is the tip velocity, (3,) float, m/s, same frame.
        """

    def torque(self, contact: Contact) -> Vector3:
        """Return the torque about the tip (N·m) that came with the last `force`.

        Zero for a law that pushes the tip itself; a tool's face gives one (``probe``).
        """

    def axis(self, contact: Contact) -> Vector3 | None:
        """Return the unit direction its spring pushes the tip along (last `force`), or None.

        The passivity controller damps along it only (see `passivity`).
        """

    def planes(self, contact: Contact) -> list | None:
        """Return the planes a device may render for this contact, or None if it has no model.

        Each plane is (point (3,) m, unit outward normal (3,), stiffness (3,) N/m, damping (3,)
        N·s/m), the point on the plane the tip's centre may not cross (``local_model``), and
        optionally the tool point it pushes (3,) m in the tip frame (omitted: the tip).
        """


def nearest_plane(contact: Contact) -> tuple[Vector3, Vector3]:
    """Return the tangent plane at the closest point, as (point, outward normal).

    The point is the tip moved back to the surface along the normal, ``tip - distance·normal``:
    the plane the tip's centre may not cross, for a point tip (the closest point itself) and a
    sphere tip (the surface moved out by its radius) alike.
    """
    n = tuple(contact.normal.tolist())
    tip, d = contact.tip.tolist(), contact.distance
    return (tip[0] - d * n[0], tip[1] - d * n[1], tip[2] - d * n[2]), n


class SpringDamper:
    """F = K⊙x − C⊙v in contact (x = depth × outward normal), never attractive; zero outside.

    Parameters
    ----------
    stiffness : float or (3,) float, N/m
        K per world axis (the object's material); one number means the same on every axis.
    damping : float or (3,) float, N·s/m
        C per world axis; it acts only in contact.
    """

    def __init__(self, stiffness, damping) -> None:
        self.stiffness = per_axis(stiffness, 'stiffness')
        self.damping = per_axis(damping, 'damping')
        self._stiffness = tuple(self.stiffness.tolist())
        self._damping = tuple(self.damping.tolist())

    def force(self, contact: Contact, velocity) -> np.ndarray:
        """Force on the tip, (3,) float, N; see `ForceLaw.force`."""
        if not contact.in_contact:
            return np.zeros(3)
        return np.array(unilateral_spring_damper(
            contact.penetration.tolist(), contact.normal.tolist(), floats3(velocity),
            self._stiffness, self._damping))

    def torque(self, contact: Contact) -> Vector3:
        """Return zero: the force acts at the tip; see `ForceLaw.torque`."""
        return _ZERO

    def axis(self, contact: Contact) -> Vector3 | None:
        """Return the outward surface normal in contact; see `ForceLaw.axis`."""
        return tuple(contact.normal.tolist()) if contact.in_contact else None

    def planes(self, contact: Contact) -> list:
        """Return the tangent plane at the closest point; see `ForceLaw.planes`."""
        return [nearest_plane(contact) + (self._stiffness, self._damping)]


class CentroidSpringDamper:
    """The paper's law: F = (r/|r|)⊙k·|d| − kd⊙v with r = tip − centroid, in contact only.

    For comparison only: the direction ignores the surface, and the damper may pull. At r = 0 the
    direction is undefined and the spring term is dropped.

    Parameters
    ----------
    stiffness : float or (3,) float, N/m
        k per axis (paper: 160 N/m; its Simulink model: 80 N/m).
    damping : float or (3,) float, N·s/m
        kd per axis (0.8 N·s/m in both).
    centroid : (3,) float, m
        Plain mean of the object's mesh vertices, in the contact's frame.
    """

    def __init__(self, stiffness, damping, centroid) -> None:
        self.stiffness = per_axis(stiffness, 'stiffness')
        self.damping = per_axis(damping, 'damping')
        self.centroid = vector3(centroid, 'centroid')
        if not np.all(np.isfinite(self.centroid)):
            raise ForceRendererError(f'centroid must be finite, got {self.centroid.tolist()}')

    def force(self, contact: Contact, velocity) -> np.ndarray:
        """Force on the tip, (3,) float, N; see `ForceLaw.force`."""
        if not contact.in_contact:
            return np.zeros(3)
        radial = contact.tip - self.centroid
        length = math.sqrt(float(radial @ radial))
        spring = radial * (-contact.distance / length) if length > 0.0 else np.zeros(3)
        return self.stiffness * spring - self.damping * np.asarray(velocity, dtype=np.float64)

    def planes(self, contact: Contact) -> None:
        """Return None: a push away from a centroid is no surface (see `ForceLaw.planes`)."""
        return None

    def torque(self, contact: Contact) -> Vector3:
        """Return zero: the force acts at the tip; see `ForceLaw.torque`."""
        return _ZERO

    def axis(self, contact: Contact) -> Vector3 | None:
        """Return the direction away from the centroid in contact; see `ForceLaw.axis`."""
        radial = contact.tip - self.centroid
        length = math.sqrt(float(radial @ radial))
        if not contact.in_contact or length == 0.0:
            return None
        return tuple((radial / length).tolist())
