"""RViz markers for the scene's objects and the current contact."""
import math

from geometry_msgs.msg import Point, Pose, Quaternion
from scipy.spatial.transform import Rotation
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker

from collision_engine.scene_file import (BoxSpec, CapsuleSpec, CylinderSpec, MeshSpec,
                                         SceneSpec, SphereSpec)

__all__ = ['scene_markers', 'contact_markers']

OBJECT_COLOR = ColorRGBA(r=0.8, g=0.7, b=0.6, a=0.6)
CONTACT_COLOR = ColorRGBA(r=1.0, g=0.2, b=0.1, a=1.0)
FREE_COLOR = ColorRGBA(r=0.2, g=0.8, b=0.2, a=1.0)
CONTACT_MARKER_SIZE = 0.004  # [m]


def scene_markers(spec: SceneSpec) -> list:
    """One marker per scene object (a capsule is a cylinder and two spheres)."""
    markers = []
    for obj in spec.objects:
        pose = _pose(obj.pose.rotation, obj.pose.translation)
        for marker in _shape_markers(obj.shape):
            marker.header.frame_id = spec.frame_id
            marker.ns = f'scene/{obj.name}'
            marker.id = len(markers)
            marker.pose = _compose(pose, marker.pose)
            marker.color = OBJECT_COLOR
            marker.frame_locked = True
            markers.append(marker)
    return markers


def contact_markers(result, frame_id: str) -> list:
    """Mark the closest point (red in contact, green outside) and the tip-to-surface segment."""
    if result is None or not math.isfinite(result.distance):
        return []
    color = CONTACT_COLOR if result.in_collision else FREE_COLOR
    size = CONTACT_MARKER_SIZE
    point = Marker(ns='contact/point', id=0, type=Marker.SPHERE, action=Marker.ADD)
    point.pose.position = _point(result.point)
    point.pose.orientation.w = 1.0
    point.scale.x = point.scale.y = point.scale.z = size
    segment = Marker(ns='contact/segment', id=1, type=Marker.LINE_LIST, action=Marker.ADD)
    segment.pose.orientation.w = 1.0
    segment.points = [_point(result.tip), _point(result.point)]
    segment.scale.x = size / 4
    for marker in (point, segment):
        marker.header.frame_id = frame_id
        marker.color = color
    return [point, segment]


def _shape_markers(shape) -> list:
    if isinstance(shape, BoxSpec):
        return [_primitive(Marker.CUBE, *shape.size)]
    if isinstance(shape, SphereSpec):
        return [_primitive(Marker.SPHERE, *(2 * shape.radius,) * 3)]
    if isinstance(shape, CylinderSpec):
        d = 2 * shape.radius
        return [_primitive(Marker.CYLINDER, d, d, shape.height)]
    if isinstance(shape, CapsuleSpec):
        d, half = 2 * shape.radius, shape.length / 2
        caps = [_primitive(Marker.SPHERE, d, d, d, z=z) for z in (-half, half)]
        return [_primitive(Marker.CYLINDER, d, d, shape.length), *caps]
    if isinstance(shape, MeshSpec):
        marker = _primitive(Marker.MESH_RESOURCE, shape.scale, shape.scale, shape.scale)
        marker.mesh_resource = shape.file.resolve().as_uri()
        return [marker]
    raise TypeError(f'no marker for shape {shape!r}')


def _primitive(kind: int, sx: float, sy: float, sz: float, *, z: float = 0.0) -> Marker:
    marker = Marker(type=kind, action=Marker.ADD)
    marker.scale.x, marker.scale.y, marker.scale.z = float(sx), float(sy), float(sz)
    marker.pose.position.z = float(z)
    marker.pose.orientation.w = 1.0
    return marker


def _pose(rotation, translation) -> tuple:
    return Rotation.from_matrix(rotation), tuple(float(v) for v in translation)


def _compose(object_pose: tuple, local: Pose) -> Pose:
    rotation, translation = object_pose
    offset = rotation.apply([local.position.x, local.position.y, local.position.z])
    x, y, z, w = rotation.as_quat()
    return Pose(position=Point(x=translation[0] + offset[0], y=translation[1] + offset[1],
                               z=translation[2] + offset[2]),
                orientation=Quaternion(x=x, y=y, z=z, w=w))


def _point(values) -> Point:
    return Point(x=float(values[0]), y=float(values[1]), z=float(values[2]))
