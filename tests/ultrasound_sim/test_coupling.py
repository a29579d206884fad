"""Contact makes the image: the collision engine's contact face decides which scanlines see.

The probe is the scenes' box tool (a 10 x 40 mm face at the tip, its long side along y), its
frame the tip's. Truths are geometric: lifted by h the whole face is h off the skin; rolled by
theta about x on a flat slab, the face's point at y is y sin(theta) above it.
"""

import math

from ground_truth.distances import scene_path
import numpy as np
import pytest

from collision_engine import load_scene
from collision_engine.probe import query_probe
from ultrasound_sim import Imager, load_anatomy, ProbeSettings, scanline_coupling

SLAB_TOP = -0.025  # m: probe_flat.yaml's and the phantom's front at x = y = 0


def roll(theta: float) -> np.ndarray:
    return np.array([math.sin(0.5 * theta), 0.0, 0.0, math.cos(0.5 * theta)])


@pytest.fixture(scope='module')
def phantom():
    path = scene_path('phantom_anatomy')
    return load_scene(path), Imager(load_anatomy(path), ProbeSettings())


def frame_at(phantom, position, quaternion):
    scene, imager = phantom
    probe = query_probe(scene, position, quaternion)
    coupled = scanline_coupling(scene.tool.face, probe.distance, imager.settings)
    return imager.frame(position, quaternion, coupled)


def test_a_lifted_probe_sees_nothing_and_a_pressed_one_sees(phantom):
    upright = roll(0.0)
    lifted = frame_at(phantom, np.array([0.0, 0.0, SLAB_TOP + 0.001]), upright)
    pressed = frame_at(phantom, np.array([0.0, 0.0, SLAB_TOP - 0.002]), upright)
    print(f'lifted 1 mm: {lifted.coupled.sum()} lines coupled, brightest pixel '
          f'{lifted.image.max()}; pressed 2 mm: {pressed.coupled.sum()} coupled, mean pixel '
          f'{pressed.image.mean():.1f}')
    assert not lifted.coupled.any() and lifted.image.max() == 0 and lifted.envelope.max() == 0
    assert pressed.coupled.all() and pressed.image.mean() > 10.0


def test_half_the_face_touching_darkens_half_the_scanlines(tmp_path):
    # probe_flat.yaml's slab, given an anatomy of its own (the slab as tissue).
    text = scene_path('probe_flat').read_text() + (
        'anatomy:\n'
        '  media:\n'
        '    tissue: {speed_of_sound: 1540.0, impedance: 1.63e+6, attenuation: 0.5,\n'
        '             scatterer_density: 100.0, scatterer_amplitude: 0.003}\n'
        '  structures:\n'
        '    - {name: slab, object: slab, medium: tissue}\n')
    path = tmp_path / 'slab.yaml'
    path.write_text(text)
    settings = ProbeSettings(gain=30.0)
    scene, imager = load_scene(path), Imager(load_anatomy(path), settings)
    theta = math.radians(5.0)
    frame = frame_at((scene, imager), np.array([0.0, 0.0, SLAB_TOP]), roll(theta))
    elements = np.linspace(-0.5 * settings.width, 0.5 * settings.width, settings.scanlines)
    expected = elements * math.sin(theta) <= settings.coupling_gap
    dark = frame.envelope.max(axis=1) == 0.0
    print(f'rolled {math.degrees(theta):g} deg: {dark.sum()} of {settings.scanlines} lines '
          f'dark, {np.count_nonzero(~expected)} expected')
    assert np.count_nonzero(frame.coupled != expected) <= 1
    assert np.array_equal(dark, ~frame.coupled)
    assert abs(dark.sum() - settings.scanlines / 2) <= 0.05 * settings.scanlines
    # In the image too: dark beyond the last coupled element, past one line of interpolation.
    geometry = frame.geometry
    lateral = geometry.lateral_origin + geometry.pixel_width * np.arange(geometry.width)
    boundary, spacing = settings.coupling_gap / math.sin(theta), elements[1] - elements[0]
    columns = frame.image.max(axis=0)
    assert columns[lateral < boundary - spacing].min() > 0
    assert columns[lateral > boundary + spacing].max() == 0


def test_coupling_interpolates_the_face_and_extends_past_it():
    settings = ProbeSettings(coupling_gap=0.0)
    # Two columns of a flat face at y = -/+ 10 mm, the skin sloping: 0 m at -10, 2 mm at +10.
    face = np.array([[-0.002, -0.01, 0.0], [0.002, -0.01, 0.0],
                     [-0.002, 0.01, 0.0], [0.002, 0.01, 0.0]])
    coupled = scanline_coupling(face, [-0.001, 0.0, 0.001, 0.003], settings)
    elements = np.linspace(-0.5 * settings.width, 0.5 * settings.width, settings.scanlines)
    # The nearest of each column (-1 mm and +1 mm), linear along y: zero at y = 0.
    np.testing.assert_array_equal(coupled, elements <= 0.0)


@pytest.mark.parametrize('points, distances, message', [
    (np.zeros((3, 3)), np.zeros(2), 'face_points must be'),
    (np.zeros((3, 2)), np.zeros(3), 'face_points must be'),
    (np.full((3, 3), np.nan), np.zeros(3), 'face_points: must be finite'),
])
def test_bad_faces_are_refused(points, distances, message):
    with pytest.raises(ValueError, match=message):
        scanline_coupling(points, distances, ProbeSettings())


def test_a_face_with_unknown_distances_is_uncoupled():
    face = np.array([[0.0, -0.01, 0.0], [0.0, 0.01, 0.0]])
    assert not scanline_coupling(face, [np.nan, np.nan], ProbeSettings()).any()
