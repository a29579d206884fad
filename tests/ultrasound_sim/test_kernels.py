"""Each compiled kernel against a plain numpy reference written here, on small cases.

The references follow each kernel's documented contract step by step in numpy and Python,
slowly and without numba, so that what the compiled code does is checked by a second writing.
"""

import math
import os
import subprocess
import sys

from ground_truth.imaging_scenes import block_scene, HALF_TURN_Y
import numpy as np
import pytest
from scipy import ndimage

from ultrasound_sim import _kernels, Imager, load_anatomy, ProbeSettings


@pytest.fixture(scope='module')
def imager(tmp_path_factory):
    structures = f"""\
        - name: vessel
          shape: {{cylinder: {{radius: 0.004, height: 0.1}}}}
          pose: {{position: [0.0, 0.002, -0.012], rpy: {HALF_TURN_Y}}}
          medium: blood
        - name: rib
          shape: {{capsule: {{radius: 0.003, length: 0.05}}}}
          pose: {{position: [0.0, -0.006, -0.008], rpy: {HALF_TURN_Y}}}
          medium: bone
        """
    path = block_scene(tmp_path_factory.mktemp('scene'), 'muscle', structures)
    settings = ProbeSettings(depth=0.025, width=0.02, scanlines=24, samples=160,
                             image_width=48, image_height=64)
    return Imager(load_anatomy(path), settings)


POSE = (np.array([0.0005, 0.001, -0.0003]),
        np.array([math.sin(0.05), 0.0, 0.0, math.cos(0.05)]))  # rolled 0.1 rad about x


def rotation_of(quaternion):
    from scipy.spatial.transform import Rotation
    return Rotation.from_quat(quaternion).as_matrix()


def reference_section(vertices, triangles, owner, rotation, position):
    local = (vertices - position) @ rotation
    positive = local[:, 0] > 0.0
    segments, owners = [], []
    for t, corners in enumerate(triangles):
        side = positive[corners]
        if side.all() or not side.any():
            continue
        points = []
        for i, j in ((0, 1), (1, 2), (2, 0)):
            a, b = local[corners[i]], local[corners[j]]
            if side[i] != side[j]:
                w = a[0] / (a[0] - b[0])
                points.extend((a[1:] + w * (b[1:] - a[1:])).tolist())
        segments.append(points)
        owners.append(owner[t])
    return np.array(segments), np.array(owners)


def test_section(imager):
    anatomy = imager.anatomy
    rotation = rotation_of(POSE[1])
    segments = np.empty((len(anatomy.triangles), 4))
    owners = np.empty(len(anatomy.triangles), dtype=np.int64)
    count = _kernels.section(anatomy.vertices, anatomy.triangles, anatomy.owner, rotation,
                             POSE[0], segments, owners)
    expected, expected_owners = reference_section(anatomy.vertices, anatomy.triangles,
                                                  anatomy.owner, rotation, POSE[0])
    assert count == len(expected) > 100
    np.testing.assert_allclose(segments[:count], expected, atol=1e-15)
    np.testing.assert_array_equal(owners[:count], expected_owners)


def reference_noise(noise, keys, point, voxel):
    scaled = np.asarray(point) / voxel
    base = np.floor(scaled).astype(np.int64)
    frac = scaled - base
    total, norm = 0j, 0.0
    for corner in range(8):
        offset = np.array([corner & 1, (corner >> 1) & 1, (corner >> 2) & 1])
        w = np.prod(np.where(offset == 1, frac, 1.0 - frac))
        node = (base + offset) % 4096
        key = keys[0, node[0]] ^ keys[1, node[1]] ^ keys[2, node[2]]
        total += w * noise[key % 4096]
        norm += w * w
    return total / math.sqrt(norm)


