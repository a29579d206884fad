"""The image against truths that share no code with the model.

Each truth is analytic: where an interface must appear (echo time at the scanner's speed of
sound), a vessel's radius, the Rayleigh statistics of fully developed speckle (mean over standard
deviation sqrt(pi / (4 - pi)) = 1.91), the two-way attenuation 2 alpha f dB/cm, a shadow under
bone. One axial resolution cell is half the pulse length, c N / (2 f) (N the burst's cycles).
Levels are read back from the mono8 image the way a user reads them: grey level times the
dynamic range over 255.
"""

import math

from ground_truth.imaging_scenes import block_scene, HALF_TURN_Y, straight_down, TOP
import numpy as np
import pytest
from scipy import ndimage

from ultrasound_sim import Imager, load_anatomy, ProbeSettings

RAYLEIGH_MEAN_OVER_STD = math.sqrt(math.pi / (4.0 - math.pi))  # 1.913


def axial_cell(settings: ProbeSettings) -> float:
    """Half the pulse length, m."""
    return settings.speed_of_sound * settings.cycles / (2.0 * settings.centre_frequency)


def image_of(path, settings, position=None, quaternion=None):
    imager = Imager(load_anatomy(path), settings)
    down = straight_down()
    position = down[0] if position is None else position
    quaternion = down[1] if quaternion is None else quaternion
    frame = imager.frame(position, quaternion, np.ones(settings.scanlines, dtype=bool))
    return frame


def decibels(frame, settings) -> np.ndarray:
    """The image's grey levels as echo levels, dB (0: a perfect reflector at the face)."""
    return frame.image.astype(np.float64) * settings.dynamic_range / 255.0 \
        - settings.dynamic_range - settings.gain


def denser_below(depth: float) -> str:
    """Return a structure filling everything deeper than ``depth`` with the denser medium."""
    return f"""\
        - name: below
          shape: {{box: {{size: [0.2, 0.2, 0.1]}}}}
          pose: {{position: [0.0, 0.0, {-depth - 0.05!r}]}}
          medium: denser
        """


def rows_depth(geometry) -> np.ndarray:
    return geometry.depth_origin + geometry.pixel_height * np.arange(geometry.height)


def columns_lateral(geometry) -> np.ndarray:
    return geometry.lateral_origin + geometry.pixel_width * np.arange(geometry.width)


@pytest.mark.parametrize('speed', [1540.0, 1450.0])
def test_a_flat_interface_appears_at_its_depth(tmp_path, speed):
    # Silent above 20 mm, a denser medium below: the one echo is the interface's. At a speed
    # of sound other than the scanner's, it appears where its echo time says: d c0 / c.
    depth = 0.02
    path = block_scene(tmp_path, 'upper', denser_below(depth),
                       media={'upper': (speed, 1.5e6, 0.0, 0.0, 0.0)})
    settings = ProbeSettings(depth=0.04, image_width=256, image_height=512, gain=0.0)
    frame = image_of(path, settings)
    assert frame.image.max() < 255  # the echo's peak is not clipped
    profile = frame.image.astype(float).mean(axis=1)
    seen = rows_depth(frame.geometry)[np.argmax(profile)]
    expected = (depth + TOP) * settings.speed_of_sound / speed
    print(f'interface: expected {expected * 1e3:.3f} mm, seen {seen * 1e3:.3f} mm, '
          f'cell {axial_cell(settings) * 1e3:.3f} mm')
    assert abs(seen - expected) <= axial_cell(settings)


def test_a_convex_probe_shows_a_flat_interface_flat(tmp_path):
    # Scan conversion of a fan: every column in the sector finds the plane at the same depth.
    depth = 0.03
    path = block_scene(tmp_path, 'silent', denser_below(depth))
    settings = ProbeSettings(probe_type='convex', centre_frequency=3.5e6, depth=0.05,
                             radius=0.05, angle=math.radians(40.0), gain=0.0)
    frame = image_of(path, settings)
    assert frame.image.max() < 255
    lateral = columns_lateral(frame.geometry)
    # Columns whose whole path to the plane is in the sector, away from its edges.
    inner = np.abs(lateral) < 0.6 * (settings.radius + depth) * math.sin(0.5 * settings.angle)
    seen = rows_depth(frame.geometry)[np.argmax(frame.image[:, inner], axis=0)]
    error = np.abs(seen - (depth + TOP))
    print(f'convex interface: {inner.sum()} columns, worst {error.max() * 1e3:.3f} mm off, '
          f'cell {axial_cell(settings) * 1e3:.3f} mm')
    assert error.max() <= axial_cell(settings)


