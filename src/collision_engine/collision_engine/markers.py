"""RViz markers for the scene's objects and the current contact.

A mesh must not be published by its ``file://`` path: that names the machine's folders to every
subscriber (user names, project layout), and the path means nothing on the machine running
RViz anyway. A mesh inside an installed package's share folder is published as the
``package://<pkg>/<path>`` URI RViz resolves on its own machine. Any other mesh is published as
a ``TRIANGLE_LIST`` of its own triangles, in metres: it leaks nothing but the geometry RViz is
there to draw, and shows the exact surface the engine queries, where a bounding shape would hide
the very concavities (the gaps between fingers) that set the distance. Its cost is the triangles
themselves, 3 points of 24 bytes each a message (about 0.8 MB for an 11k-triangle hand, sent at
the node's marker rate): for a large mesh, install it in a package.
"""
import math
from pathlib import Path

from geometry_msgs.msg import Point, Pose, Quaternion
from scipy.spatial.transform import Rotation
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker

from collision_engine.scene_file import (BoxSpec, CapsuleSpec, CylinderSpec, MeshSpec,
                                         SceneSpec, SphereSpec)

__all__ = ['contact_markers', 'package_uri', 'scene_markers']

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
    """Mark the closest point (red in contact, green outside) and the tip-to-surface segment.

    ``result`` is a tip's ``QueryResult`` or a tool's ``ToolResult``: the segment starts at its
    row's tip slot, the tip or the tool's witness.
    """
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
    segment.points = [_point(result.row[10:13]), _point(result.point)]
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
        return [_mesh_marker(shape)]
    raise TypeError(f'no marker for shape {shape!r}')


def _mesh_marker(shape: MeshSpec) -> Marker:
    """Show a mesh by its package:// URI, else by its triangles (module docstring)."""
    uri = package_uri(shape.file)
    if uri is not None:
        marker = _primitive(Marker.MESH_RESOURCE, shape.scale, shape.scale, shape.scale)
        marker.mesh_resource = uri
        return marker
    from collision_engine.mesh_io import load_mesh

    mesh = load_mesh(shape.file, scale=shape.scale, check_self_intersection=False)
    marker = _primitive(Marker.TRIANGLE_LIST, 1.0, 1.0, 1.0)
    marker.points = [_point(corner) for corner in mesh.vertices[mesh.faces].reshape(-1, 3)]
    return marker


def package_uri(file: Path) -> str | None:
    """``package://<pkg>/<path>`` of a file inside an installed package's share folder, or None.

    The package whose share folder holds the file most deeply wins; both sides are compared with
    symlinks resolved (as ``haptic_util.paths.package_file`` maps the URI back).
    """
    from ament_index_python.packages import get_packages_with_prefixes

    target = Path(file).resolve()
    try:
        packages = get_packages_with_prefixes()
    except OSError:  # no AMENT_PREFIX_PATH: no package is installed
        return None
    best = None
    for package, prefix in packages.items():
        share = (Path(prefix) / 'share' / package).resolve()
        deeper = best is None or len(share.parts) > len(best[1].parts)
        if target.is_relative_to(share) and deeper:
            best = package, share
    if best is None:
        return None
    package, share = best
    return f'package://{package}/{target.relative_to(share).as_posix()}'


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
