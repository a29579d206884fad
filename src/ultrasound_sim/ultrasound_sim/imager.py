"""A B-mode frame from the probe's pose: the model's one entry point.

``Imager(anatomy, settings)`` makes once what does not depend on the pose: the scanlines, the
point spread function, the time-gain curve, the scan conversion's lookup, the scatterer field's
table and the work arrays. ``Imager.frame(position, quaternion, coupled)`` then makes a frame
with four compiled calls (``_kernels``): cut the anatomy by the scan plane, trace every coupled
scanline through the cut (attenuation, interfaces, scatterers), apply the point spread and
detect the envelope, log-compress and scan-convert.

The scatterer field is fully developed speckle: complex Gaussian, its mean intensity per medium
a^2 density times the nominal resolution cell (axial FWHM x lateral FWHM at ``f_number`` x
``slice_thickness``), so that the resolution cell holds that many scatterers on average. It is
a hashed grid fixed to the scene frame, interpolated between its nodes, of one sample's spacing:
the speckle moves with the tissue as the probe slides, and changes as it leaves the slice.
Straight rays: no refraction, no multiple reflections, and the tissue is not compressed under
the probe (a pressed face images from where it is).
"""

from dataclasses import dataclass
import math

import numpy as np

from ultrasound_sim import _kernels
from ultrasound_sim.anatomy import Anatomy
from ultrasound_sim.geometry import ImageGeometry, scan_conversion, scan_geometry
from ultrasound_sim.pulse import lateral_width, point_spread
from ultrasound_sim.settings import ProbeSettings

__all__ = ['BModeFrame', 'Imager']

_NOISE_SEED = 20130801  # the scatterer field is the same in every run
_NOISE_SIZE = 1 << 12  # as _kernels._NOISE_MASK and _AXIS_MASK
_HIT_CAPACITY = 256  # crossings of one scanline with the cut anatomy
_PER_MM3 = 1e9  # per m^3
_DB_PER_CM_MHZ = 100.0 / 1e6  # dB/(cm MHz) times Hz gives dB/m


@dataclass(frozen=True, eq=False)
class BModeFrame:
    """One frame.

    Attributes
    ----------
    image : (image_height, image_width) uint8
        mono8: rows go deeper, columns toward the probe frame's +y (``geometry``).
    geometry : ImageGeometry
        Where the pixels are, in the probe frame.
    envelope : (scanlines, samples) float32
        The detected echo amplitude before gain, TGC and compression (1: a perfect reflector
        at the face); 0 on uncoupled lines.
    coupled : (scanlines,) bool
    """

    image: np.ndarray
    geometry: ImageGeometry
    envelope: np.ndarray
    coupled: np.ndarray


def _unit_quaternion(quaternion) -> np.ndarray:
    q = np.asarray(quaternion, dtype=np.float64)
    if q.shape != (4,) or not np.all(np.isfinite(q)):
        raise ValueError(f'pose: quaternion must be 4 finite numbers (x, y, z, w), got {q}')
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > 1e-6:
        raise ValueError(f'pose: quaternion must have unit norm, got {norm:.9g}')
    return q / norm


def _rotation(q: np.ndarray) -> np.ndarray:
    x, y, z, w = q
    return np.array([
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
        [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
        [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)]])


