"""Where the scanlines run, and how the image's pixels map onto them (scan conversion).

Both depend on the settings alone, never on the pose, so they are made once per settings. A
linear array's scanlines are parallel, from elements spread evenly across ``width``; a convex
array's fan out over ``angle`` from elements on an arc of ``radius``, normal to it. Positions
are (y, z) in the probe frame's scan plane (``settings``); the image's are (lateral, depth) with
depth = -z, rows going deeper and columns toward +y.
"""

from dataclasses import dataclass
import itertools

import numpy as np

from ultrasound_sim.settings import LINEAR, ProbeSettings

__all__ = ['ImageGeometry', 'ScanConversion', 'ScanGeometry', 'scan_conversion', 'scan_geometry']


@dataclass(frozen=True, eq=False)
class ScanGeometry:
    """The scanlines in the probe frame's scan plane.

    Attributes
    ----------
    origins : (scanlines, 2) float64, m
        Each line's element, (y, z).
    directions : (scanlines, 2) float64
        Each line's unit direction, (y, z), into the patient.
    line_spacing : (samples,) float64, m
        The distance between neighbouring lines at each sample's range (the fan widens).
    """

    origins: np.ndarray
    directions: np.ndarray
    line_spacing: np.ndarray


@dataclass(frozen=True)
class ImageGeometry:
    """Where the image's pixels are, in the probe frame.

    Pixel (row, column) is centred at y = ``lateral_origin`` + column ``pixel_width`` and
    z = -(``depth_origin`` + row ``pixel_height``), x = 0.

    Attributes
    ----------
    width, height : int, px
    pixel_width, pixel_height : float, m
    lateral_origin, depth_origin : float, m
        The centre of pixel (0, 0).
    """

    width: int
    height: int
    pixel_width: float
    pixel_height: float
    lateral_origin: float
    depth_origin: float


@dataclass(frozen=True, eq=False)
class ScanConversion:
    """Each pixel's four neighbouring samples (flattened, row-major).

    ``line_at`` (pixels,) int64 is the lower line (-1: outside the field), ``sample_at`` the
    lower sample; ``line_weight`` and ``sample_weight`` (pixels,) float64 are the bilinear
    weights of the upper ones. ``read`` (scanlines, samples) bool marks the samples some pixel
    reads: a linear probe's image shows every other one of them, and the rest need no grey level.
    """

    geometry: ImageGeometry
    line_at: np.ndarray
    sample_at: np.ndarray
    line_weight: np.ndarray
    sample_weight: np.ndarray
    read: np.ndarray


def _lateral_span(settings: ProbeSettings) -> float:
    """Return the distance between the outermost lines' elements (linear) or their angle."""
    return settings.width if settings.probe_type == LINEAR else settings.angle


def scan_geometry(settings: ProbeSettings) -> ScanGeometry:
    """Place the scanlines of ``settings``."""
    n = settings.scanlines
    ranges = (np.arange(settings.samples) + 0.5) * settings.sample_spacing
    step = _lateral_span(settings) / (n - 1)
    across = -0.5 * _lateral_span(settings) + step * np.arange(n)
    if settings.probe_type == LINEAR:
        origins = np.column_stack((across, np.zeros(n)))
        directions = np.tile([0.0, -1.0], (n, 1))
        spacing = np.full(settings.samples, step)
    else:
        r = settings.radius
        origins = np.column_stack((r * np.sin(across), r * (1.0 - np.cos(across))))
        directions = np.column_stack((np.sin(across), -np.cos(across)))
        spacing = (r + ranges) * step
    return ScanGeometry(origins, directions, spacing)


def _image_box(settings: ProbeSettings) -> tuple[float, float, float, float]:
    """(lateral min, lateral max, depth min, depth max) of the imaged field, m."""
    if settings.probe_type == LINEAR:
        half = 0.5 * settings.width
        return -half, half, 0.0, settings.depth
    half_angle = 0.5 * settings.angle
    reach = settings.radius + settings.depth
    return (-reach * np.sin(half_angle), reach * np.sin(half_angle),
            -settings.radius * (1.0 - np.cos(half_angle)), settings.depth)


def _lower(position: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Split fractional indices into a lower index in [0, count - 2] and the upper's weight."""
    lower = np.clip(np.floor(position), 0, count - 2).astype(np.int64)
    return lower, np.clip(position - lower, 0.0, 1.0)


def scan_conversion(settings: ProbeSettings) -> ScanConversion:
    """Map every pixel of the image onto the scanlines' samples (module docstring)."""
    left, right, top, bottom = (float(edge) for edge in _image_box(settings))
    width, height = settings.image_width, settings.image_height
    pixel_width, pixel_height = (right - left) / width, (bottom - top) / height
    geometry = ImageGeometry(width, height, pixel_width, pixel_height,
                             left + 0.5 * pixel_width, top + 0.5 * pixel_height)
    lateral = geometry.lateral_origin + pixel_width * np.arange(width)
    depth = geometry.depth_origin + pixel_height * np.arange(height)
    y, d = np.meshgrid(lateral, depth)  # (height, width): rows are depths
    step = _lateral_span(settings) / (settings.scanlines - 1)
    if settings.probe_type == LINEAR:
        across, along = y, d
    else:
        across = np.arctan2(y, settings.radius + d)
        along = np.hypot(y, settings.radius + d) - settings.radius
    line = (across + 0.5 * _lateral_span(settings)) / step
    sample = along / settings.sample_spacing - 0.5
    inside = ((line >= -1e-9) & (line <= settings.scanlines - 1 + 1e-9)
              & (along >= 0.0) & (along <= settings.depth))
    line_at, line_weight = _lower(line.ravel(), settings.scanlines)
    sample_at, sample_weight = _lower(sample.ravel(), settings.samples)
    line_at[~inside.ravel()] = -1
    read = np.zeros((settings.scanlines, settings.samples), dtype=bool)
    shown = line_at >= 0
    for lines, samples in itertools.product((0, 1), (0, 1)):
        read[line_at[shown] + lines, sample_at[shown] + samples] = True
    return ScanConversion(geometry, line_at, sample_at, line_weight, sample_weight, read)
