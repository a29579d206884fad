"""Easing a new contact model into the hand: no step, and still no more energy than was put in.

Why: a model-mediated link sends a new estimate of the contact every few milliseconds. Each one
moves the plane or changes its stiffness a little, and rendered at once the felt force steps by
what the estimate moved since the last one came (in the telerobotic scan at 250 ms one way, 2.8 N
in one tick, scaled to the patient, where the patient's force changed by 0.02 N). A sonographer
reads tissue by differences of a few tenths of a newton: a step the patient's force did not make
is a jolt.

So a new model's planes start as stiff and as damped as the planes rendered the period before
(their stiffnesses scaled by one factor, a damping added to each plane's) and shifted along their
normals to where they push (their springs, the sum of k·depth over the planes behind) what those
pushed: the force and the stored energy go on from where they were. The factor, the added damping
and the shift then ease toward the model as it is, each at most ``rate`` N/s of spring push (the
damping at most that much force at the tip's speed), and the hand's own motion is felt at once,
as before. The damping matters at a
lift-off: the estimate's damping moves between updates (from nothing to some), and on a hand
moving at 3 cm/s that stepped the felt force by 0.09 N (scaled) in a tick. It is added, not a
factor on the model's own: an estimate's damping falls to zero now and then (its fit is clamped
there), no factor carries the damping felt onto that, and on a hand pressing in at 3 cm/s the
damping felt dropped at once by 0.06 N (scaled), the largest step of the scan at 100 ms. Scaling
the stiffness matters too: an estimate that turns softer at the same push stores more
energy than the port absorbed, and the bound below would cut the force at once (in the scan at
250 ms, 0.5 N in a tick at the first contact). A model that comes after nothing was rendered (a
first contact) starts from zero push, a ramp. One that comes after a lapse (models that stopped
coming for a while: a silent link, a stalled tick) starts from the push before it, as far as it
pushes itself where the tool now is: the hand that sank while it felt nothing finds the force it
left, as the remote end, which never saw the lapse, still presses the patient. A ramp from zero
there let the hand sink further and the robot follow it in (one core hogged, ``test_hostile_link``:
17.5 N at the patient against 3.9-5 N felt, scaled, for 2 s).

The planes' normals go on too: each is rendered as it was the period before and turns toward the
model's by at most ``rate`` / push radians a period, so that the push turning moves sideways by
at most ``rate`` N/s. The estimate's normal is the measured force's direction, low-passed; models
that reach the hand tens of milliseconds apart (the link's jitter, its losses) turned it by half
a degree, and a 7 N push (scaled) stepped sideways by 0.06 N, the largest steps at 250 and 500 ms
once the damping was eased. A normal turned further than ``EASED_TURN`` is another face (a
corner's planes come in any order) and is taken at once; the planes are matched by their order.

Passive: the switch itself stores what the planes before stored (the same push on the same
stiffness, the same normals), a damping (never below zero) only takes energy out, and each period's
easing may raise the stored energy only up to what the port has absorbed in this contact
(``port_passivity.bounded_shift``, here also inward of the model when the new estimate pushes less
than the old one did), as passive set-position modulation does (Lee and Huang, IEEE T-RO 2010);
beyond, the shift holds. The hand's own motion into the planes is not bounded again: that is the
spring it feels.

``springs`` are each plane's (depth of its tool point behind it, stiffness along its normal), m and
N/m (``ContactModel.springs``); a shift is m, outward along the normals. ``servo_loop`` computes
the same floats, compiled.
"""
import dataclasses
import math

from haptic_contract.contact_model import ContactModel
from haptic_wand_driver.port_passivity import bounded_shift

__all__ = ['COS_EASED_TURN', 'EASED_TURN', 'eased_extra', 'eased_scale', 'eased_shift',
           'held_normals', 'least_shift', 'matched_extra', 'matched_shift', 'scaled_model',
           'spring_push', 'stored_energy', 'total_damping', 'total_stiffness', 'turned_normals']

EASED_TURN = math.radians(10.0)  # [rad] a normal turned further is another face: at once
COS_EASED_TURN = math.cos(EASED_TURN)


def total_stiffness(springs) -> float:
    """Return the sum of the planes' stiffnesses along their normals (N/m), in plane order."""
    total = 0.0
    for _, k in springs:
        if k > 0.0:
            total += k
    return total


def spring_push(springs, shift: float) -> float:
    """Return the planes' spring push (N) with the planes moved out by ``shift``."""
    push = 0.0
    for depth, stiffness in springs:
        if depth - shift > 0.0:
            push += stiffness * (depth - shift)
    return push


def total_damping(model: ContactModel, extra: float = 0.0) -> float:
    """Return the sum of the planes' dampings along their normals (N·s/m), in plane order.

    Each with ``extra`` (N·s/m) added on every axis, and none below zero.
    """
    total = 0.0
    for plane in model.planes:
        n, c = plane.normal, plane.damping
        along = (max(c[0] + extra, 0.0) * n[0] * n[0] + max(c[1] + extra, 0.0) * n[1] * n[1]
                 + max(c[2] + extra, 0.0) * n[2] * n[2])
        if along > 0.0:
            total += along
    return total


def stored_energy(springs, shift: float) -> float:
    """Return the energy (J) the planes' springs store, moved out by ``shift``."""
    energy = 0.0
    for depth, stiffness in springs:
        if depth - shift > 0.0:
            energy += 0.5 * stiffness * (depth - shift) * (depth - shift)
    return energy