def test_a_vessel_is_a_dark_disc_of_its_radius(tmp_path):
    radius, depth, lateral = 0.004, 0.02, 0.003
    structures = f"""\
        - name: vessel
          shape: {{cylinder: {{radius: {radius!r}, height: 0.1}}}}
          pose: {{position: [0.0, {lateral!r}, {-depth!r}], rpy: {HALF_TURN_Y}}}
          medium: blood
        """
    path = block_scene(tmp_path, 'tissue', structures)
    settings = ProbeSettings(depth=0.04, width=0.0384, scanlines=256, samples=512,
                             image_width=256, image_height=256, gain=20.0, dynamic_range=90.0)
    frame = image_of(path, settings)
    assert np.mean(frame.image == 255) < 0.001  # the tissue's speckle is not clipped
    # The edge of a blurred disc is where the echo amplitude is half the tissue's.
    amplitude = ndimage.uniform_filter(10.0 ** (decibels(frame, settings) / 20.0), size=5)
    y, d = np.meshgrid(columns_lateral(frame.geometry), rows_depth(frame.geometry))
    r = np.hypot(y - lateral, d - depth)
    tissue = np.median(amplitude[(r > radius + 0.002) & (r < radius + 0.004)])
    lumen = np.median(amplitude[r < 0.5 * radius])
    labels, _ = ndimage.label(amplitude < 0.5 * (tissue + lumen))
    centre = labels[np.unravel_index(np.argmin(r), r.shape)]
    area = np.count_nonzero(labels == centre) * frame.geometry.pixel_width \
        * frame.geometry.pixel_height
    seen = math.sqrt(area / math.pi)
    contrast = 20.0 * math.log10(tissue / lumen)
    print(f'vessel: radius {radius * 1e3:.3f} mm, seen {seen * 1e3:.3f} mm, lumen {contrast:.1f} '
          f'dB under the tissue, cell {axial_cell(settings) * 1e3:.3f} mm')
    assert contrast > 20.0
    assert abs(seen - radius) <= axial_cell(settings)


def test_fully_developed_speckle_is_rayleigh(tmp_path):
    settings = ProbeSettings(depth=0.04)
    frame = image_of(block_scene(tmp_path, 'tissue'), settings)
    envelope = frame.envelope[8:-8, 32:-32].astype(np.float64)  # whole kernels only
    ratio = envelope.mean() / envelope.std()
    print(f'speckle: mean / std {ratio:.3f} (Rayleigh {RAYLEIGH_MEAN_OVER_STD:.3f}) over '
          f'{envelope.size} samples')
    assert ratio == pytest.approx(RAYLEIGH_MEAN_OVER_STD, rel=0.1)


@pytest.mark.parametrize('frequency, attenuation', [(5.0e6, 0.5), (3.0e6, 0.7)])
def test_brightness_falls_with_depth_at_two_alpha_f(tmp_path, frequency, attenuation):
    path = block_scene(tmp_path, 'lossy',
                       media={'lossy': (1540.0, 1.63e6, attenuation, 100.0, 0.003)})
    settings = ProbeSettings(centre_frequency=frequency, depth=0.06, gain=20.0,
                             dynamic_range=120.0)
    frame = image_of(path, settings)
    depth = rows_depth(frame.geometry)
    band = (depth > 0.005) & (depth < 0.055)
    levels = frame.image[band]
    assert 0 < levels.min() and levels.max() < 255  # nothing clipped: the levels are the echo's
    mean = decibels(frame, settings)[band].mean(axis=1)
    slope = np.polyfit(depth[band] * 100.0, mean, 1)[0]  # dB/cm
    expected = -2.0 * attenuation * frequency / 1e6
    print(f'attenuation at {frequency / 1e6:g} MHz: {slope:.3f} dB/cm, 2 alpha f = '
          f'{-expected:.3f}')
    assert slope == pytest.approx(expected, rel=0.1)