class Imager:
    """Frames of one anatomy with one probe and settings (module docstring).

    Parameters
    ----------
    anatomy : Anatomy
    settings : ProbeSettings
    """

    def __init__(self, anatomy: Anatomy, settings: ProbeSettings) -> None:
        if not isinstance(anatomy, Anatomy):
            raise ValueError(f'anatomy: must be an Anatomy (load_anatomy), got {anatomy!r}')
        if not isinstance(settings, ProbeSettings):
            raise ValueError(f'settings: must be ProbeSettings, got {settings!r}')
        self.anatomy = anatomy
        self.settings = settings
        self.scan = scan_geometry(settings)
        self.psf = point_spread(settings, self.scan.line_spacing)
        self.conversion = scan_conversion(settings)
        ranges = (np.arange(settings.samples) + 0.5) * settings.sample_spacing
        self._gain = settings.gain + np.interp(
            ranges, np.linspace(0.0, settings.depth, len(settings.tgc)), settings.tgc)
        self._media = self._media_table(anatomy.media, settings)
        nominal_cell = (self.psf.axial_fwhm * lateral_width(settings, [0.0])[0]
                        * settings.slice_thickness)
        energy = (np.sum(np.abs(self.psf.axial) ** 2) * np.sum(self.psf.lateral ** 2, axis=1))
        self._scatter_gain = np.sqrt(nominal_cell * _PER_MM3 / energy)
        rng = np.random.default_rng(_NOISE_SEED)
        noise = rng.standard_normal((_NOISE_SIZE, 2))
        self._noise = (noise[:, 0] + 1j * noise[:, 1]) / math.sqrt(2.0)
        self._keys = rng.integers(0, 2 ** 62, (3, _NOISE_SIZE), dtype=np.int64)
        self._voxel = settings.sample_spacing
        self._lateral = np.ascontiguousarray(self.psf.lateral.T)  # taps by depth, as the kernel
        shape = (settings.scanlines, settings.samples)
        self._segments = np.empty((len(anatomy.triangles), 4))
        self._segment_owner = np.empty(len(anatomy.triangles), dtype=np.int64)
        self._hit_t = np.empty(_HIT_CAPACITY)
        self._hit_owner = np.empty(_HIT_CAPACITY, dtype=np.int64)
        self._inside = np.empty(len(anatomy.names), dtype=np.int64)
        self._field = np.empty(shape, dtype=np.complex128)
        self._work = np.empty((2, *shape))
        self._levels = np.empty(shape)

    @staticmethod
    def _media_table(media: np.ndarray, settings: ProbeSettings) -> np.ndarray:
        """Media in the kernels' units: attenuation in dB/m at the centre frequency."""
        table = np.array(media, dtype=np.float64, copy=True)
        table[:, 2] *= _DB_PER_CM_MHZ * settings.centre_frequency
        return table

    @property
    def geometry(self) -> ImageGeometry:
        """Where the image's pixels are, in the probe frame."""
        return self.conversion.geometry

    def frame(self, position, quaternion, coupled) -> BModeFrame:
        """Image the anatomy from a probe pose.

        Parameters
        ----------
        position : (3,) float, m, scene frame
            The probe frame's origin (``settings``).
        quaternion : (4,) float
            Its orientation in the scene frame, (x, y, z, w), unit.
        coupled : (scanlines,) bool
            Which scanlines touch the skin (``scanline_coupling``); the others stay black.

        Returns
        -------
        BModeFrame

        Raises
        ------
        ValueError
            Naming ``pose`` for a position or quaternion that is not finite, or not of unit
            norm; ``coupled`` for a mask of the wrong shape.
        """
        p = np.asarray(position, dtype=np.float64)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ValueError(f'pose: position must be 3 finite numbers (m), got {p}')
        rotation = _rotation(_unit_quaternion(quaternion))
        mask = np.asarray(coupled)
        if mask.shape != (self.settings.scanlines,) or mask.dtype != np.bool_:
            raise ValueError(f'coupled: must be ({self.settings.scanlines},) bool, got '
                             f'{mask.shape} {mask.dtype}')
        anatomy, settings = self.anatomy, self.settings
        count = _kernels.section(anatomy.vertices, anatomy.triangles, anatomy.owner, rotation, p,
                                 self._segments, self._segment_owner)
        _kernels.trace_lines(
            self._segments, self._segment_owner, count, self.scan.origins, self.scan.directions,
            mask, anatomy.structure_medium, self._media,
            settings.sample_spacing / settings.speed_of_sound, settings.speed_of_sound,
            settings.centre_frequency, rotation, p, self._voxel, self._noise, self._keys,
            self._scatter_gain, self._field, self._hit_t, self._hit_owner, self._inside)
        envelope = np.empty((settings.scanlines, settings.samples), dtype=np.float32)
        _kernels.point_spread(self._field, mask, self.psf.axial, self._lateral, self._work,
                              envelope)
        geometry = self.conversion.geometry
        image = np.empty((geometry.height, geometry.width), dtype=np.uint8)
        conversion = self.conversion
        _kernels.display(envelope, mask, self._gain, settings.dynamic_range, self._levels,
                         conversion.read, conversion.line_at, conversion.sample_at,
                         conversion.line_weight, conversion.sample_weight, image)
        return BModeFrame(image, geometry, envelope, mask.copy())
