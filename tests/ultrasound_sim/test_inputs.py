"""Bad input gets a clear error that names the field, before any frame is made."""

from ground_truth.distances import scene_path
from ground_truth.imaging_scenes import block_scene
import numpy as np
import pytest

from collision_engine import SceneError
from ultrasound_sim import Imager, load_anatomy, ProbeSettings


@pytest.fixture(scope='module')
def imager(tmp_path_factory):
    return Imager(load_anatomy(block_scene(tmp_path_factory.mktemp('scene'), 'tissue')),
                  ProbeSettings())


@pytest.mark.parametrize('fields, message', [
    ({'probe_type': 'phased'}, r'^probe_type must be one of linear, convex'),
    ({'depth': 0.0}, r'^depth must be finite > 0'),
    ({'depth': float('nan')}, r'^depth must be finite > 0'),
    ({'scanlines': 300}, r'^scanlines must be at most image_width \(256\)'),
    ({'scanlines': 1}, r'^scanlines must be an integer >= 2'),
    ({'samples': 512.0}, r'^samples must be an integer >= 2'),
    ({'centre_frequency': -5e6}, r'^centre_frequency must be finite > 0'),
    ({'bandwidth': 2.5}, r'^bandwidth must be below 2'),
    ({'angle': 4.0}, r'^angle must be below pi'),
    ({'gain': float('inf')}, r'^gain must be finite'),
    ({'tgc': (0.0, float('nan'))}, r'^tgc must be 2 finite numbers'),
    ({'tgc': [0.0, 1.0]}, r'^tgc must be a tuple'),
    ({'dynamic_range': 0}, r'^dynamic_range must be finite > 0'),
    ({'coupling_gap': -1e-3}, r'^coupling_gap must be finite >= 0'),
])
def test_bad_settings_name_the_field(fields, message):
    with pytest.raises(ValueError, match=message):
        ProbeSettings(**fields)


def test_settings_keep_the_checked_numbers():
    settings = ProbeSettings(depth=np.float32(0.05), scanlines=np.int64(64), tgc=(0, 1))
    assert type(settings.depth) is float and settings.depth == pytest.approx(0.05)
    assert type(settings.scanlines) is int and settings.scanlines == 64
    assert settings.tgc == (0.0, 1.0) and all(type(g) is float for g in settings.tgc)


@pytest.mark.parametrize('position, quaternion, message', [
    ([np.nan, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], r'^pose: position must be 3 finite'),
    ([0.0, 0.0], [0.0, 0.0, 0.0, 1.0], r'^pose: position must be 3 finite'),
    ([0.0, 0.0, 0.0], [0.0, 0.0, np.nan, 1.0], r'^pose: quaternion must be 4 finite'),
    ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 2.0], r'^pose: quaternion must have unit norm'),
])
def test_a_bad_pose_is_refused(imager, position, quaternion, message):
    with pytest.raises(ValueError, match=message):
        imager.frame(position, quaternion, np.ones(128, dtype=bool))


@pytest.mark.parametrize('coupled', [np.ones(127, dtype=bool), np.ones(128)])
def test_a_bad_coupling_mask_is_refused(imager, coupled):
    with pytest.raises(ValueError, match=r'^coupled: must be \(128,\) bool'):
        imager.frame([0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], coupled)


def test_a_scene_without_acoustic_properties_is_refused():
    with pytest.raises(ValueError, match=r'probe_phantom\.yaml: anatomy: missing: the scene has '
                                         r'no acoustic properties'):
        load_anatomy(scene_path('probe_phantom'))


def test_a_medium_missing_a_property_is_refused(tmp_path):
    path = block_scene(tmp_path, 'tissue')
    path.write_text(path.read_text().replace('impedance: 1.630000e+6, ', '', 1))
    with pytest.raises(SceneError, match=r'anatomy\.media\.tissue\.impedance: missing'):
        load_anatomy(path)


def test_wrong_types_are_refused():
    with pytest.raises(ValueError, match='^anatomy: must be an Anatomy'):
        Imager('scene.yaml', ProbeSettings())
