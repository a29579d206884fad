"""The imaging node's core: from the tip's pose to a frame, or a dark one and why.

The scene is the shipped phantom with its anatomy and box probe (the probe frame is the tip
frame). Truths: the probe's face is at the tip; lifted 1 mm off the skin it touches nothing;
pressed 3 mm in, every scanline is coupled and the tissue shows.
"""

from dataclasses import fields
import math

from ground_truth.distances import scene_path
from ground_truth.imaging_scenes import block_scene
import numpy as np
import pytest

from collision_engine.tool import MountedTool
from ultrasound_sim.params import ProbeImagerParams
from ultrasound_sim.probe_imaging import ProbeImaging
from ultrasound_sim.probe_mount import probe_mount
from ultrasound_sim.settings import ProbeSettings

SKIN = -0.025  # m: the phantom's front at x = y = 0
UPRIGHT = np.array([0.0, 0.0, 0.0, 1.0])


@pytest.fixture(scope='module')
def imaging():
    return ProbeImaging.from_scene_file(scene_path('phantom_anatomy'), ProbeSettings(),
                                        'base_link')


def test_pressed_the_tissue_shows_lifted_the_frame_is_dark(imaging):
    pressed = imaging.image('base_link', [0.0, 0.0, SKIN - 0.003], UPRIGHT)
    lifted = imaging.image('base_link', [0.0, 0.0, SKIN + 0.001], UPRIGHT)
    assert pressed.reason == '' and pressed.coupled == imaging.imager.settings.scanlines
    assert pressed.image.shape == (256, 256) and pressed.image.dtype == np.uint8
    assert pressed.image.mean() > 20.0
    assert lifted.reason == '' and lifted.coupled == 0 and not lifted.image.any()


@pytest.mark.parametrize('frame_id, position, quaternion, words', [
    ('world', [0.0, 0.0, SKIN], UPRIGHT, ["'world'", "'base_link'"]),
    ('base_link', [math.nan, 0.0, SKIN], UPRIGHT, ['position', 'finite']),
    ('base_link', [0.0, 0.0], UPRIGHT, ['position', '3']),
    ('base_link', [0.0, 0.0, SKIN], [0.0, 0.0, 0.0, 0.0], ['orientation', 'not all zero']),
    ('base_link', [0.0, 0.0, SKIN], [0.0, math.inf, 0.0, 1.0], ['orientation', 'finite']),
])
def test_a_pose_that_cannot_be_imaged_gives_a_dark_frame_and_why(imaging, frame_id, position,
                                                                 quaternion, words):
    imaged = imaging.image(frame_id, position, quaternion)
    assert not imaged.image.any() and imaged.image.shape == (256, 256)
    for word in words:
        assert word in imaged.reason


def test_an_unnormalised_quaternion_is_normalised(imaging):
    pressed = imaging.image('base_link', [0.0, 0.0, SKIN - 0.003], 2.0 * UPRIGHT)
    assert pressed.reason == '' and pressed.coupled == imaging.imager.settings.scanlines


def test_a_scene_without_anatomy_or_without_a_probe_is_refused_by_name(tmp_path):
    with pytest.raises(ValueError, match='no acoustic properties'):
        ProbeImaging.from_scene_file(scene_path('probe_phantom'), ProbeSettings(), 'base_link')
    with pytest.raises(ValueError, match="no tool: the probe's mount"):
        ProbeImaging.from_scene_file(block_scene(tmp_path, 'tissue'), ProbeSettings(),
                                     'base_link')


def test_every_probe_setting_is_a_parameter_and_checked():
    names = {field.name for field in fields(ProbeImagerParams)}
    assert {field.name for field in fields(ProbeSettings)} <= names
    assert ProbeImagerParams().settings() == ProbeSettings()
    for bad, field in (({'probe_type': 'phased'}, 'probe_type'), ({'depth': 0.0}, 'depth'),
                       ({'scanlines': 300}, 'scanlines')):
        with pytest.raises(ValueError, match=f'^{field} '):
            ProbeImagerParams(**bad).settings()


def _tool(quaternion, face, radius=0.0) -> MountedTool:
    return MountedTool(None, None, tuple(quaternion), np.asarray(face, dtype=float), radius)


def test_the_probe_frame_is_at_the_face_centre_with_the_tool_axes():
    # A face 40 mm long along the tool's y, 30 mm below the tip; the tool yawed 90 degrees:
    # the tool's y is the tip's -x.
    yaw = np.array([0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)])
    along = np.linspace(-0.02, 0.02, 5)
    face_in_tip = np.column_stack([-along, np.zeros(5), np.full(5, -0.03)])
    mount = probe_mount(_tool(yaw, face_in_tip))
    np.testing.assert_allclose(mount.origin, [0.0, 0.0, -0.03], atol=1e-12)
    np.testing.assert_allclose(mount.face, np.column_stack([np.zeros(5), along, np.zeros(5)]),
                               atol=1e-12)
    position, quaternion = mount.probe_pose([1.0, 2.0, 3.0], UPRIGHT)
    np.testing.assert_allclose(position, [1.0, 2.0, 2.97], atol=1e-12)
    assert abs(abs(np.dot(quaternion, yaw)) - 1.0) < 1e-12
    # A round tool: its surface, where the face touches, lies its radius below the points.
    round_mount = probe_mount(_tool(UPRIGHT, [[0.0, 0.0, 0.0], [0.0, 0.01, 0.0]], 0.002))
    np.testing.assert_allclose(round_mount.origin, [0.0, 0.005, -0.002], atol=1e-12)
