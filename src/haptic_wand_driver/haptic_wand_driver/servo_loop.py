"""The simulated wand's servo periods with the device's law (``LocalRenderer``), compiled.

Why: the wand runs its dynamics and the local law at the servo rate, four periods a 1 kHz tick
at 4 kHz. In Python a period cost about 10 µs (``bench/servo_rate.py``), the largest piece of the
driver's tick. This is the same arithmetic in the same order, compiled: the Python path
(``SimulatedWand`` with any other law, which calls ``LocalRenderer.wrench``) is its reference,
and the tests hold the two to the same trajectory, force and energy books.

Its kernels go through the project's one numba decorator (``haptic_util.jit``). The
module is self-contained (numba caches a kernel by its own file, so a kernel here must not call
one elsewhere): ``_saturate`` and ``_plane_force`` repeat ``haptic_contract.plane_law``'s
``saturate_components`` and ``unilateral_spring_damper``, the references their tests hold them
to. It is imported only by a wand given such a law, which calls ``compile_now``
before its loop starts. Its inputs, float64 arrays:

* ``packed`` (2, n): the renderer's settings and what it holds, from a period on and before it
  (``LocalRenderer.packed``, whose layout ``local_rendering`` defines);
* ``books``: the port's passivity (``PortPassivity.books``);
* ``bound``: the shift of the planes, the take it was set for and the last period's spring push,
  and what the easing carries on (``LocalRenderer.bound``; ``model_easing`` when the law eases
  its models in);
* ``joints`` (5, 6): per joint, the hand's stiffness and damping, the inverse inertia, the
  damping decay per period and the workspace stops (lower, upper);
* ``targets`` (n, 2, 5): the hand's target and its rate at each period.
"""
import math

import numpy as np

from haptic_util.jit import jit
from haptic_wand_driver.local_rendering import (BOUND_SIZE, DEADLINE, LAPSED, LAW_SIZE,
                                                MODE_PLANES, MODE_WRENCH, PLANE_SIZE, PLANES_AT,
                                                SERIAL, SINCE, STEP_RATE)
from haptic_wand_driver.model_easing import COS_EASED_TURN, EASED_TURN
from haptic_wand_driver.port_passivity import BOOKS_CLOSE_AFTER

__all__ = ['advance', 'compile_now']


@jit
def _saturate(x, y, z, limit):
    """Return ``haptic_contract.plane_law.saturate_components`` of (x, y, z), compiled."""
    norm = math.sqrt(x * x + y * y + z * z)
    if norm == math.inf or norm != norm:
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            return 0.0, 0.0, 0.0
        largest = max(abs(x), abs(y), abs(z))
        a, b, c = x / largest, y / largest, z / largest
        norm = largest * math.sqrt(a * a + b * b + c * c)
    if norm <= limit:
        return x, y, z
    scale = limit / norm
    return x * scale, y * scale, z * scale


@jit
def _cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@jit
def _plane_force(law, at, depth, vx, vy, vz, limit, period):
    """One plane's force on its point (``ContactModel.wrench``), damped as the device damps."""
    nx, ny, nz = law[at + 3], law[at + 4], law[at + 5]
    kx, ky, kz = law[at + 6], law[at + 7], law[at + 8]
    fx = kx * (depth * nx) - law[at + 9] * vx
    fy = ky * (depth * ny) - law[at + 10] * vy
    fz = kz * (depth * nz) - law[at + 11] * vz
    pushing = fx * nx + fy * ny + fz * nz
    if pushing < 0.0:
        fx -= pushing * nx
        fy -= pushing * ny
        fz -= pushing * nz
    ratio = law[2]
    if ratio <= 0.0:
        return fx, fy, fz
    stiffness = kx * nx * nx + ky * ny * ny + kz * nz * nz
    inertia = law[3] * nx * nx + law[4] * ny * ny + law[5] * nz * nz
    damping = 2.0 * ratio * math.sqrt(stiffness * inertia)
    cap = law[20] * inertia / period
    if cap < damping:
        damping = cap
    fx, fy, fz = _saturate(fx, fy, fz, limit)
    push = fx * nx + fy * ny + fz * nz
    speed = vx * nx + vy * ny + vz * nz
    change = -push
    if -damping * speed > change:
        change = -damping * speed
    return fx + change * nx, fy + change * ny, fz + change * nz