def test_a_rib_shadows_what_lies_behind_it(tmp_path):
    rib_at, radius = -0.008, 0.004
    structures = f"""\
        - name: rib
          shape: {{cylinder: {{radius: {radius!r}, height: 0.1}}}}
          pose: {{position: [0.0, {rib_at!r}, -0.012], rpy: {HALF_TURN_Y}}}
          medium: bone
        """
    path = block_scene(tmp_path, 'muscle', structures)
    settings = ProbeSettings(depth=0.04, gain=30.0, dynamic_range=100.0,
                             tgc=(0.0, 20.0, 40.0))
    frame = image_of(path, settings)
    levels = decibels(frame, settings)
    y, d = np.meshgrid(columns_lateral(frame.geometry), rows_depth(frame.geometry))
    deep = (d > 0.022) & (d < 0.035)
    behind = levels[deep & (np.abs(y - rib_at) < 0.5 * radius)].mean()
    beside = levels[deep & (np.abs(y + rib_at) < 0.5 * radius)].mean()
    print(f'shadow: behind the rib {behind:.1f} dB, beside it {beside:.1f} dB: '
          f'{beside - behind:.1f} dB darker (the floor is {-settings.dynamic_range:g} dB)')
    assert beside - behind >= 20.0


def test_fluid_enhances_what_lies_behind_it(tmp_path):
    # Less attenuation in the cyst than in the tissue beside it: brighter below it.
    structures = """\
        - name: cyst
          shape: {sphere: {radius: 0.005}}
          pose: {position: [0.0, -0.008, -0.015]}
          medium: fluid
        """
    path = block_scene(tmp_path, 'muscle', structures,
                       media={'fluid': (1480.0, 1.48e6, 0.0022, 0.0, 0.0)})
    settings = ProbeSettings(depth=0.04, gain=30.0, dynamic_range=100.0)
    levels = decibels(frame := image_of(path, settings), settings)
    y, d = np.meshgrid(columns_lateral(frame.geometry), rows_depth(frame.geometry))
    deep = (d > 0.024) & (d < 0.034)
    behind = levels[deep & (np.abs(y + 0.008) < 0.002)].mean()
    beside = levels[deep & (np.abs(y - 0.008) < 0.002)].mean()
    # Two-way through 10 mm of fluid instead of muscle: 2 (1.09 - 0.0022) 5 MHz 1 cm = 10.9 dB,
    # less what the cyst's two walls reflect.
    print(f'enhancement: behind the cyst {behind - beside:.1f} dB brighter')
    assert behind - beside > 6.0


def test_speckle_is_fixed_to_the_tissue_not_to_the_probe(tmp_path):
    # Slide the probe by whole line spacings along y, and push it down by whole samples: the
    # same tissue points fall on other lines and samples, so the speckle moves by as many.
    settings = ProbeSettings(depth=0.03, scanlines=128, samples=512)
    imager = Imager(load_anatomy(block_scene(tmp_path, 'tissue')), settings)
    spacing = settings.width / (settings.scanlines - 1)
    lines, samples = 6, 20
    position, quaternion = straight_down()
    coupled = np.ones(settings.scanlines, dtype=bool)
    first = imager.frame(position, quaternion, coupled).envelope
    moved = imager.frame(position + [0.0, lines * spacing, -samples * settings.sample_spacing],
                         quaternion, coupled).envelope
    # Away from the edges, where the lateral kernel is whole, and past the press's first mm.
    kept = first[lines + 8:-8, samples + 16:-16]
    seen = moved[8:-lines - 8, 16:-samples - 16]
    shifted = np.corrcoef(kept.ravel(), seen.ravel())[0, 1]
    fixed_to_probe = np.corrcoef(first[8:-8, 16:-16].ravel(), moved[8:-8, 16:-16].ravel())[0, 1]
    print(f'speckle after the move: {shifted:.4f} correlated with the tissue-shifted frame, '
          f'{fixed_to_probe:.4f} with the unshifted one')
    assert shifted > 0.99 and fixed_to_probe < 0.2
