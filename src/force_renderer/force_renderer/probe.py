"""The probe's contact law: its face's points pressed into the surface, giving force and torque.

Why a point shell: a probe's face (about 40 x 10 mm) sits flush on the skin, and tilting it is
felt as a torque, which a single contact point cannot give. The face is n points, each the centre
of an equal share of its area (``collision_engine.tool.face_shell``); the collision engine
measures each point's exact signed distance to the scene. Each point in the surface by a depth d
along the outward normal n pushes with the material's spring-damper at **1/n of its gains**,

    f_i = K/n ⊙ (d_i n_i) − C/n ⊙ v, never pulling (``unilateral_spring_damper``),

so the total stiffness is the material's whatever the number of points: a face flush at depth d
gets exactly K d, as a point tip would. The torque about the tip is the sum of (x_i − tip) × f_i,
x_i the face point. On a plane of stiffness k, a face rolled by θ with all of it pressed in gets
the restoring torque −k cos θ sin θ ⟨y²⟩ (⟨y²⟩ the mean square of the points' arms along the
tilted side: L²/12 (1 − 1/m²) for m cells along a side L; the continuous face's L²/12 as m grows).
The damper here acts on the tip's linear velocity (the state carries no angular one); the
device's own rendering of the model's planes damps each tool point's velocity, rotation included
(``haptic_contract.contact_model``).

Contact set: the points with d > 0. With none, the law pushes nothing; its local model then
holds the whole face, for the contact the device may meet before the next state.
"""
import math

import numpy as np

from force_renderer.contact import Contact
from force_renderer.spring_damper import SpringDamper
from haptic_contract.checks import floats3
from haptic_contract.plane_law import unilateral_spring_damper

__all__ = ['ProbeSpringDamper', 'equivalent_points']

Vector3 = tuple[float, float, float]
_ZERO = (0.0, 0.0, 0.0)
_ANGLES = [0.5 * math.pi + 2.0 * math.pi * j / 3 for j in range(3)]
_SPREAD = math.sqrt(2.0) * np.array([[math.cos(a), math.sin(a)] for a in _ANGLES])
"""Three unit points 120 degrees apart, times sqrt 2: mean zero, covariance the identity."""


def equivalent_points(arms: np.ndarray) -> np.ndarray:
    """Return three points with the mean and covariance of ``arms`` (k, 3), as (3, 3) rows.

    Why: three points of equal stiffness placed so reproduce, on a plane, the force, the torque
    and the rotational stiffness of the k points, which is all a 3-plane model can carry.
    """
    mean = arms.mean(axis=0)
    centred = arms - mean
    values, vectors = np.linalg.eigh(centred.T @ centred / len(arms))
    widths = np.sqrt(np.maximum(values[1:], 0.0)) * vectors[:, 1:]  # the two widest axes
    return mean + _SPREAD @ widths.T


class ProbeSpringDamper(SpringDamper):
    """The face's point shell, each point at 1/n of the material's gains (module docstring).

    A contact without a face (a point tip's state) gets the plain normal law, ``SpringDamper``.

    Parameters
    ----------
    stiffness : float or (3,) float, N/m
        K per world axis, for the whole face.
    damping : float or (3,) float, N·s/m
        C per world axis, for the whole face, in contact only.
    """

    def __init__(self, stiffness, damping) -> None:
        super().__init__(stiffness, damping)
        self._torque = _ZERO

    def wrench(self, contact: Contact, velocity) -> tuple[Vector3, Vector3]:
        """Force (N) and torque about the tip (N·m) of the face, scene frame, as floats.

        Plain floats point by point: numpy's per-call cost on 3-vectors is larger than the
        arithmetic, and this runs once per state at 1 kHz.
        """
        face = contact.face
        velocity = floats3(velocity)
        share = 1.0 / len(face.distance)
        stiffness = tuple((self.stiffness * share).tolist())
        damping = tuple((self.damping * share).tolist())
        tx0, ty0, tz0 = contact.tip.tolist()
        fx = fy = fz = mx = my = mz = 0.0
        for distance, (px, py, pz), n in zip(face.distance.tolist(), face.points.tolist(),
                                             face.normals.tolist()):
            if distance >= 0.0:
                continue
            d = -distance
            f = unilateral_spring_damper((d * n[0], d * n[1], d * n[2]), n, velocity,
                                         stiffness, damping)
            ax, ay, az = px - tx0, py - ty0, pz - tz0
            fx, fy, fz = fx + f[0], fy + f[1], fz + f[2]
            mx += ay * f[2] - az * f[1]
            my += az * f[0] - ax * f[2]
            mz += ax * f[1] - ay * f[0]
        return (fx, fy, fz), (mx, my, mz)

    def force(self, contact: Contact, velocity) -> np.ndarray:
        """Force on the tip, (3,) float, N; keeps the torque for ``torque``."""
        if contact.face is None:
            self._torque = _ZERO
            return super().force(contact, velocity)
        force, self._torque = self.wrench(contact, velocity)
        return np.array(force)

    def torque(self, contact: Contact) -> Vector3:
        """Return the torque about the tip (N·m) that came with the last ``force``."""
        return self._torque

    def axis(self, contact: Contact) -> Vector3 | None:
        """Return the outward normal while any point pushes; see ``ForceLaw.axis``."""
        if contact.face is None:
            return super().axis(contact)
        depth = contact.face.depth
        if not np.any(depth > 0.0):
            return None
        normal = depth @ contact.face.normals
        return tuple((normal / np.linalg.norm(normal)).tolist())

    def planes(self, contact: Contact) -> list:
        """Return three planes pushing the face's equivalent points; see ``ForceLaw.planes``.

        The points pressed in (or, with none, the whole face) become three points with their
        mean and covariance (``equivalent_points``), in the tip frame, each at a third of their
        share of the gains, against the surface plane through the points' surface points (the
        mean, along the mean normal): exact on a plane while the same points stay in contact.
        """
        face = contact.face
        if face is None:
            return super().planes(contact)
        pressed = face.depth > 0.0
        if not np.any(pressed):
            pressed = np.ones(len(face.distance), dtype=bool)
        normals = face.normals[pressed]
        normal = normals.sum(axis=0)
        normal /= np.linalg.norm(normal)
        surface = (face.points[pressed] - face.distance[pressed, None] * normals).mean(axis=0)
        arms = (face.points[pressed] - contact.tip) @ face.rotation  # in the tip frame
        share = np.count_nonzero(pressed) / (3.0 * len(face.distance))
        gains = (tuple((self.stiffness * share).tolist()), tuple((self.damping * share).tolist()))
        return [(tuple(surface.tolist()), tuple(normal.tolist()), *gains, tuple(arm))
                for arm in equivalent_points(arms).tolist()]
