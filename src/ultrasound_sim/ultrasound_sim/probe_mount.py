"""Where the probe images from: its frame on the tip that holds it, and its contact face there.

The scene's ``tool:`` section mounts the probe on the tip (the robot's TCP, or the wand's tip):
its ``offset`` is the tool's frame in the tip's, and the collision engine measures the tool's
contact face, its -z side, in the tip frame (``collision_engine.tool.MountedTool``). The image's
probe frame (``ultrasound_sim.settings``) has the tool frame's axes, the array along y and the
beams along -z, and its origin at the centre of that face: the face points' centroid, moved out
by a round tool's radius. With the shipped box probe (its face at the tip, no rotation) the probe
frame is the tip frame.
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ['ProbeMount', 'probe_mount']


@dataclass(frozen=True, eq=False)
class ProbeMount:
    """The probe frame in the tip frame, and the contact face in the probe frame.

    Attributes
    ----------
    origin : (3,) float64, m, tip frame
        The centre of the probe's face.
    rotation : scipy Rotation
        The probe frame's axes in the tip frame.
    face : (n, 3) float64, m, probe frame
        The contact face's points, as ``scanline_coupling`` takes them.
    """

    origin: np.ndarray
    rotation: Rotation
    face: np.ndarray

    def probe_pose(self, tip_position, tip_quaternion) -> tuple:
        """Return the probe frame's (position, quaternion (x, y, z, w)) from the tip's pose.

        Both in the scene frame; the tip's quaternion must be of unit norm.
        """
        tip = Rotation.from_quat(tip_quaternion)
        position = np.asarray(tip_position, dtype=np.float64) + tip.apply(self.origin)
        return position, (tip * self.rotation).as_quat(canonical=False)


def probe_mount(tool) -> ProbeMount:
    """Return the probe's mount from the scene's mounted tool (``Scene.tool``)."""
    rotation = Rotation.from_quat(tool.offset_quaternion)
    outward = rotation.apply([0.0, 0.0, -1.0])  # the face's outward normal, tip frame
    origin = np.mean(tool.face, axis=0) + tool.radius * outward
    face = rotation.inv().apply(np.asarray(tool.face) - origin)
    return ProbeMount(origin, rotation, np.atleast_2d(face))
