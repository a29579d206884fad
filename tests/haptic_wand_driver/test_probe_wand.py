"""The simulated wand holding a probe pressed and rolled on a plane: the hand holds its roll, the
face's torque turns it back, and it settles where the two balance.

The face law runs in the wand's servo loop (``render_locally``), as a device renders a contact
model. The expected rest is solved here from the hand's springs and a point-by-point sum of the
face on the plane, with no code of the toolkit's.
"""
import math

import numpy as np
import pytest
from scipy.optimize import fsolve

from force_renderer.contact import Contact, FaceContact
from force_renderer.probe import ProbeSpringDamper
from haptic_wand_driver.simulated import SimulatedWand, SimulatedWandConfig
from simulated_operator.hand import OperatorHand
from simulated_operator.scripts import WaypointScript

K, C = 1000.0, 2.0
SURFACE = -0.025
FACE = np.array([[x, y, 0.0] for x in (-0.0025, 0.0025) for y in np.arange(-0.0175, 0.018, 0.005)])
HAND, HAND_ROLL = 50.0, 0.3  # N/m and N·m/rad: OperatorHand's defaults


class FaceOnPlane:
    """The face law against the plane z = SURFACE, at the wand's state (a device's servo law)."""

    def __init__(self) -> None:
        self.law = ProbeSpringDamper(K, C)

    def wrench(self, time, coordinates, rates, period):
        x, y, z, roll, yaw = coordinates
        c, s, cy, sy = math.cos(roll), math.sin(roll), math.cos(yaw), math.sin(yaw)
        rotation = np.array([[cy, -sy * c, sy * s], [sy, cy * c, -cy * s], [0.0, s, c]])
        points = np.array([x, y, z]) + FACE @ rotation.T
        distance = points[:, 2] - SURFACE
        up = np.tile([0.0, 0.0, 1.0], (len(FACE), 1))
        contact = Contact(distance.min(), (x, y, SURFACE), (0.0, 0.0, 1.0), (x, y, z),
                          face=FaceContact(distance, points, up, rotation))
        force = self.law.force(contact, rates[:3])
        return tuple(force.tolist()), self.law.torque(contact)


def face_on_plane(z: float, roll: float) -> tuple[float, float]:
    """Force (N, along z) and roll torque (N·m) of the face, summed point by point."""
    force = torque = 0.0
    for _, y, _ in FACE:
        depth = SURFACE - (z + math.sin(roll) * y)
        if depth > 0.0:
            force += K / len(FACE) * depth
            torque += math.cos(roll) * y * K / len(FACE) * depth
    return force, torque


@pytest.mark.parametrize(('press', 'tilt'), [(0.03, math.radians(20.0)),
                                             (0.12, math.radians(-20.0)), (0.03, 0.0)])
def test_the_wand_rests_where_the_hand_balances_the_face(press, tilt):
    target = (0.0, 0.0, SURFACE - press, tilt, 0.0)
    script = WaypointScript([0.0, 1.0], [target, target])
    wand = SimulatedWand(SimulatedWandConfig(initial_position=np.array([0.0, 0.0, SURFACE])),
                         operator=OperatorHand(script))
    wand.render_locally(FaceOnPlane())
    wand.read(0.0)
    state = wand.read(3.0)

    def balance(unknowns):
        z, roll = unknowns
        force, torque = face_on_plane(z, roll)
        return [HAND * (target[2] - z) + force, HAND_ROLL * (tilt - roll) + torque]
    z, roll = fsolve(balance, [SURFACE - 0.002, 0.8 * tilt], xtol=1e-13)
    assert state.position[2] == pytest.approx(z, abs=2e-6)
    assert state.roll == pytest.approx(roll, abs=2e-5)
    if tilt != 0.0:
        assert abs(roll) < abs(tilt)  # the face turns the wand back toward flat
    assert state.yaw == pytest.approx(0.0, abs=1e-12)
