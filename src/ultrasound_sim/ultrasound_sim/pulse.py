"""The point spread function: the axial pulse and the lateral beam, made once per settings.

Axial: the transmitted burst (``cycles`` of a sine at the centre frequency) filtered by the
transducer's pulse-echo response, a Gaussian of -6 dB fractional ``bandwidth``; its complex
envelope, demodulated at the centre frequency and sampled at the echo time between samples, is
the axial kernel. Lateral: an aperture focused at every depth in transmit and receive (as
coherent plane-wave compounding or synthetic aperture gives) at ``f_number``, wider where the
aperture stops growing at the array's size; the two-way beam of a uniform aperture is sinc^2,
whose main lobe the lateral kernel matches with a Gaussian of the same half-amplitude width.
Both are normalised to a peak of 1, so a plane reflector of pressure reflection r shows r.
"""

from dataclasses import dataclass
import math

import numpy as np
from scipy.optimize import brentq

from ultrasound_sim.settings import LINEAR, ProbeSettings

__all__ = ['PointSpread', 'SINC2_HALF_WIDTH', 'axial_pulse', 'lateral_width', 'point_spread']

_OVERSAMPLING = 64  # fine samples per period for the pulse
_TAIL = 1e-3  # taps whose magnitude is below this share of the peak are cut
_GAUSSIAN_FWHM_SIGMAS = 2.0 * math.sqrt(2.0 * math.log(2.0))

SINC2_HALF_WIDTH = brentq(lambda u: np.sinc(u) ** 2 - 0.5, 0.1, 0.9)
"""u where sinc(u)^2 = 1/2: the two-way beam's FWHM is 2 u wavelength f_number (0.886 l F)."""


@dataclass(frozen=True, eq=False)
class PointSpread:
    """The kernels of one settings.

    Attributes
    ----------
    axial : (2 ka + 1,) complex128
        Along a scanline, one tap a sample, peak magnitude 1.
    lateral : (samples, 2 kl + 1) float64
        Across scanlines, one row a sample's depth, peak 1.
    axial_fwhm : float, m
        The pulse's envelope full width at half maximum, in depth.
    lateral_fwhm : (samples,) float64, m
        The beam's, at each sample.
    """

    axial: np.ndarray
    lateral: np.ndarray
    axial_fwhm: float
    lateral_fwhm: np.ndarray


def _envelope_fwhm(envelope: np.ndarray, spacing: float) -> float:
    """Full width at half maximum of a single-peaked profile, interpolated between samples."""
    half = 0.5 * envelope.max()
    above = np.flatnonzero(envelope >= half)
    first, last = above[0], above[-1]
    left = first - (envelope[first] - half) / (envelope[first] - envelope[first - 1])
    right = last + (envelope[last] - half) / (envelope[last] - envelope[last + 1])
    return float((right - left) * spacing)


def axial_pulse(settings: ProbeSettings) -> tuple[np.ndarray, float]:
    """Return the axial kernel (complex taps, one a sample) and its envelope FWHM (m)."""
    fc = settings.centre_frequency
    fine = _OVERSAMPLING * fc
    span = 4.0 * settings.cycles / fc + 16.0 / (settings.bandwidth * fc)  # burst and ringing
    n = int(2 ** math.ceil(math.log2(span * fine)))
    t = (np.arange(n) - n // 2) / fine
    burst = np.where((t >= 0.0) & (t < settings.cycles / fc), np.sin(2.0 * np.pi * fc * t), 0.0)
    f = np.fft.fftfreq(n, 1.0 / fine)
    sigma = 0.5 * settings.bandwidth * fc / math.sqrt(2.0 * math.log(2.0))  # -6 dB half width
    response = np.exp(-0.5 * ((np.abs(f) - fc) / sigma) ** 2)
    # the echo's analytic signal: its spectrum's positive half, doubled
    analytic = np.fft.ifft(np.fft.fft(burst) * response * (1.0 + np.sign(f)))
    baseband = analytic * np.exp(-2j * np.pi * fc * t)
    peak = int(np.argmax(np.abs(baseband)))
    depth_per_fine = 0.5 * settings.speed_of_sound / fine
    fwhm = _envelope_fwhm(np.abs(baseband), depth_per_fine)
    stride = settings.sample_spacing / depth_per_fine  # fine samples a tap
    reach = np.flatnonzero(np.abs(baseband) >= _TAIL * np.abs(baseband[peak]))
    half_taps = int(math.ceil(max(peak - reach[0], reach[-1] - peak) / stride))
    at = peak + stride * np.arange(-half_taps, half_taps + 1)
    inside = (at >= 0) & (at <= n - 1)
    taps = np.zeros(len(at), dtype=np.complex128)
    taps[inside] = (np.interp(at[inside], np.arange(n), baseband.real)
                    + 1j * np.interp(at[inside], np.arange(n), baseband.imag))
    return taps / np.abs(baseband[peak]), fwhm


def lateral_width(settings: ProbeSettings, ranges: np.ndarray) -> np.ndarray:
    """Return the two-way beam's FWHM (m) at each range (m) from the elements."""
    aperture = settings.width if settings.probe_type == LINEAR else \
        2.0 * settings.radius * math.sin(0.5 * settings.angle)
    f_number = np.maximum(settings.f_number, np.asarray(ranges) / aperture)
    return 2.0 * SINC2_HALF_WIDTH * settings.wavelength * f_number


def point_spread(settings: ProbeSettings, line_spacing: np.ndarray) -> PointSpread:
    """Make the kernels of ``settings``, with the lines ``line_spacing`` (samples,) m apart."""
    axial, axial_fwhm = axial_pulse(settings)
    ranges = (np.arange(settings.samples) + 0.5) * settings.sample_spacing
    width = lateral_width(settings, ranges)
    sigma = width / _GAUSSIAN_FWHM_SIGMAS / line_spacing  # in lines
    half_taps = int(math.ceil(3.0 * sigma.max()))
    offsets = np.arange(-half_taps, half_taps + 1)
    lateral = np.exp(-0.5 * (offsets[None, :] / sigma[:, None]) ** 2)
    return PointSpread(axial, lateral, axial_fwhm, width)
