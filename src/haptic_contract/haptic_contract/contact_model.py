"""A local model of the contact (``haptic_msgs/ContactModel``): values, checks and fields.

Why: a force computed from a pose one round trip old lags the motion, and a stiff wall then gives
energy back (it rebounds). The force renderer sends, with every answer, the planes of the surface
near the tool and their material; the device renders them against its *current* position at its
own servo rate, so the force lags by one servo period instead of a round trip.

Each plane pushes one point of the tool (its ``tool_point``, in the tip frame: zero for the tip
itself) with the renderer's own law (``plane_law``): a depth d behind the plane gives
K ⊙ (d·n) − C ⊙ v, never pulling. A plane is exact only at its point: on a surface of
curvature radius R, a tip that slid a distance s along it sees the plane off by about s²/(2R),
hence a force error of K·s²/(2R); ``valid_radius`` bounds s (``docs/local_rendering.md`` has the
figures on the cylinder and the hand).

Producers (the force renderer, the operator's leader) write a model with ``model_fields``, the
device reads one with ``ContactModel.from_fields``: the message's layout is looked up here, by
field name, and nowhere else.
"""
from dataclasses import dataclass
import enum
import functools
import math
import re
from typing import NamedTuple, Sequence

from haptic_contract.fields import span
from haptic_contract.plane_law import damped_along, saturate_components, unilateral_spring_damper
from haptic_contract.wand import rotate
from haptic_msgs.msg import ContactModel as ContactModelMessage

__all__ = ['Kind', 'MAX_PLANES', 'ModelRefused', 'Plane', 'ContactModel', 'UNIT_TOLERANCE',
           'model_fields']  # and MODEL, the codec (``__getattr__``)

# ContactPlane[3]: read from the definition's types, which imports nothing more.
MAX_PLANES = int(re.search(r'\[(\d+)\]', ContactModelMessage.get_fields_and_field_types()
                           ['planes'])[1])
UNIT_TOLERANCE = 1e-6  # |normal| may differ from 1 by this much
Vector3 = tuple[float, float, float]
_PLANE_VECTORS = ('point', 'normal', 'stiffness', 'damping', 'tool_point')
_ZERO = (0.0, 0.0, 0.0)


class _Layout(NamedTuple):
    """Where a ContactModel's fields sit in the codec's tuple: slices, found by name."""

    codec: object  # haptic_util.cdr.MessageCodec
    header: slice  # stamp, frame, object, kind, plane count
    planes: slice
    plane_size: int
    limits: slice  # force limit, valid for, valid radius
    numbers: slice  # the limits, the tip and the wrench
    tip: slice
    wrench: slice
    at: dict  # within one plane's leaves, where each vector starts

    def plane(self, k: int) -> slice:
        """Return the slice of plane ``k``'s leaves."""
        start = self.planes.start + self.plane_size * k
        return slice(start, start + self.plane_size)


@functools.cache
def _layout() -> _Layout:
    """Build the codec and find the fields, once, on first use.

    Not at import: the codec imports the message's nested types (geometry_msgs), which a
    device's core that never reads a message must not load.
    """
    from haptic_util.cdr import MessageCodec

    codec = MessageCodec(ContactModelMessage)
    planes = span(codec, 'planes[0].point.x', f'planes[{MAX_PLANES - 1}].tool_point.z')
    return _Layout(
        codec, span(codec, 'header.stamp.sec', 'plane_count'), planes,
        (planes.stop - planes.start) // MAX_PLANES, span(codec, 'force_limit', 'valid_radius'),
        span(codec, 'force_limit', 'wrench.torque.z'), span(codec, 'tip.x', 'tip.z'),
        span(codec, 'wrench.force.x', 'wrench.torque.z'),
        {name: codec.index(f'planes[0].{name}.x') - planes.start for name in _PLANE_VECTORS})


def __getattr__(name: str):
    """``MODEL``, the ContactModel codec, is built on first use (see ``_layout``)."""
    if name == 'MODEL':
        return _layout().codec
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')


class Kind(enum.IntEnum):
    """What a model holds, as ``haptic_msgs/ContactModel.KIND_*``."""

    FREE = ContactModelMessage.KIND_FREE
    PLANES = ContactModelMessage.KIND_PLANES
    UNAVAILABLE = ContactModelMessage.KIND_UNAVAILABLE


_KINDS = {int(kind): kind for kind in Kind}  # a message's kind -> Kind, without Kind()'s cost