def matched_shift(springs, push: float) -> float:
    """Return the shift at which the planes' springs push ``push`` (N).

    Negative when they push less than that as they are. With nothing to match (zero push), the
    planes are moved just onto the tool (not inward of the model).
    """
    behind = sorted(((d, k) for d, k in springs if k > 0.0), reverse=True)
    a = b = 0.0
    for m, (depth, stiffness) in enumerate(behind):
        a += stiffness
        b += stiffness * depth
        shift = (b - push) / a
        if m + 1 == len(behind) or shift >= behind[m + 1][0]:
            return shift if push > 0.0 else max(shift, 0.0)
    return 0.0


def least_shift(springs, energy: float, lowest: float) -> float:
    """Return the least shift, from ``lowest`` on, at which the planes store at most ``energy``."""
    return bounded_shift([(d - lowest, k) for d, k in springs], energy) + lowest


def eased_shift(springs, shift: float, push_step: float) -> float:
    """Return ``shift`` moved toward zero by what changes the springs' push by ``push_step``."""
    stiffness = total_stiffness(springs)
    if stiffness == 0.0:
        return 0.0
    step = push_step / stiffness
    return max(shift - step, 0.0) if shift > 0.0 else min(shift + step, 0.0)


def eased_scale(scale: float, push_step: float, push: float) -> float:
    """Return the stiffness factor ``scale`` moved toward 1, changing ``push`` by ``push_step``.

    1 at once when nothing pushes.
    """
    if push <= 0.0:
        return 1.0
    step = push_step * scale / push
    return min(scale + step, 1.0) if scale < 1.0 else max(scale - step, 1.0)


def matched_extra(model: ContactModel, damped: float) -> float:
    """Return the damping (N·s/m) to add to each plane's for their sum to be ``damped``."""
    if not model.planes:
        return 0.0
    return (damped - total_damping(model)) / len(model.planes)


def eased_extra(extra: float, push_step: float, push: float, velocity, count: int) -> float:
    """Return the damping ``extra`` added to each of ``count`` planes moved toward 0.

    By as much as changes their force on the tip at ``velocity`` (m/s) by ``push_step`` (N) at
    most; 0 at once when nothing pushes or the tip is still.
    """
    speed = count * math.sqrt(velocity[0] * velocity[0] + velocity[1] * velocity[1]
                              + velocity[2] * velocity[2])
    if push <= 0.0 or speed == 0.0:
        return 0.0
    step = push_step / speed
    return min(extra + step, 0.0) if extra < 0.0 else max(extra - step, 0.0)


def held_normals(model: ContactModel, held) -> ContactModel:
    """Return ``model`` with the normals ``held`` where each is within ``EASED_TURN`` of its own.

    ``held``: the count of planes rendered the period before, then their normals, 3 floats each;
    ``model`` as it is when they were not as many as its planes.
    """
    count = len(model.planes)
    if held[0] != count or count == 0:
        return model
    planes = []
    for k, plane in enumerate(model.planes):
        h = (float(held[1 + 3 * k]), float(held[2 + 3 * k]), float(held[3 + 3 * k]))
        n = plane.normal
        along = h[0] * n[0] + h[1] * n[1] + h[2] * n[2]
        planes.append(plane._replace(normal=h) if along >= COS_EASED_TURN else plane)
    return dataclasses.replace(model, planes=tuple(planes))


def turned_normals(model: ContactModel, toward: ContactModel, push_step: float,
                   push: float) -> ContactModel:
    """Return ``model``, each normal turned toward ``toward``'s by ``push_step`` / ``push`` rad.

    At most: a push turning by that angle moves sideways by ``push_step``. At once when nothing
    pushes, or by more than ``EASED_TURN``.
    """
    return dataclasses.replace(model, planes=tuple(
        plane._replace(normal=_turned(plane.normal, goal.normal, push_step, push))
        for plane, goal in zip(model.planes, toward.planes)))


def _turned(normal, toward, push_step: float, push: float):
    along = normal[0] * toward[0] + normal[1] * toward[1] + normal[2] * toward[2]
    if push <= 0.0 or along < COS_EASED_TURN:
        return toward
    angle = push_step / push
    if angle >= EASED_TURN or along >= math.cos(angle):
        return toward
    x, y, z = (toward[0] - along * normal[0], toward[1] - along * normal[1],
               toward[2] - along * normal[2])
    length = math.sqrt(x * x + y * y + z * z)
    cos, sin = math.cos(angle), math.sin(angle)
    return (normal[0] * cos + x / length * sin, normal[1] * cos + y / length * sin,
            normal[2] * cos + z / length * sin)


def scaled_model(model: ContactModel, scale: float, extra: float) -> ContactModel:
    """Return ``model`` with its planes' stiffnesses times ``scale``, ``extra`` on their dampings.

    A damping never below zero.
    """
    if scale == 1.0 and extra == 0.0:
        return model
    return dataclasses.replace(model, planes=tuple(plane._replace(
        stiffness=(plane.stiffness[0] * scale, plane.stiffness[1] * scale,
                   plane.stiffness[2] * scale),
        damping=(max(plane.damping[0] + extra, 0.0), max(plane.damping[1] + extra, 0.0),
                 max(plane.damping[2] + extra, 0.0))) for plane in model.planes))