@jit
def _arm(law, at, cr, sr, cy, sy):
    """Return the tool point of the plane at ``at``, turned by the wand's roll and yaw."""
    x, y, z = law[at + 12], law[at + 13], law[at + 14]
    y, z = cr * y - sr * z, sr * y + cr * z
    return cy * x - sy * y, sy * x + cy * y, z


@jit
def _depth(law, at, coordinates, ax, ay, az):
    """How far the tool point at (ax, ay, az) from the tip lies behind the plane at ``at``."""
    return (law[at + 3] * (law[at] - (coordinates[0] + ax))
            + law[at + 4] * (law[at + 1] - (coordinates[1] + ay))
            + law[at + 5] * (law[at + 2] - (coordinates[2] + az)))


@jit
def _springs(law, coordinates, depths, stiffnesses):
    """Fill each plane's depth and stiffness along its normal (``ContactModel.springs``)."""
    roll, yaw = coordinates[3], coordinates[4]
    cr, sr, cy, sy = math.cos(roll), math.sin(roll), math.cos(yaw), math.sin(yaw)
    for k in range(int(law[19])):
        at = PLANES_AT + PLANE_SIZE * k
        ax, ay, az = _arm(law, at, cr, sr, cy, sy)
        depths[k] = _depth(law, at, coordinates, ax, ay, az)
        nx, ny, nz = law[at + 3], law[at + 4], law[at + 5]
        stiffnesses[k] = law[at + 6] * nx * nx + law[at + 7] * ny * ny + law[at + 8] * nz * nz


@jit
def _deepest_first(depths, stiffnesses, count, lowest, sorted_depths, sorted_stiffnesses,
                   behind_only):
    """Sort the springs as sorted(reverse=True) does, depths less ``lowest``; return how many.

    ``behind_only``: only those behind (depth above ``lowest``); else all; with stiffness > 0.
    """
    kept = 0
    for k in range(count):
        depth, stiffness = depths[k] - lowest, stiffnesses[k]
        if not (stiffness > 0.0 and (depth > 0.0 or not behind_only)):
            continue
        j = kept
        while j > 0 and (sorted_depths[j - 1] < depth
                         or (sorted_depths[j - 1] == depth
                             and sorted_stiffnesses[j - 1] < stiffness)):
            sorted_depths[j] = sorted_depths[j - 1]
            sorted_stiffnesses[j] = sorted_stiffnesses[j - 1]
            j -= 1
        sorted_depths[j], sorted_stiffnesses[j] = depth, stiffness
        kept += 1
    return kept


@jit
def _least_shift(depths, stiffnesses, count, energy, lowest):
    """Return the least shift from ``lowest`` storing at most ``energy`` (``least_shift``)."""
    d, k = np.empty(3), np.empty(3)
    behind = _deepest_first(depths, stiffnesses, count, lowest, d, k, True)
    a = b = c = 0.0
    for m in range(behind):
        a += k[m]
        b += k[m] * d[m]
        c += k[m] * d[m] * d[m]
        shift = (b - math.sqrt(max(b * b - a * (c - 2.0 * energy), 0.0))) / a
        if m + 1 == behind or shift >= d[m + 1]:
            return max(shift, 0.0) + lowest
    return 0.0 + lowest


@jit
def _matched_shift(depths, stiffnesses, count, push):
    """Return the shift at which the springs push ``push`` (``model_easing.matched_shift``)."""
    d, k = np.empty(3), np.empty(3)
    kept = _deepest_first(depths, stiffnesses, count, 0.0, d, k, False)
    a = b = 0.0
    for m in range(kept):
        a += k[m]
        b += k[m] * d[m]
        shift = (b - push) / a
        if m + 1 == kept or shift >= d[m + 1]:
            if push > 0.0:
                return shift
            return max(shift, 0.0)
    return 0.0


@jit
def _push(depths, stiffnesses, count, shift):
    """Return the springs' push with the planes moved out by ``shift`` (``spring_push``)."""
    push = 0.0
    for k in range(count):
        if depths[k] - shift > 0.0:
            push += stiffnesses[k] * (depths[k] - shift)
    return push


@jit
def _total_stiffness(stiffnesses, count):
    total = 0.0
    for k in range(count):
        if stiffnesses[k] > 0.0:
            total += stiffnesses[k]
    return total


@jit
def _eased_scale(scale, step, push):
    """Return ``scale`` moved toward 1 (``model_easing.eased_scale``)."""
    if push <= 0.0:
        return 1.0
    change = step * scale / push
    return min(scale + change, 1.0) if scale < 1.0 else max(scale - change, 1.0)


