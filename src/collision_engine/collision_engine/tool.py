"""A convex tool (the probe) prepared for scene queries: validated, packed, with its point shell.

The tool is any convex shape of ``shapes`` in its own frame. What ``Scene.query_tool`` needs of
it is packed once per tool object and kept: its kind and support data, its radius (a sphere's or
a capsule's, measured apart as in ``narrowphase``), its bounding sphere, and its point shell.

The point shell is the overlap method against a non-convex mesh (``tool_query``): points on the
surface of the tool's core (the centre of a sphere, the axis of a capsule, the whole surface of
a box, cylinder or convex mesh) no farther than ``spacing`` from their neighbours along the
surface, corners and edges included. The deepest of them by the mesh's exact signed distance is
the tool's deepest point. Polytope corners are in the shell, so a flat face pressed on a flat
surface is measured exactly; a bump of the surface narrower than the spacing can reach between
shell points, undercounting the depth by at most the bump's height over one spacing.
"""

from dataclasses import dataclass
import math
from pathlib import Path
import weakref

import numpy as np

from collision_engine.errors import MeshError
from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere
from collision_engine.support import pack_convex
from collision_engine.transforms import Pose

__all__ = ['BOX_FLOATS', 'DEFAULT_SHELL_SPACING', 'FLOAT_HEADER', 'INT_HEADER',
           'MAX_FACE_POINTS', 'MEASURED_FLOATS', 'MountedTool', 'face_shell', 'load_tool',
           'mount_tool', 'pack_tool', 'point_shell']

DEFAULT_SHELL_SPACING = 0.005  # m
FLOAT_HEADER = 8  # radius, bounding radius, bounding centre (3), spacing, shell at, work at
INT_HEADER = 2  # kind, shell points
BOX_FLOATS = 25  # the tool's extents in an object's frame (``tool_mesh._set_tool_box``)
MEASURED_FLOATS = 8  # a shell point measured: itself, a bound, a surface point, its triangle
MAX_FACE_POINTS = 32  # as haptic_msgs/CollisionState's contact sequences
_FACE_TOLERANCE = 1e-9  # m: a hull vertex this near the lowest z lies on the face
_CONVEX = (Box, Sphere, Cylinder, Capsule, ConvexMesh)
_PACKED = weakref.WeakKeyDictionary()


def _steps(length: float, spacing: float) -> np.ndarray:
    """Coordinates from -length/2 to +length/2, no more than ``spacing`` apart."""
    return np.linspace(-0.5 * length, 0.5 * length, int(math.ceil(length / spacing)) + 1)


def _box_shell(size, spacing: float) -> np.ndarray:
    axes = [_steps(s, spacing) for s in size]
    grid = np.stack(np.meshgrid(*axes, indexing='ij'), axis=-1).reshape(-1, 3)
    on_surface = np.any(np.abs(grid) == 0.5 * np.asarray(size), axis=1)
    return grid[on_surface]


def _ring(radius: float, z: float, spacing: float) -> np.ndarray:
    count = max(8, int(math.ceil(2.0 * math.pi * radius / spacing)))
    angles = 2.0 * math.pi * np.arange(count) / count
    return np.column_stack((radius * np.cos(angles), radius * np.sin(angles),
                            np.full(count, z)))


def _cylinder_shell(radius: float, height: float, spacing: float) -> np.ndarray:
    side = [_ring(radius, z, spacing) for z in _steps(height, spacing)]
    caps = [_ring(r, z, spacing) for z in (-0.5 * height, 0.5 * height)
            for r in np.linspace(0.0, radius, int(math.ceil(radius / spacing)) + 1)[1:-1]]
    centres = [[0.0, 0.0, -0.5 * height], [0.0, 0.0, 0.5 * height]]
    return np.vstack(side + caps + [centres])


def _hull_shell(shape: ConvexMesh, spacing: float) -> np.ndarray:
    points = [shape.vertices]
    for corners in shape.vertices[shape.faces]:
        longest = max(np.linalg.norm(corners - np.roll(corners, 1, axis=0), axis=1))
        n = int(math.ceil(longest / spacing))
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing='ij')
        keep = i + j <= n
        weights = np.column_stack((i[keep], j[keep], n - i[keep] - j[keep])) / n
        points.append(weights @ corners)
    return np.unique(np.vstack(points), axis=0)


