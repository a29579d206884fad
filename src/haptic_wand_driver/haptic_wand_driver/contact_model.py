"""A local model of the contact (``haptic_msgs/ContactModel``), checked and rendered on the device.

Why: a force computed from a pose one round trip old lags the motion, and a stiff wall then gives
energy back (it rebounds). The force renderer sends, with every answer, the planes of the surface
near the tool and their material; the device renders them against its *current* position at its
own servo rate, so the force lags by one servo period instead of a round trip.

Each plane pushes one point of the tool (its ``tool_point``, in the tip frame: zero for the tip
itself) with the force renderer's own law (``force_renderer.spring_damper``): a depth d behind the
plane gives K ⊙ (d·n) − C ⊙ v, never pulling. A plane is exact only at its point: on a surface of
curvature radius R, a tip that slid a distance s along it sees the plane off by about s²/(2R),
hence a force error of K·s²/(2R); ``valid_radius`` bounds s (``docs/local_rendering.md`` has the
figures on the cylinder and the hand).
"""
from dataclasses import dataclass
import enum
import math
from typing import NamedTuple, Sequence

from force_renderer.spring_damper import unilateral_spring_damper
from haptic_wand_driver.orientation import rotate
from haptic_wand_driver.wrench_input import saturate_components

__all__ = ['Kind', 'ModelRefused', 'Plane', 'ContactModel', 'MAX_PLANES', 'UNIT_TOLERANCE']

MAX_PLANES = 3
UNIT_TOLERANCE = 1e-6  # |normal| may differ from 1 by this much
Vector3 = tuple[float, float, float]
_PLANE_VECTORS = ('point', 'normal', 'stiffness', 'damping', 'tool_point')


class Kind(enum.IntEnum):
    """What a model holds, as ``haptic_msgs/ContactModel.KIND_*``."""

    FREE = 0
    PLANES = 1
    UNAVAILABLE = 2


_KINDS = {int(kind): kind for kind in Kind}  # a message's kind -> Kind, without Kind()'s cost


class ModelRefused(ValueError):
    """A model that must not be rendered; ``field`` names what is wrong with it."""

    def __init__(self, field: str, message: str) -> None:
        super().__init__(f'contact model refused: {field} {message}')
        self.field = field


class Plane(NamedTuple):
    """One plane of a model: see ``ContactPlane.msg``. Vectors (3,) float, SI units.

    A named tuple: one is built for every plane of every answer, at a third of a frozen
    dataclass's cost.
    """

    point: Vector3
    normal: Vector3
    stiffness: Vector3
    damping: Vector3
    tool_point: Vector3


@dataclass(frozen=True)
class ContactModel:
    """A checked model: every number finite, normals unit, gains and limits non-negative.

    Attributes
    ----------
    stamp : float, s
        The pose's stamp (ROS time).
    kind : Kind
    planes : tuple of Plane
    force_limit, valid_for, valid_radius : float
        N, s, m.
    tip : (3,) float, m
        The tip the model was made for.
    held_wrench : (6,) float
        The message's ``wrench``, the law's force (N) and torque (N·m): what the device holds
        when ``kind`` is ``UNAVAILABLE``.
    """

    stamp: float
    kind: Kind
    planes: tuple
    force_limit: float
    valid_for: float
    valid_radius: float
    tip: Vector3
    held_wrench: tuple

    @classmethod
    def from_fields(cls, fields: Sequence, frame_id: str) -> 'ContactModel':
        """Check the leaf fields of a ``ContactModel`` message and build the model.

        Raises ModelRefused naming the first bad field (an unknown frame, a NaN, a normal that
        is not unit, a negative gain, more than three planes, an unknown kind). It runs with
        every answer, so a model whose numbers are all finite and whose limits are not
        negative skips the field-by-field checks that find the culprit.
        """
        sec, nanosec, frame, _, kind, count = fields[:6]
        if frame != frame_id:
            raise ModelRefused('header.frame_id', f'is {frame!r}, not {frame_id!r}')
        if kind not in _KINDS:
            raise ModelRefused('kind', f'is {kind}, not one of {[k.value for k in Kind]}')
        if count > MAX_PLANES:
            raise ModelRefused('plane_count', f'is {count}, more than {MAX_PLANES}')
        force_limit, valid_for, valid_radius = fields[51:54]
        if not (all(map(math.isfinite, fields[51:63]))
                and all(map(math.isfinite, fields[6:6 + 15 * count]))
                and min(force_limit, valid_for, valid_radius) >= 0.0):
            _refuse(fields, count)
        planes = tuple(_plane(k, fields[6 + 15 * k:21 + 15 * k]) for k in range(count))
        model = object.__new__(cls)  # checked above: the dataclass's frozen __init__ costs more
        model.__dict__.update(
            stamp=sec + nanosec * 1e-9, kind=_KINDS[kind],
            planes=planes if kind == Kind.PLANES else (), force_limit=force_limit,
            valid_for=valid_for, valid_radius=valid_radius, tip=tuple(fields[54:57]),
            held_wrench=tuple(fields[57:63]))
        return model

    def valid(self, position: Sequence[float]) -> bool:
        """Whether ``position`` (3,) m is within ``valid_radius`` of the model's tip."""
        dx, dy, dz = (position[0] - self.tip[0], position[1] - self.tip[1],
                      position[2] - self.tip[2])
        return dx * dx + dy * dy + dz * dz <= self.valid_radius * self.valid_radius

    def springs(self, position: Sequence[float], roll: float,
                yaw: float) -> list[tuple[float, float]]:
        """Each plane's (depth of its tool point behind it, stiffness along its normal), m, N/m."""
        springs = []
        for plane in self.planes:
            n, k = plane.normal, plane.stiffness
            springs.append((_depth(plane, position, rotate(plane.tool_point, roll, yaw)),
                            k[0] * n[0] * n[0] + k[1] * n[1] * n[1] + k[2] * n[2] * n[2]))
        return springs

    def wrench(self, position: Sequence[float], velocity: Sequence[float], roll: float,
               yaw: float, angular_velocity: Sequence[float],
               contact_damping=None, limit: float = math.inf,
               shift: float = 0.0) -> tuple[Vector3, Vector3]:
        """Force (N) and torque about the tip (N·m) of the planes on the tool, world frame.

        ``position``, ``velocity`` (3,) are the tip's; ``roll``, ``yaw`` (rad) its orientation;
        ``angular_velocity`` (3,) rad/s, world frame. ``contact_damping(plane)`` (N·s/m) adds
        damping along a plane's normal while it pushes, never pulling (the device's own choice,
        see ``local_rendering``); None adds none. It acts on the plane's force saturated to
        ``limit`` (N): damping added to an unsaturated spring and then saturated is lost
        whenever the spring alone passes the limit, and a deep tap then comes back out as hard
        as it went in (at K = 1e5 N/m and 10 N the tool bounced off the wall). ``shift`` (m)
        moves every plane out along its normal (the port's bound on a switch,
        ``port_passivity.bounded_shift``).
        """
        fx = fy = fz = tx = ty = tz = 0.0
        for plane in self.planes:
            arm = rotate(plane.tool_point, roll, yaw)
            depth = _depth(plane, position, arm) - shift
            if depth <= 0.0:
                continue
            n = plane.normal
            spin = _cross(angular_velocity, arm)
            speed = (velocity[0] + spin[0], velocity[1] + spin[1], velocity[2] + spin[2])
            f = unilateral_spring_damper((depth * n[0], depth * n[1], depth * n[2]), n, speed,
                                         plane.stiffness, plane.damping)
            if contact_damping is not None:
                f = _damped_along(saturate_components(f, limit), n, speed,
                                  contact_damping(plane))
            t = _cross(arm, f)
            fx, fy, fz = fx + f[0], fy + f[1], fz + f[2]
            tx, ty, tz = tx + t[0], ty + t[1], tz + t[2]
        return (fx, fy, fz), (tx, ty, tz)


