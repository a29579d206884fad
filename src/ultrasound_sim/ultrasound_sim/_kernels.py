"""The per-frame work, compiled: section, trace, point spread, display.

Every kernel here goes through the project's one numba decorator (``collision_engine._jit``).
They all live in this one module and call only each other, so numba's own cache (keyed on this
file) can never hold stale machine code of a kernel edited elsewhere. The public wrappers in
``imager`` check shapes and dtypes; these trust them. Plain numpy references of each kernel are
in ``tests/ultrasound_sim/test_kernels.py``.

Conventions: the probe frame of ``settings``; positions (y, z) in the scan plane x = 0; the
field is the complex baseband (I/Q) echo, demodulated at the centre frequency.
"""

import math

import numpy as np

from collision_engine._jit import jit

__all__ = ['display', 'point_spread', 'section', 'trace_lines']

_OUTSIDE = -1
# media columns (``anatomy.MEDIA_COLUMNS``)
_SPEED, _IMPEDANCE, _ATTENUATION, _BACKSCATTER = 0, 1, 2, 3
_LN10_OVER_10 = math.log(10.0) / 10.0
_NOISE_MASK = 0xFFF  # the noise table holds 2**12 values (64 KB: it stays in cache)
_AXIS_MASK = 0xFFF  # each axis's key table too: the field repeats every 2**12 voxels


@jit
def _local(vertices, v, rotation, position, axis):
    """Return coordinate ``axis`` of vertex ``v`` in the probe frame (rotation transposed)."""
    return (rotation[0, axis] * (vertices[v, 0] - position[0])
            + rotation[1, axis] * (vertices[v, 1] - position[1])
            + rotation[2, axis] * (vertices[v, 2] - position[2]))


@jit
def section(vertices, triangles, owner, rotation, position, segments, segment_owner):
    """Cut the anatomy's triangles by the probe's scan plane (x = 0 in the probe frame).

    A vertex is on the plane's positive side when its x > 0, else on the other, the same rule
    for every triangle that shares it, so the cut of a closed mesh is closed polygons. Writes
    each cut as (y0, z0, y1, z1) into ``segments`` and its structure into ``segment_owner``;
    returns how many. Only x is found for every vertex; y and z only for the few triangles cut.
    """
    n_vertices = vertices.shape[0]
    x = np.empty(n_vertices)
    for v in range(n_vertices):
        x[v] = _local(vertices, v, rotation, position, 0)
    count = 0
    for t in range(triangles.shape[0]):
        a, b, c = triangles[t, 0], triangles[t, 1], triangles[t, 2]
        pa, pb, pc = x[a] > 0.0, x[b] > 0.0, x[c] > 0.0
        if pa == pb and pb == pc:
            continue
        found = 0
        for edge in range(3):
            i, j = (a, b) if edge == 0 else ((b, c) if edge == 1 else (c, a))
            if (x[i] > 0.0) != (x[j] > 0.0):
                w = x[i] / (x[i] - x[j])
                for axis in (1, 2):
                    start = _local(vertices, i, rotation, position, axis)
                    end = _local(vertices, j, rotation, position, axis)
                    segments[count, 2 * found + axis - 1] = start + w * (end - start)
                found += 1
        segment_owner[count] = owner[t]
        count += 1
    return count


@jit
def _line_hits(segments, segment_owner, count, oy, oz, dy, dz, hit_t, hit_owner):
    """Where the full line o + t d crosses the cut polygons: t (sorted) and owners; how many."""
    n = 0
    capacity = hit_t.shape[0]
    for s in range(count):
        ay, az, by, bz = segments[s, 0], segments[s, 1], segments[s, 2], segments[s, 3]
        sa = dy * (az - oz) - dz * (ay - oy)
        sb = dy * (bz - oz) - dz * (by - oy)
        if (sa > 0.0) == (sb > 0.0) or n == capacity:
            continue
        u = sa / (sa - sb)
        t = (ay + u * (by - ay) - oy) * dy + (az + u * (bz - az) - oz) * dz
        k = n  # insertion sort: a line crosses a few dozen edges at most
        while k > 0 and hit_t[k - 1] > t:
            hit_t[k] = hit_t[k - 1]
            hit_owner[k] = hit_owner[k - 1]
            k -= 1
        hit_t[k] = t
        hit_owner[k] = segment_owner[s]
        n += 1
    return n


@jit
def _top(inside, structure_medium):
    """Return the medium of the last-listed structure the point is in, or ``_OUTSIDE``."""
    for s in range(inside.shape[0] - 1, -1, -1):
        if inside[s] & 1:
            return structure_medium[s]
    return _OUTSIDE