def point_shell(shape, spacing: float = DEFAULT_SHELL_SPACING) -> np.ndarray:
    """Return the tool core's point shell (module docstring).

    Parameters
    ----------
    shape : Box, Sphere, Cylinder, Capsule or ConvexMesh
    spacing : float, m
        The largest gap between neighbouring shell points along the surface.

    Returns
    -------
    (n, 3) float64, m, the tool's frame
    """
    if isinstance(shape, Sphere):
        return np.zeros((1, 3))
    if isinstance(shape, Capsule):
        z = _steps(shape.length, spacing)
        return np.column_stack((np.zeros_like(z), np.zeros_like(z), z))
    if isinstance(shape, Box):
        return _box_shell(shape.size, spacing)
    if isinstance(shape, Cylinder):
        return _cylinder_shell(shape.radius, shape.height, spacing)
    return _hull_shell(shape, spacing)


def _cell_centres(lower, upper, spacing: float) -> np.ndarray:
    """Centres (m, 2) of a grid of cells no wider than ``spacing`` over a rectangle."""
    axes = []
    for low, high in zip(lower, upper):
        count = max(1, int(math.ceil((high - low) / spacing - 1e-9)))
        axes.append(low + (np.arange(count) + 0.5) * (high - low) / count)
    return np.stack(np.meshgrid(*axes, indexing='ij'), axis=-1).reshape(-1, 2)


def _on_z(points: np.ndarray, z: float) -> np.ndarray:
    return np.column_stack((points, np.full(len(points), z)))


def _hull_face(shape: ConvexMesh, spacing: float) -> np.ndarray:
    """Cell centres inside the hull's lowest face, or its lowest vertices if it has no face."""
    from scipy.spatial import ConvexHull, QhullError

    z = shape.vertices[:, 2].min()
    corners = shape.vertices[shape.vertices[:, 2] <= z + _FACE_TOLERANCE][:, :2]
    try:
        outline = ConvexHull(corners)
    except (QhullError, ValueError):  # a vertex or an edge at the bottom: no area to share
        return _on_z(corners, z)
    cells = _cell_centres(corners.min(axis=0), corners.max(axis=0), spacing)
    inside = np.all(cells @ outline.equations[:, :2].T + outline.equations[:, 2] <= 0.0, axis=1)
    return _on_z(cells[inside], z)


def face_shell(shape, spacing: float) -> tuple[np.ndarray, float]:
    """Return the tool's contact face as points, and the radius to add to them (module doc).

    Parameters
    ----------
    shape : Box, Sphere, Cylinder, Capsule or ConvexMesh
    spacing : float, m
        The widest cell of the grid on the face.

    Returns
    -------
    points : (n, 3) float64, m, the tool's frame
    radius : float, m
        The tool's surface lies this far out of the points (0 but for a sphere or capsule).
    """
    if isinstance(shape, Sphere):
        return np.zeros((1, 3)), shape.radius
    if isinstance(shape, Capsule):
        return np.array([[0.0, 0.0, -0.5 * shape.length]]), shape.radius
    if isinstance(shape, Box):
        half = 0.5 * np.asarray(shape.size)
        return _on_z(_cell_centres(-half[:2], half[:2], spacing), -half[2]), 0.0
    if isinstance(shape, Cylinder):
        r = shape.radius
        cells = _cell_centres((-r, -r), (r, r), spacing)
        inside = cells[np.einsum('ij,ij->i', cells, cells) <= r * r]
        return _on_z(inside if len(inside) else np.zeros((1, 2)), -0.5 * shape.height), 0.0
    return _hull_face(shape, spacing), 0.0


@dataclass(frozen=True, eq=False)
class MountedTool:
    """A tool on the wand: its shape, its frame in the tip's, and its contact face.

    Attributes
    ----------
    shape : Box, Sphere, Cylinder, Capsule or ConvexMesh
        In its own frame.
    offset : Pose
        The tool's frame in the tip frame.
    offset_quaternion : tuple of 4 float
        The offset's rotation, (x, y, z, w).
    face : (n, 3) float64, m, the tip frame
        The contact face's points (``face_shell``), n <= ``MAX_FACE_POINTS``.
    radius : float, m
        The surface lies this far out of the face points.
    """

    shape: object
    offset: Pose
    offset_quaternion: tuple
    face: np.ndarray
    radius: float