@jit
def _total_damping(law, extra):
    """Return the planes' dampings along their normals, ``extra`` added (``total_damping``)."""
    total = 0.0
    for k in range(int(law[19])):
        at = PLANES_AT + PLANE_SIZE * k
        nx, ny, nz = law[at + 3], law[at + 4], law[at + 5]
        along = (max(law[at + 9] + extra, 0.0) * nx * nx + max(law[at + 10] + extra, 0.0) * ny * ny
                 + max(law[at + 11] + extra, 0.0) * nz * nz)
        if along > 0.0:
            total += along
    return total


@jit
def _held_normals(law, bound):
    """Return ``law`` with the normals rendered the period before (``held_normals``)."""
    count = int(law[19])
    if bound[7] != count or count == 0:
        return law
    rendered = law.copy()
    for k in range(count):
        at = PLANES_AT + PLANE_SIZE * k
        hx, hy, hz = bound[8 + 3 * k], bound[9 + 3 * k], bound[10 + 3 * k]
        if hx * law[at + 3] + hy * law[at + 4] + hz * law[at + 5] >= COS_EASED_TURN:
            rendered[at + 3], rendered[at + 4], rendered[at + 5] = hx, hy, hz
    return rendered


@jit
def _turn_normals(rendered, law, step, push):
    """Turn ``rendered``'s normals toward ``law``'s, in place (``turned_normals``)."""
    for k in range(int(law[19])):
        at = PLANES_AT + PLANE_SIZE * k
        nx, ny, nz = rendered[at + 3], rendered[at + 4], rendered[at + 5]
        tx, ty, tz = law[at + 3], law[at + 4], law[at + 5]
        along = nx * tx + ny * ty + nz * tz
        rendered[at + 3], rendered[at + 4], rendered[at + 5] = tx, ty, tz
        if push <= 0.0 or along < COS_EASED_TURN:
            continue
        angle = step / push
        if angle >= EASED_TURN or along >= math.cos(angle):
            continue
        x, y, z = tx - along * nx, ty - along * ny, tz - along * nz
        length = math.sqrt(x * x + y * y + z * z)
        cos, sin = math.cos(angle), math.sin(angle)
        rendered[at + 3] = nx * cos + x / length * sin
        rendered[at + 4] = ny * cos + y / length * sin
        rendered[at + 5] = nz * cos + z / length * sin


@jit
def _shift(law, coordinates, rates, books, bound, period):
    """Set ``bound`` for this period of the planes held (``LocalRenderer._shift``)."""
    rate = law[STEP_RATE]
    first = law[SERIAL] != bound[1]
    if not (first or rate > 0.0):
        return
    _observe(books, coordinates)
    depths, stiffnesses = np.empty(3), np.empty(3)
    count = int(law[19])
    if rate == 0.0:
        _springs(law, coordinates, depths, stiffnesses)
        bound[0], bound[1] = _least_shift(depths, stiffnesses, count, books[0], 0.0), law[SERIAL]
        return
    step, shift, push, scale, extra = rate * period, bound[0], bound[2], bound[3], bound[5]
    rendered = _held_normals(law, bound).copy()
    _springs(rendered, coordinates, depths, stiffnesses)
    if first:
        total, damping = _total_stiffness(stiffnesses, count), _total_damping(rendered, 0.0)
        scale = bound[4] / total if bound[4] > 0.0 and total > 0.0 else 1.0
        extra = (bound[6] - damping) / count if count > 0 else 0.0
        for k in range(count):
            stiffnesses[k] = scale * stiffnesses[k]
        if bound[LAPSED] != 0.0:
            push = min(push, _push(depths, stiffnesses, count, 0.0))
        shift = _matched_shift(depths, stiffnesses, count, push)
    else:
        held = 0.0
        for k in range(count):
            if depths[k] - shift > 0.0:
                held += 0.5 * (scale * stiffnesses[k]) * (depths[k] - shift) * (depths[k] - shift)
        _turn_normals(rendered, law, step, push)
        _springs(rendered, coordinates, depths, stiffnesses)
        total = _total_stiffness(stiffnesses, count)
        scale = _eased_scale(scale, step, push)
        extra, speed = 0.0, count * math.sqrt(rates[0] * rates[0] + rates[1] * rates[1]
                                              + rates[2] * rates[2])
        if push > 0.0 and speed != 0.0:
            change = step / speed
            extra = min(bound[5] + change, 0.0) if bound[5] < 0.0 else max(bound[5] - change, 0.0)
        for k in range(count):
            stiffnesses[k] = scale * stiffnesses[k]
        scaled = _total_stiffness(stiffnesses, count)
        eased = 0.0
        if scaled != 0.0:
            change = step / scaled
            eased = max(shift - change, 0.0) if shift > 0.0 else min(shift + change, 0.0)
        floor = _least_shift(depths, stiffnesses, count, max(books[0], held), min(eased, 0.0))
        shift = floor if floor > eased else eased
    bound[0], bound[1], bound[2] = shift, law[SERIAL], _push(depths, stiffnesses, count, shift)
    bound[3], bound[4], bound[5] = scale, scale * total, extra
    bound[6], bound[7] = _total_damping(rendered, extra), count
    for k in range(count):
        at = PLANES_AT + PLANE_SIZE * k
        bound[8 + 3 * k], bound[9 + 3 * k], bound[10 + 3 * k] = (
            rendered[at + 3], rendered[at + 4], rendered[at + 5])