def reference_trace(imager, segments, owners, coupled, rotation, position):
    """The scanline walk, in plain Python: media by crossing parity, interfaces, scatter."""
    settings, anatomy = imager.settings, imager.anatomy
    media = imager._media
    dtau = settings.sample_spacing / settings.speed_of_sound
    field = np.zeros((settings.scanlines, settings.samples), dtype=complex)
    for line in np.flatnonzero(coupled):
        o, d = imager.scan.origins[line], imager.scan.directions[line]
        a, b = segments[:, :2], segments[:, 2:]
        side_a = d[0] * (a[:, 1] - o[1]) - d[1] * (a[:, 0] - o[0])
        side_b = d[0] * (b[:, 1] - o[1]) - d[1] * (b[:, 0] - o[0])
        crossing = (side_a > 0.0) != (side_b > 0.0)
        u = side_a[crossing] / (side_a[crossing] - side_b[crossing])
        points = a[crossing] + u[:, None] * (b[crossing] - a[crossing])
        t = (points - o) @ d
        order = np.argsort(t, kind='stable')
        hits, hit_owner = t[order], owners[crossing][order]
        counts = np.zeros(len(anatomy.names), dtype=int)

        def medium_now():
            odd = np.flatnonzero(counts % 2)
            return anatomy.structure_medium[odd[-1]] if len(odd) else -1

        for owner in hit_owner[hits < 0.0]:
            counts[owner] += 1
        pending = list(zip(hits[hits >= 0.0], hit_owner[hits >= 0.0]))
        medium = medium_now()
        in_body, s, tau, passed, loss = medium != -1, 0.0, 0.0, 1.0, 0.0
        for j in range(settings.samples):
            target = (j + 0.5) * dtau
            while True:
                speed = media[medium, 0] if medium != -1 else settings.speed_of_sound
                alpha = media[medium, 2] if medium != -1 else 0.0
                reach = s + (target - tau) * speed
                if pending and pending[0][0] <= reach:
                    at, owner = pending.pop(0)
                    tau += (at - s) / speed
                    loss += alpha * (at - s)
                    s = at
                    counts[owner] += 1
                    after = medium_now()
                    if after == medium:
                        continue
                    if medium == -1 and not in_body:
                        r = 0.0
                    elif after == -1:
                        r = -1.0
                    else:
                        z1, z2 = media[medium, 1], media[after, 1]
                        r = (z2 - z1) / (z2 + z1)
                    if r:
                        echo = r * passed * 10 ** (-loss / 10) * np.exp(
                            -4j * np.pi * settings.centre_frequency * tau)
                        k = math.floor(tau / dtau - 0.5)
                        w = tau / dtau - 0.5 - k
                        for index, weight in ((k, 1 - w), (k + 1, w)):
                            if 0 <= index < settings.samples:
                                field[line, index] += weight * echo
                    passed *= 1 - r * r
                    medium = after
                    in_body = in_body or medium != -1
                else:
                    loss += alpha * (reach - s)
                    s, tau = reach, target
                    break
            if passed == 0.0:
                break
            if medium == -1 or media[medium, 3] == 0.0:
                continue
            point = position + rotation @ np.array([0.0, *(o + s * d)])
            field[line, j] += (media[medium, 3] * imager._scatter_gain[j] * passed
                               * 10 ** (-loss / 10)
                               * reference_noise(imager._noise, imager._keys, point,
                                                 imager._voxel))
    return field


def test_trace_lines(imager):
    settings, anatomy = imager.settings, imager.anatomy
    rotation = rotation_of(POSE[1])
    segments = np.empty((len(anatomy.triangles), 4))
    owners = np.empty(len(anatomy.triangles), dtype=np.int64)
    count = _kernels.section(anatomy.vertices, anatomy.triangles, anatomy.owner, rotation,
                             POSE[0], segments, owners)
    coupled = np.ones(settings.scanlines, dtype=bool)
    coupled[5] = False
    field = np.empty((settings.scanlines, settings.samples), dtype=complex)
    _kernels.trace_lines(segments, owners, count, imager.scan.origins, imager.scan.directions,
                         coupled, anatomy.structure_medium, imager._media,
                         settings.sample_spacing / settings.speed_of_sound,
                         settings.speed_of_sound, settings.centre_frequency, rotation, POSE[0],
                         imager._voxel, imager._noise, imager._keys, imager._scatter_gain, field,
                         np.empty(256), np.empty(256, dtype=np.int64),
                         np.empty(len(anatomy.names), dtype=np.int64))
    expected = reference_trace(imager, segments[:count], owners[:count], coupled, rotation,
                               POSE[0])
    assert np.abs(expected).max() > 0 and not field[5].any()
    np.testing.assert_allclose(field, expected, rtol=1e-9, atol=1e-12)