def _depth(plane: Plane, position: Sequence[float], arm: Vector3) -> float:
    """How far (m) the tool point at ``arm`` from the tip lies behind ``plane``."""
    n, p = plane.normal, plane.point
    return (n[0] * (p[0] - (position[0] + arm[0])) + n[1] * (p[1] - (position[1] + arm[1]))
            + n[2] * (p[2] - (position[2] + arm[2])))


def _damped_along(force: Vector3, normal: Vector3, velocity: Sequence[float],
                  damping: float) -> Vector3:
    """``force`` minus ``damping`` times the normal speed, along the normal, never pulling."""
    push = force[0] * normal[0] + force[1] * normal[1] + force[2] * normal[2]
    speed = velocity[0] * normal[0] + velocity[1] * normal[1] + velocity[2] * normal[2]
    change = max(-push, -damping * speed)
    return (force[0] + change * normal[0], force[1] + change * normal[1],
            force[2] + change * normal[2])


def _refuse(fields: Sequence, count: int) -> None:
    """Raise ModelRefused naming the first bad number, in the order the fields are read."""
    for name, value in zip(('force_limit', 'valid_for', 'valid_radius'), fields[51:54]):
        _non_negative(name, value)
    _finite('tip', fields[54:57])
    _finite('wrench', fields[57:63])
    for k in range(count):
        values = fields[6 + 15 * k:21 + 15 * k]
        for label, at in zip(_PLANE_VECTORS, range(0, 15, 3)):
            _finite(f'planes[{k}].{label}', values[at:at + 3])
        _plane(k, values)


def _plane(k: int, values: Sequence[float]) -> Plane:
    """Return plane k of a model whose numbers are finite, its gains and normal checked."""
    if min(values[6:12]) < 0.0:
        for label, at in (('stiffness', 6), ('damping', 9)):
            if min(values[at:at + 3]) < 0.0:
                raise ModelRefused(f'planes[{k}].{label}',
                                   f'is negative: {list(values[at:at + 3])}')
    nx, ny, nz = values[3:6]
    norm = math.sqrt(0.0 + nx * nx + ny * ny + nz * nz)  # the order sum() adds them in
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise ModelRefused(f'planes[{k}].normal', f'is not unit (|n| = {norm:.9g})')
    return Plane(tuple(values[0:3]), (nx, ny, nz), tuple(values[6:9]), tuple(values[9:12]),
                 tuple(values[12:15]))


def _finite(name: str, vector: Sequence[float]) -> None:
    if not all(math.isfinite(c) for c in vector):
        raise ModelRefused(name, f'is not finite: {list(vector)}')


def _non_negative(name: str, value: float) -> None:
    if not (math.isfinite(value) and value >= 0.0):
        raise ModelRefused(name, f'must be finite and >= 0, got {value}')


def _cross(a: Sequence[float], b: Sequence[float]) -> Vector3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
