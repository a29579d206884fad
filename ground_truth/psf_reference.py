"""A point target's resolution: SIMUS's (PyMUST) and the model's, measured the same way.

SIMUS (D. Garcia, "SIMUS: an open-source simulator for medical ultrasound imaging", Comput.
Methods Programs Biomed. 218:106726, 2022) simulates the RF echoes of one point scatterer on a
Verasonics probe of its ``getparam``; they are demodulated (``rf2iq``) and beamformed by delay
and sum (``dasmtx``) at the receive f-number, from plane waves steered over the same f-number's
angles (+-atan(1 / 2F)) and summed coherently: transmit and receive are both focused at every
depth, the beam the model assumes. The model images a thin wire across the scan plane (the
in-plane point target of resolution phantoms). Widths are the envelope's full width at half
maximum along depth and across, through the peak, interpolated between samples.
"""

import math

from ground_truth.imaging_scenes import block_scene, HALF_TURN_Y, TOP
import numpy as np

from ultrasound_sim import Imager, load_anatomy, ProbeSettings

__all__ = ['PROBES', 'fwhm', 'model_psf', 'simus_psf']

PROBES = ('L11-5v', 'L12-3v')
"""SIMUS's linear arrays (``pymust.getparam``)."""

_ANGLES = 15  # plane waves compounded
_SPEED = 1540.0  # m/s
_STEP = 5e-6  # m between beamformed points
_WIRE_RADIUS = 1e-5  # m


def fwhm(profile: np.ndarray, spacing: float) -> float:
    """Full width at half maximum of a single-peaked profile (m), interpolated."""
    profile = np.abs(np.asarray(profile))
    peak = int(np.argmax(profile))
    half = 0.5 * profile[peak]
    left = peak
    while left > 0 and profile[left - 1] >= half:
        left -= 1
    right = peak
    while right < len(profile) - 1 and profile[right + 1] >= half:
        right += 1
    if left == 0 or right == len(profile) - 1:
        raise ValueError('the profile does not fall to half its peak on both sides')
    a = left - (profile[left] - half) / (profile[left] - profile[left - 1])
    b = right + (profile[right] - half) / (profile[right] - profile[right + 1])
    return float((b - a) * spacing)


def simus_psf(probe: str, *, cycles: float, f_number: float, depth: float) -> dict:
    """Simulate a point target at ``depth`` below the array's centre: probe and widths (m)."""
    import pymust

    param = pymust.getparam(probe)
    param.c = _SPEED
    param.fs = 4.0 * param.fc
    param.TXnow = cycles
    param.fnumber = f_number
    reach = math.atan(1.0 / (2.0 * f_number))
    along = depth + np.arange(-300, 301) * _STEP
    across = np.arange(-400, 401) * _STEP
    axial, lateral = 0j, 0j
    for angle in np.linspace(-reach, reach, _ANGLES):
        delays = pymust.txdelay(param, float(angle))
        rf, _ = pymust.simus(np.array([0.0]), np.array([depth]), np.array([1.0]), delays, param)
        iq = pymust.rf2iq(rf, param).flatten(order='F')
        shape = 1j * np.array(rf.shape)
        axial = axial + pymust.dasmtx(shape, np.zeros_like(along), along, delays, param) @ iq
        lateral = lateral + pymust.dasmtx(shape, across, np.full_like(across, depth), delays,
                                          param) @ iq
    return {'fc': float(param.fc), 'bandwidth': float(param.bandwidth) / 100.0,
            'aperture': float(param.Nelements * param.pitch),
            'axial': fwhm(axial, _STEP), 'lateral': fwhm(lateral, _STEP)}


def model_psf(folder, *, centre_frequency: float, bandwidth: float, aperture: float,
              cycles: float, f_number: float, depth: float) -> dict:
    """Image a thin wire at ``depth`` below the face's centre with the model: widths (m)."""
    structures = f"""\
        - name: wire
          shape: {{cylinder: {{radius: {_WIRE_RADIUS:.6f}, height: 0.1}}}}
          pose: {{position: [0.0, 0.0, {-depth + TOP!r}], rpy: {HALF_TURN_Y}}}
          medium: denser
        """
    lines = 1025  # lines 37.5 um apart across the aperture, the middle one on the wire
    settings = ProbeSettings(centre_frequency=centre_frequency, bandwidth=bandwidth,
                             cycles=cycles, f_number=f_number, width=aperture,
                             depth=depth + 0.004, samples=2048, scanlines=lines,
                             image_width=lines)
    imager = Imager(load_anatomy(block_scene(folder, 'silent', structures)), settings)
    frame = imager.frame(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]), np.ones(lines, bool))
    envelope = frame.envelope.astype(np.float64)
    line, sample = np.unravel_index(np.argmax(envelope), envelope.shape)
    spacing = aperture / (lines - 1)
    return {'axial': fwhm(envelope[line], settings.sample_spacing),
            'lateral': fwhm(envelope[:, sample], spacing)}