def mount_tool(shape, offset: Pose, *, face_spacing: float,
               workspace_size: float) -> MountedTool:
    """Check a tool and mount it at ``offset`` from the tip.

    Raises
    ------
    ValueError
        If the shape is not convex, is larger than the workspace, or its face has more than
        ``MAX_FACE_POINTS`` points at this spacing.
    """
    _refuse(shape, workspace_size)
    face, radius = face_shell(shape, face_spacing)
    if len(face) > MAX_FACE_POINTS:
        raise ValueError(f'the tool\'s face has {len(face)} points at a face_spacing of '
                         f'{face_spacing:g} m, more than the {MAX_FACE_POINTS} a collision '
                         'state carries: use a wider spacing')
    from scipy.spatial.transform import Rotation

    face = offset.to_world(face)
    face.setflags(write=False)
    quaternion = tuple(Rotation.from_matrix(offset.rotation).as_quat().tolist())
    return MountedTool(shape, offset, quaternion, face, radius)


def _refuse(shape, workspace_size: float) -> None:
    """Raise a ValueError that says why ``shape`` cannot be a tool, if it cannot."""
    if not isinstance(shape, _CONVEX):
        named = getattr(shape, 'name', None)
        raise ValueError((f'{named}: ' if named else '') + 'the tool must be convex (Box, '
                         f'Sphere, Cylinder, Capsule or ConvexMesh), got {shape!r}')
    centre, radius = shape.bounding_sphere()
    if 2.0 * radius > workspace_size:
        raise ValueError(f'the tool {shape!r} is {2.0 * radius:.6g} m across, larger than the '
                         f'workspace ({workspace_size:.6g} m)')


def pack_tool(shape, *, spacing: float, workspace_size: float) -> tuple[np.ndarray, np.ndarray]:
    """Validate and pack a tool once per shape object and spacing (the pack is kept).

    Layout: floats = [radius, bounding radius, bounding centre (3), spacing, shell offset,
    work offset], the shape's float block, the shell (n, 3), then work space: the tool's pose
    in an object's frame (12), its extents there (``BOX_FLOATS``) and the shell points measured
    so far (``MEASURED_FLOATS`` n: each with a lower bound on its signed distance, and the
    nearest surface point found for it and its triangle), then each shell point's lower and
    upper bound from the mesh's distance grid (2 n).
    ints = [kind, n], then the shape's int block.

    Raises
    ------
    ValueError
        If the shape is not convex or is larger than the workspace (m, its bounding diameter).
    """
    packed = _PACKED.get(shape)
    if packed is not None and packed[0][5] == spacing:
        return packed
    _refuse(shape, workspace_size)
    kind, shape_floats, shape_ints = pack_convex(shape)
    shell = point_shell(shape, spacing)
    centre, bounding = shape.bounding_sphere()
    radius = shape.radius if isinstance(shape, (Sphere, Capsule)) else 0.0
    shell_at = FLOAT_HEADER + len(shape_floats)
    work_at = shell_at + shell.size
    header = [radius, bounding, *centre, spacing, shell_at, work_at]
    work = np.zeros(12 + BOX_FLOATS + (MEASURED_FLOATS + 2) * len(shell))
    floats = np.concatenate((header, shape_floats, shell.ravel(), work))
    ints = np.concatenate(([kind, len(shell)], shape_ints)).astype(np.int64)
    packed = (floats, ints)
    _PACKED[shape] = packed
    return packed


def load_tool(path, *, scale: float = 1.0) -> ConvexMesh:
    """Read a tool's mesh file (``mesh_io.load_mesh``); a tool must be convex.

    Raises
    ------
    MeshError
        Naming the file, if it cannot be read or its surface is not convex.
    """
    from collision_engine.mesh_io import load_mesh

    mesh = load_mesh(Path(path), scale=scale)
    if not mesh.is_convex:
        raise MeshError(f'{path}: the tool mesh is not convex (a tool must be: use its convex '
                        'hull or a convex part)')
    return ConvexMesh(mesh.vertices)