def test_point_spread(imager):
    rng = np.random.default_rng(3)
    shape = (imager.settings.scanlines, imager.settings.samples)
    field = rng.normal(size=shape) + 1j * rng.normal(size=shape)
    coupled = np.ones(shape[0], dtype=bool)
    coupled[7] = False
    envelope = np.empty(shape, dtype=np.float32)
    _kernels.point_spread(field, coupled, imager.psf.axial,
                          np.ascontiguousarray(imager.psf.lateral.T), np.empty((2, *shape)),
                          envelope)
    heard = np.where(coupled[:, None], field, 0.0)
    axial = np.array([np.convolve(row, imager.psf.axial, mode='same') for row in heard])
    kl = imager.psf.lateral.shape[1] // 2
    padded = np.pad(axial, ((kl, kl), (0, 0)))
    expected = np.zeros(shape, dtype=complex)
    for k in range(-kl, kl + 1):
        expected += imager.psf.lateral[:, k + kl][None, :] * padded[kl - k: kl - k + shape[0]]
    expected[~coupled] = 0.0
    assert np.abs(expected[6]).min() > 0  # line 7's neighbours are heard without it
    np.testing.assert_allclose(envelope, np.abs(expected), rtol=1e-5)


def test_display(imager):
    settings, conversion = imager.settings, imager.conversion
    rng = np.random.default_rng(4)
    shape = (settings.scanlines, settings.samples)
    envelope = (10.0 ** rng.uniform(-4, 0.5, shape)).astype(np.float32)
    envelope[0, :5] = 0.0
    coupled = np.ones(settings.scanlines, dtype=bool)
    coupled[7] = False
    gain = np.linspace(0.0, 12.0, settings.samples)
    geometry = conversion.geometry
    image = np.empty((geometry.height, geometry.width), dtype=np.uint8)
    unread = np.full(shape, np.nan)  # a level the kernel used without making it shows
    _kernels.display(envelope, coupled, gain, settings.dynamic_range, unread, conversion.read,
                     conversion.line_at, conversion.sample_at, conversion.line_weight,
                     conversion.sample_weight, image)
    assert 0 < conversion.read.sum() < conversion.read.size
    assert np.isnan(unread[~conversion.read]).all()
    with np.errstate(divide='ignore'):
        levels = (20 * np.log10(envelope) + gain + settings.dynamic_range) * 255 \
            / settings.dynamic_range
    levels = np.clip(np.nan_to_num(levels, neginf=0.0), 0.0, 255.0)
    levels[~coupled] = 0.0
    inside = conversion.line_at >= 0
    coordinates = np.stack((conversion.line_at + conversion.line_weight,
                            conversion.sample_at + conversion.sample_weight))
    expected = ndimage.map_coordinates(levels, coordinates, order=1)
    expected = np.where(inside, np.floor(expected + 0.5), 0).reshape(image.shape)
    assert inside.any()
    np.testing.assert_allclose(image, expected, atol=1)


def test_the_kernels_as_plain_python_agree_too():
    """The same checks with numba off: the kernels' Python is what numba compiles."""
    if os.environ.get('NUMBA_DISABLE_JIT') == '1':
        pytest.skip('this is the uncompiled run')
    result = subprocess.run([sys.executable, '-m', 'pytest', '-q', '-p', 'no:cacheprovider',
                             __file__, '-k', 'not plain_python'],
                            env=dict(os.environ, NUMBA_DISABLE_JIT='1'), capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert '4 passed' in result.stdout
