"""From the pose of the tip that holds the probe to its B-mode image: the imaging node's core.

One scene serves the force and the image: its objects' surfaces give the probe's contact face,
point by point (``collision_engine.probe.query_probe``, as the force comes from), which says
which scanlines are coupled to the skin; its ``anatomy:`` section gives what the scanlines see
(``Imager``); its ``tool:`` section gives the probe's mount on the tip (``probe_mount``). A pose
that cannot be imaged (another frame, not finite, a zero quaternion) gives a dark image and the
reason, never an exception: the node publishes it, stamped as the pose, and logs the reason.
A configuration that cannot image at all (no anatomy, no tool, bad settings) raises ValueError
at construction, naming what to fix.
"""

from dataclasses import dataclass
import time

import numpy as np

from collision_engine import load_scene
from collision_engine.probe import query_probe
from ultrasound_sim.anatomy import load_anatomy
from ultrasound_sim.coupling import scanline_coupling
from ultrasound_sim.imager import Imager
from ultrasound_sim.probe_mount import probe_mount
from ultrasound_sim.settings import ProbeSettings

__all__ = ['Imaged', 'ProbeImaging']


@dataclass(frozen=True, eq=False)
class Imaged:
    """One image of the probe, or a dark one and why.

    Attributes
    ----------
    image : (image_height, image_width) uint8
        mono8, rows deeper (``ImageGeometry``).
    reason : str
        Empty for an image of the anatomy; else why the image is dark.
    coupled : int
        How many scanlines touched the skin.
    """

    image: np.ndarray
    reason: str = ''
    coupled: int = 0


def _unit(quaternion) -> np.ndarray:
    """Return the quaternion normalised; raise ValueError naming it unless finite and non-zero."""
    q = np.asarray(quaternion, dtype=np.float64)
    norm = float(np.linalg.norm(q)) if q.shape == (4,) else 0.0
    if not (np.isfinite(norm) and norm > 0.0):
        raise ValueError(f'pose: orientation must be 4 finite numbers, not all zero, got {q}')
    return q / norm


class ProbeImaging:
    """The probe on its tip, over the scene's anatomy (module docstring).

    Parameters
    ----------
    scene : collision_engine.Scene
        With a tool (the probe); the image is taken in its frame.
    imager : Imager
        Of the scene's anatomy.
    frame_id : str
        The frame the poses must be given in: the scene's, where the robot's base is.
    """

    def __init__(self, scene, imager: Imager, frame_id: str) -> None:
        if scene.tool is None:
            raise ValueError('scene: has no tool: the probe\'s mount and contact face come from '
                             'its tool: section (see phantom_anatomy.yaml)')
        self.scene, self.imager, self.frame_id = scene, imager, frame_id
        self.mount = probe_mount(scene.tool)
        geometry = imager.geometry
        self._dark = np.zeros((geometry.height, geometry.width), dtype=np.uint8)
        self._dark.setflags(write=False)

    @classmethod
    def from_scene_file(cls, path, settings: ProbeSettings, frame_id: str) -> 'ProbeImaging':
        """Load the scene (its surfaces, tool and anatomy) once; raise ValueError naming it."""
        return cls(load_scene(path), Imager(load_anatomy(path), settings), frame_id)

    def image(self, frame_id: str, position, quaternion) -> Imaged:
        """Image the anatomy from the tip's pose (``frame_id``, m, quaternion (x, y, z, w))."""
        if frame_id != self.frame_id:
            return Imaged(self._dark, f'pose in frame {frame_id!r}, not {self.frame_id!r}')
        try:
            tip = np.asarray(position, dtype=np.float64)
            if tip.shape != (3,) or not np.all(np.isfinite(tip)):
                raise ValueError(f'pose: position must be 3 finite numbers, got {tip}')
            orientation = _unit(quaternion)
            probe = query_probe(self.scene, tip, orientation)
            coupled = scanline_coupling(self.mount.face, probe.distance, self.imager.settings)
            frame = self.imager.frame(*self.mount.probe_pose(tip, orientation), coupled)
        except ValueError as error:
            return Imaged(self._dark, str(error))
        return Imaged(frame.image, '', int(np.count_nonzero(coupled)))

    def warm_up(self) -> float:
        """Make one frame, so that every kernel is compiled or loaded; return the time it took.

        The first frame of a process otherwise loads them from numba's cache or compiles them
        (a fraction of a second, or tens of seconds), stalling whatever waits on it.
        """
        started = time.perf_counter()
        self.image(self.frame_id, np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
        self.imager.frame(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]),
                          np.ones(self.imager.settings.scanlines, dtype=bool))
        return time.perf_counter() - started