@jit
def _scatter(noise, keys, fx, fy, fz):
    """Sample the tissue-fixed random field at a point in voxels: trilinear, unit variance.

    A grid node's value is ``noise`` at the xor of its three coordinates' ``keys`` (simple
    tabulation hashing: each axis's key from a table of random words, 3-independent). In real
    arithmetic: numba's complex product costs half as much again.
    """
    ix, iy, iz = math.floor(fx), math.floor(fy), math.floor(fz)
    x1, y1, z1 = fx - ix, fy - iy, fz - iz
    x0, y0, z0 = 1.0 - x1, 1.0 - y1, 1.0 - z1
    xa, xb = keys[0, ix & _AXIS_MASK], keys[0, (ix + 1) & _AXIS_MASK]
    ya, yb = keys[1, iy & _AXIS_MASK], keys[1, (iy + 1) & _AXIS_MASK]
    za, zb = keys[2, iz & _AXIS_MASK], keys[2, (iz + 1) & _AXIS_MASK]
    real = imag = 0.0
    for corner in range(8):
        cx, cy, cz = corner & 1, corner & 2, corner & 4
        w = (x1 if cx else x0) * (y1 if cy else y0) * (z1 if cz else z0)
        value = noise[((xb if cx else xa) ^ (yb if cy else ya) ^ (zb if cz else za)) & _NOISE_MASK]
        real += w * value.real
        imag += w * value.imag
    scale = 1.0 / math.sqrt((x0 * x0 + x1 * x1) * (y0 * y0 + y1 * y1) * (z0 * z0 + z1 * z1))
    return complex(real * scale, imag * scale)


@jit
def trace_lines(segments, segment_owner, count, origins, directions, coupled, structure_medium,
                media, dtau, speed_of_sound, centre_frequency, rotation, position, voxel, noise,
                keys, scatter_gain, field, hit_t, hit_owner, inside):
    """Follow each coupled scanline through the cut anatomy; write its I/Q echo into ``field``.

    Along the line, in echo time: two-way attenuation at the centre frequency; at each change of
    medium an echo of the pressure reflection coefficient (Z2 - Z1) / (Z2 + Z1), at its time and
    carrier phase, and the rest passed on both ways (1 - r^2); the scatterer field, fixed to the
    scene, times the medium's backscatter. From outside into the first tissue is the gel's
    coupling (no echo); out of the body into air reflects all and the line ends.
    """
    n_lines, n_samples = field.shape
    for line in range(n_lines):
        for j in range(n_samples):
            field[line, j] = 0j
        if not coupled[line]:
            continue
        oy, oz = origins[line, 0], origins[line, 1]
        dy, dz = directions[line, 0], directions[line, 1]
        # the line in the scene, in voxels: base + s * step
        base = np.empty(3)
        step = np.empty(3)
        for a in range(3):
            base[a] = (position[a] + rotation[a, 1] * oy + rotation[a, 2] * oz) / voxel
            step[a] = (rotation[a, 1] * dy + rotation[a, 2] * dz) / voxel
        n = _line_hits(segments, segment_owner, count, oy, oz, dy, dz, hit_t, hit_owner)
        inside[:] = 0
        h = 0
        while h < n and hit_t[h] < 0.0:
            inside[hit_owner[h]] += 1
            h += 1
        medium = _top(inside, structure_medium)
        in_body = medium != _OUTSIDE
        s = 0.0  # m along the line
        tau = 0.0  # s, one way
        transmitted = 1.0  # two-way pressure amplitude passed through the interfaces so far
        attenuation = 0.0  # dB, one way
        loss = 1.0  # two-way amplitude left by attenuation, 10^(-attenuation / 10)
        decay = 1.0  # loss's factor over a whole sample in the medium
        for j in range(n_samples):
            tau_j = (j + 0.5) * dtau
            crossed = j == 0  # the first step is half a sample
            while True:
                speed = media[medium, _SPEED] if medium != _OUTSIDE else speed_of_sound
                alpha = media[medium, _ATTENUATION] if medium != _OUTSIDE else 0.0
                reach = s + (tau_j - tau) * speed
                if h < n and hit_t[h] <= reach:
                    crossed = True
                    length = hit_t[h] - s
                    tau += length / speed
                    attenuation += alpha * length
                    s = hit_t[h]
                    inside[hit_owner[h]] += 1
                    h += 1
                    after = _top(inside, structure_medium)
                    if after == medium:
                        continue
                    if medium == _OUTSIDE and not in_body:
                        r = 0.0
                    elif after == _OUTSIDE:
                        r = -1.0
                    else:
                        z1, z2 = media[medium, _IMPEDANCE], media[after, _IMPEDANCE]
                        r = (z2 - z1) / (z2 + z1)
                    if r != 0.0:
                        echo = (r * transmitted * math.exp(-_LN10_OVER_10 * attenuation)
                                * np.exp(-4j * math.pi * centre_frequency * tau))
                        at = tau / dtau - 0.5
                        k = math.floor(at)
                        w = at - k
                        if 0 <= k < n_samples:
                            field[line, k] += (1.0 - w) * echo
                        if 0 <= k + 1 < n_samples:
                            field[line, k + 1] += w * echo
                    transmitted *= 1.0 - r * r
                    medium = after
                    in_body = in_body or medium != _OUTSIDE
                else:
                    attenuation += alpha * (reach - s)
                    s = reach
                    tau = tau_j
                    break
            if transmitted == 0.0:
                break
            if crossed:
                loss = math.exp(-_LN10_OVER_10 * attenuation)
                if medium != _OUTSIDE:
                    decay = math.exp(-_LN10_OVER_10 * media[medium, _ATTENUATION]
                                     * media[medium, _SPEED] * dtau)
            else:
                loss *= decay
            if medium == _OUTSIDE or media[medium, _BACKSCATTER] == 0.0:
                continue
            field[line, j] += (media[medium, _BACKSCATTER] * scatter_gain[j] * transmitted * loss
                               * _scatter(noise, keys, base[0] + s * step[0],
                                          base[1] + s * step[1], base[2] + s * step[2]))