def model_fields(header: tuple, name: str, kind: int, planes: Sequence, force_limit: float,
                 valid_for: float, valid_radius: float, tip: Sequence[float],
                 wrench: Sequence[float], plane_count: int | None = None) -> tuple:
    """Return the leaf fields of a ContactModel message.

    ``header`` is (sec, nanosec, frame_id), ``name`` the object's; each plane is (point,
    normal, stiffness, damping[, tool_point]), (3,) each (no tool point: the tip itself);
    ``wrench`` (6,) the law's force and torque. ``plane_count`` is ``len(planes)`` unless set
    (a test's malformed model).
    """
    values = [value for plane in planes
              for value in (*plane[0], *plane[1], *plane[2], *plane[3],
                            *(plane[4] if len(plane) > 4 else _ZERO))]
    slots = _layout().planes
    values += [0.0] * (slots.stop - slots.start - len(values))
    count = len(planes) if plane_count is None else plane_count
    return (*header, name, int(kind), count, *values, force_limit, valid_for, valid_radius, *tip,
            *wrench)


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
        at = _layout()
        sec, nanosec, frame, _, kind, count = fields[at.header]
        if frame != frame_id:
            raise ModelRefused('header.frame_id', f'is {frame!r}, not {frame_id!r}')
        if kind not in _KINDS:
            raise ModelRefused('kind', f'is {kind}, not one of {[k.value for k in Kind]}')
        if count > MAX_PLANES:
            raise ModelRefused('plane_count', f'is {count}, more than {MAX_PLANES}')
        force_limit, valid_for, valid_radius = fields[at.limits]
        if not (all(map(math.isfinite, fields[at.numbers]))
                and all(map(math.isfinite, fields[at.planes.start:at.plane(count).start]))
                and min(force_limit, valid_for, valid_radius) >= 0.0):
            _refuse(fields, count)
        planes = tuple(_plane(k, fields[at.plane(k)]) for k in range(count))
        model = object.__new__(cls)  # checked above: the dataclass's frozen __init__ costs more
        model.__dict__.update(
            stamp=sec + nanosec * 1e-9, kind=_KINDS[kind],
            planes=planes if kind == Kind.PLANES else (), force_limit=force_limit,
            valid_for=valid_for, valid_radius=valid_radius, tip=tuple(fields[at.tip]),
            held_wrench=tuple(fields[at.wrench]))
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
                f = damped_along(saturate_components(f, limit), n, speed,
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


def _refuse(fields: Sequence, count: int) -> None:
    """Raise ModelRefused naming the first bad number, in the order the fields are read."""
    at = _layout()
    for name, value in zip(('force_limit', 'valid_for', 'valid_radius'), fields[at.limits]):
        _non_negative(name, value)
    _finite('tip', fields[at.tip])
    _finite('wrench', fields[at.wrench])
    for k in range(count):
        values = fields[at.plane(k)]
        for label in _PLANE_VECTORS:
            _finite(f'planes[{k}].{label}', values[at.at[label]:at.at[label] + 3])
        _plane(k, values)


def _plane(k: int, values: Sequence[float]) -> Plane:
    """Return plane k of a model whose numbers are finite, its gains and normal checked."""
    at = _layout().at
    point, normal, stiffness, damping, tool_point = (
        tuple(values[at[name]:at[name] + 3]) for name in _PLANE_VECTORS)
    if min(stiffness + damping) < 0.0:
        for label, gains in (('stiffness', stiffness), ('damping', damping)):
            if min(gains) < 0.0:
                raise ModelRefused(f'planes[{k}].{label}', f'is negative: {list(gains)}')
    nx, ny, nz = normal
    norm = math.sqrt(0.0 + nx * nx + ny * ny + nz * nz)  # the order sum() adds them in
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise ModelRefused(f'planes[{k}].normal', f'is not unit (|n| = {norm:.9g})')
    return Plane(point, (nx, ny, nz), stiffness, damping, tool_point)


def _finite(name: str, vector: Sequence[float]) -> None:
    if not all(math.isfinite(c) for c in vector):
        raise ModelRefused(name, f'is not finite: {list(vector)}')


def _non_negative(name: str, value: float) -> None:
    if not (math.isfinite(value) and value >= 0.0):
        raise ModelRefused(name, f'must be finite and >= 0, got {value}')


def _cross(a: Sequence[float], b: Sequence[float]) -> Vector3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