@jit
def _scaled(law, scale, extra):
    """Return ``law``, its planes' stiffnesses scaled, ``extra`` on dampings (``scaled_model``)."""
    if scale == 1.0 and extra == 0.0:
        return law
    scaled = law.copy()
    for k in range(int(law[19])):
        at = PLANES_AT + PLANE_SIZE * k
        for j in range(6, 9):
            scaled[at + j] = law[at + j] * scale
            scaled[at + j + 3] = max(law[at + j + 3] + extra, 0.0)
    return scaled


@jit
def _planes(law, coordinates, rates, limit, period, shift):
    """Force and torque of the held planes moved out by ``shift`` (``ContactModel.wrench``)."""
    roll, yaw = coordinates[3], coordinates[4]
    cr, sr, cy, sy = math.cos(roll), math.sin(roll), math.cos(yaw), math.sin(yaw)
    wx, wy, wz = rates[3] * cy, rates[3] * sy, rates[3] * 0.0 + rates[4]
    fx = fy = fz = tx = ty = tz = 0.0
    for k in range(int(law[19])):
        at = PLANES_AT + PLANE_SIZE * k
        ax, ay, az = _arm(law, at, cr, sr, cy, sy)
        depth = _depth(law, at, coordinates, ax, ay, az) - shift
        if depth <= 0.0:
            continue
        sx, sy_, sz = _cross(wx, wy, wz, ax, ay, az)
        px, py, pz = _plane_force(law, at, depth, rates[0] + sx, rates[1] + sy_, rates[2] + sz,
                                  limit, period)
        qx, qy, qz = _cross(ax, ay, az, px, py, pz)
        fx, fy, fz = fx + px, fy + py, fz + pz
        tx, ty, tz = tx + qx, ty + qy, tz + qz
    return fx, fy, fz, tx, ty, tz


@jit
def _observe(books, coordinates):
    """Book the work the held force did since the last period (``PortPassivity.observe``)."""
    if books[8] != 0.0:
        work = (books[2] * (coordinates[0] - books[5]) + books[3] * (coordinates[1] - books[6])
                + books[4] * (coordinates[2] - books[7]))
        books[0] -= work
        books[1] += work
    books[5], books[6], books[7], books[8] = coordinates[0], coordinates[1], coordinates[2], 1.0


@jit
def _passive(books, fx, fy, fz, coordinates, rates, period, lapsed):
    """Return the force the port's passivity controller lets through (``PortPassivity``)."""
    _observe(books, coordinates)
    magnitude = math.sqrt(fx * fx + fy * fy + fz * fz)
    if magnitude == 0.0:
        if not lapsed:
            books[9] += period
        if books[9] >= BOOKS_CLOSE_AFTER:
            books[0] = 0.0
        books[2] = books[3] = books[4] = 0.0
        return 0.0, 0.0, 0.0
    books[9] = 0.0
    speed = (fx * rates[0] + fy * rates[1] + fz * rates[2]) / magnitude
    predicted = books[0] - magnitude * speed * period
    scale = 1.0
    if predicted < 0.0 and speed > 0.0 and period > 0.0:
        alpha = -predicted / (period * speed * speed)
        if books[10] < alpha:
            alpha = books[10]
        scale = 1.0 - alpha * speed / magnitude
        if not scale > 0.0:
            scale = 0.0
    books[2], books[3], books[4] = fx * scale, fy * scale, fz * scale
    return books[2], books[3], books[4]


