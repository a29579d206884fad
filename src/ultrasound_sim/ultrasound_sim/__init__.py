"""A simulated B-mode ultrasound image from the probe's pose in the scene's anatomy.

A pure core: numpy, scipy and numba (through the collision engine's one decorator); trimesh
only to build the anatomy's meshes; no ROS. Typical use::

    from ultrasound_sim import Imager, ProbeSettings, load_anatomy, scanline_coupling
    anatomy = load_anatomy('scenes/phantom_anatomy.yaml')   # the scene's inner structures
    imager = Imager(anatomy, ProbeSettings(probe_type='linear', centre_frequency=5e6))
    coupled = scanline_coupling(face_points, face_distance, imager.settings)
    frame = imager.frame(position, quaternion, coupled)     # probe pose, scene frame
    frame.image, frame.geometry                             # mono8 (rows deeper), pixel places
"""

from ultrasound_sim.anatomy import Anatomy, load_anatomy
from ultrasound_sim.coupling import scanline_coupling
from ultrasound_sim.geometry import ImageGeometry
from ultrasound_sim.imager import BModeFrame, Imager
from ultrasound_sim.settings import CONVEX, LINEAR, ProbeSettings

__all__ = ['Anatomy', 'BModeFrame', 'CONVEX', 'ImageGeometry', 'Imager', 'LINEAR',
           'ProbeSettings', 'load_anatomy', 'scanline_coupling']