@jit
def point_spread(field, coupled, axial, lateral, work, envelope):
    """Convolve the I/Q field with the axial pulse, then the lateral beam; its magnitude.

    ``axial`` (2 ka + 1,) complex taps along a line; ``lateral`` (2 kl + 1, samples) real taps
    across lines, one column per depth (the beam widens where the aperture stops growing). An
    uncoupled line's field counts as zero and its envelope is zero. ``work`` (2, lines, samples)
    holds the axial pass, real and imaginary apart: in real arithmetic, tap by tap over whole
    rows, the loops vectorise (numba's wrap-around of an index that may be negative does not).
    """
    n_lines, n_samples = field.shape
    ka = axial.shape[0] // 2
    kl = lateral.shape[0] // 2
    real, imag = work[0], work[1]
    field_real, field_imag = np.empty(n_samples), np.empty(n_samples)
    for line in range(n_lines):
        row_real, row_imag = real[line], imag[line]
        row_real[:] = 0.0
        row_imag[:] = 0.0
        if not coupled[line]:
            continue
        for j in range(n_samples):
            field_real[j], field_imag[j] = field[line, j].real, field[line, j].imag
        for k in range(-ka, ka + 1):
            tap_real, tap_imag = axial[k + ka].real, axial[k + ka].imag
            start, stop = max(0, k), min(n_samples, n_samples + k)
            out_real, out_imag = row_real[start:stop], row_imag[start:stop]
            in_real, in_imag = field_real[start - k:stop - k], field_imag[start - k:stop - k]
            for j in range(stop - start):  # indices that cannot be negative: it vectorises
                out_real[j] += tap_real * in_real[j] - tap_imag * in_imag[j]
                out_imag[j] += tap_real * in_imag[j] + tap_imag * in_real[j]
    sum_real, sum_imag = np.empty(n_samples), np.empty(n_samples)
    for line in range(n_lines):
        if not coupled[line]:
            envelope[line, :] = 0.0
            continue
        sum_real[:] = 0.0
        sum_imag[:] = 0.0
        for k in range(max(-kl, line - n_lines + 1), min(kl, line) + 1):
            taps, row_real, row_imag = lateral[k + kl], real[line - k], imag[line - k]
            for j in range(n_samples):
                sum_real[j] += taps[j] * row_real[j]
                sum_imag[j] += taps[j] * row_imag[j]
        for j in range(n_samples):
            envelope[line, j] = math.sqrt(sum_real[j] * sum_real[j] + sum_imag[j] * sum_imag[j])


@jit
def display(envelope, coupled, gain, dynamic_range, levels, read, line_at, sample_at,
            line_weight, sample_weight, image):
    """Log-compress the envelope to grey levels, then scan-convert them into ``image``.

    Level 255 is 0 dB (a perfect reflector at the face, after ``gain`` (samples,) dB), level 0
    is ``dynamic_range`` below; an uncoupled line is black. Only the samples ``read`` get a
    level: the logarithm is most of this kernel's time. Each pixel interpolates the levels of
    the four samples around it (``line_at`` < 0: outside the field, black).
    """
    n_lines, n_samples = envelope.shape
    scale = 255.0 / dynamic_range
    for line in range(n_lines):
        for j in range(n_samples):
            if not read[line, j]:
                continue
            value = envelope[line, j]
            level = 0.0
            if coupled[line] and value > 0.0:
                level = (20.0 * math.log10(value) + gain[j] + dynamic_range) * scale
                level = min(max(level, 0.0), 255.0)
            levels[line, j] = level
    flat = image.ravel()
    for p in range(flat.shape[0]):
        i = line_at[p]
        if i < 0:
            flat[p] = 0
            continue
        j = sample_at[p]
        wl, ws = line_weight[p], sample_weight[p]
        value = ((1.0 - wl) * ((1.0 - ws) * levels[i, j] + ws * levels[i, j + 1])
                 + wl * ((1.0 - ws) * levels[i + 1, j] + ws * levels[i + 1, j + 1]))
        flat[p] = np.uint8(value + 0.5)