@jit
def _forget(bound):
    """Nothing renders planes now (``LocalRenderer._forget``)."""
    bound[2] = bound[4] = bound[6] = bound[7] = bound[LAPSED] = 0.0


@jit
def _law_wrench(packed, books, bound, time, coordinates, rates, period):
    """Return what ``LocalRenderer.wrench`` renders this period: force and torque, saturated."""
    law = packed[0] if time + period > packed[0, SINCE] else packed[1]
    fx = fy = fz = tx = ty = tz = 0.0
    limit = law[0]
    mode, live = law[6], time + period <= law[DEADLINE]
    dx, dy, dz = coordinates[0] - law[10], coordinates[1] - law[11], coordinates[2] - law[12]
    if mode == MODE_WRENCH and live:
        fx, fy, fz, tx, ty, tz = law[13], law[14], law[15], law[16], law[17], law[18]
        _forget(bound)
    elif mode == MODE_PLANES and live and dx * dx + dy * dy + dz * dz <= law[9] * law[9]:
        if law[8] < limit:
            limit = law[8]
        _shift(law, coordinates, rates, books, bound, period)
        bound[LAPSED] = 0.0
        fx, fy, fz, tx, ty, tz = _planes(_scaled(_held_normals(law, bound), bound[3], bound[5]),
                                         coordinates, rates, limit, period, bound[0])
    elif mode == MODE_PLANES and not live:
        bound[LAPSED] = 1.0
    else:
        _forget(bound)
    fx, fy, fz = _passive(books, fx, fy, fz, coordinates, rates, period, not live)
    fx, fy, fz = _saturate(fx, fy, fz, limit)
    tx, ty, tz = _saturate(tx, ty, tz, law[1])
    return fx, fy, fz, tx, ty, tz


@jit
def advance(coordinates, rates, joints, targets, packed, books, bound, force_limit, torque_limit,
            start, first, step, rendered, edges, pushing):
    """Run ``len(targets)`` servo periods from period ``first``, in place.

    Adds each period's force and torque to ``rendered`` (6,), writes to ``edges`` the periods at
    which the force switched on or off, and returns (pushing after the last one, edges written).
    """
    written = 0
    for k in range(targets.shape[0]):
        done = first + k
        fx, fy, fz, tx, ty, tz = _law_wrench(packed, books, bound, start + done * step,
                                             coordinates, rates, step)
        fx, fy, fz = _saturate(fx, fy, fz, force_limit)
        tx, ty, tz = _saturate(tx, ty, tz, torque_limit)
        rendered[0] += fx
        rendered[1] += fy
        rendered[2] += fz
        rendered[3] += tx
        rendered[4] += ty
        rendered[5] += tz
        now_pushing = fx != 0.0 or fy != 0.0 or fz != 0.0
        if now_pushing != pushing:
            pushing = now_pushing
            edges[written] = done
            written += 1
        cy, sy = math.cos(coordinates[4]), math.sin(coordinates[4])
        efforts = (fx, fy, fz, cy * tx + sy * ty + 0.0 * tz, tz)
        for j in range(5):
            stiffness, damping, inverse_inertia, decay, lower, upper = (
                joints[j, 0], joints[j, 1], joints[j, 2], joints[j, 3], joints[j, 4],
                joints[j, 5])
            coordinate, rate = coordinates[j], rates[j]
            effort = efforts[j] + (stiffness * (targets[k, 0, j] - coordinate)
                                   + damping * (targets[k, 1, j] - rate))
            rate = (rate + step * effort * inverse_inertia) * decay
            coordinate += step * rate
            if coordinate < lower:
                coordinate = lower
                if rate < 0.0:
                    rate = 0.0
            elif coordinate > upper:
                coordinate = upper
                if rate > 0.0:
                    rate = 0.0
            coordinates[j], rates[j] = coordinate, rate
    return pushing, written


def compile_now() -> None:
    """Compile ``advance`` for the types the wand passes (or load it from numba's cache)."""
    advance(np.zeros(5), np.zeros(5), np.zeros((5, 6)), np.zeros((0, 2, 5)),
            np.zeros((2, LAW_SIZE)),
            np.zeros(11), np.zeros(BOUND_SIZE), 1.0, 1.0, 0.0, 0, 1.0,
            np.zeros(6),
            np.empty(0, dtype=np.int64), False)
