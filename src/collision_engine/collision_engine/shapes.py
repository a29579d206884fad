"""The scene's shapes: geometry only, in each shape's local frame (the pose is kept apart).

Primitives are centred on their local origin; the cylinder and the capsule have their axis along
local z. Every convex shape is described to the kernels by its exact support function (a
cylinder is a cylinder, not a tessellation). A :class:`TriangleMesh` is a closed, consistently
wound, possibly non-convex surface; its ``support`` is that of its convex hull.
"""

import math

import numpy as np

from collision_engine import support as _support
from collision_engine.errors import MeshError
from collision_engine.norms import scaled3

__all__ = ['Box', 'Sphere', 'Cylinder', 'Capsule', 'ConvexMesh', 'TriangleMesh']


def _length(value, name: str) -> float:
    try:
        length = float(value)
    except (TypeError, ValueError):
        raise ValueError(f'{name} must be a positive number (m), got {value!r}') from None
    if not (length > 0.0 and math.isfinite(length)):
        raise ValueError(f'{name} must be a positive finite number (m), got {value!r}')
    return length


def _points(value, name: str) -> np.ndarray:
    array = np.array(value, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 3 or not np.all(np.isfinite(array)):
        raise ValueError(f'{name} must be a finite (n, 3) array (m), got shape {array.shape}')
    return array


class _ConvexShape:
    """What every convex shape shares: its packed form and its support function."""

    __slots__ = ('_packed', '__weakref__')
    kind = -1

    def _pack(self) -> tuple:
        if self._packed is None:
            self._packed = _support.pack_convex(self)
        return self._packed

    def support(self, direction) -> np.ndarray:
        """Farthest point of the shape along ``direction``.

        Parameters
        ----------
        direction : (3,) float, local frame
            Need not be unit length.

        Returns
        -------
        (3,) float64, m, local frame
        """
        kind, floats, ints = self._pack()
        return _support.support_point(kind, floats, ints, direction)


class Box(_ConvexShape):
    """A box centred on the local origin, edges along the local axes.

    Parameters
    ----------
    size : (3,) float, m
        Full edge lengths along x, y, z.
    """

    __slots__ = ('size',)
    kind = _support.BOX

    def __init__(self, size) -> None:
        values = list(np.ravel(np.asarray(size, dtype=object)))
        if len(values) != 3:
            raise ValueError(f'Box.size must be 3 positive numbers (m), got {size!r}')
        self.size = tuple(_length(v, f'Box.size[{i}]') for i, v in enumerate(values))
        self._packed = None

    def bounding_sphere(self) -> tuple[np.ndarray, float]:
        """Centre (3,) m and radius m of a sphere holding the shape, local frame."""
        return np.zeros(3), 0.5 * math.hypot(*self.size)

    def __repr__(self) -> str:
        return f'Box(size={list(self.size)})'


class Sphere(_ConvexShape):
    """A sphere centred on the local origin.

    Parameters
    ----------
    radius : float, m
    """

    __slots__ = ('radius',)
    kind = _support.SPHERE

    def __init__(self, radius) -> None:
        self.radius = _length(radius, 'Sphere.radius')
        self._packed = None

    def bounding_sphere(self) -> tuple[np.ndarray, float]:
        """Centre (3,) m and radius m of a sphere holding the shape, local frame."""
        return np.zeros(3), self.radius

    def __repr__(self) -> str:
        return f'Sphere(radius={self.radius})'


class Cylinder(_ConvexShape):
    """A capped cylinder centred on the local origin, axis along local z.

    Parameters
    ----------
    radius : float, m
    height : float, m
        Full height, from z = -height/2 to +height/2.
    """

    __slots__ = ('radius', 'height')
    kind = _support.CYLINDER

    def __init__(self, radius, height) -> None:
        self.radius = _length(radius, 'Cylinder.radius')
        self.height = _length(height, 'Cylinder.height')
        self._packed = None

    def bounding_sphere(self) -> tuple[np.ndarray, float]:
        """Centre (3,) m and radius m of a sphere holding the shape, local frame."""
        return np.zeros(3), math.hypot(self.radius, 0.5 * self.height)

    def __repr__(self) -> str:
        return f'Cylinder(radius={self.radius}, height={self.height})'


class Capsule(_ConvexShape):
    """The points within ``radius`` of a segment on the local z axis, centred on the origin.

    Parameters
    ----------
    radius : float, m
    length : float, m
        Length of the segment (the capsule's total length is ``length + 2 radius``).
    """

    __slots__ = ('radius', 'length')
    kind = _support.CAPSULE

    def __init__(self, radius, length) -> None:
        self.radius = _length(radius, 'Capsule.radius')
        self.length = _length(length, 'Capsule.length')
        self._packed = None

    def bounding_sphere(self) -> tuple[np.ndarray, float]:
        """Centre (3,) m and radius m of a sphere holding the shape, local frame."""
        return np.zeros(3), 0.5 * self.length + self.radius

    def __repr__(self) -> str:
        return f'Capsule(radius={self.radius}, length={self.length})'


class ConvexMesh(_ConvexShape):
    """The convex hull of a set of points.

    Parameters
    ----------
    vertices : (n, 3) float, m, local frame
        Any points; only the hull's vertices are kept. The hull must have a volume.

    Attributes
    ----------
    vertices : (k, 3) float64, m
        The hull's vertices.
    faces : (f, 3) int64
        The hull's triangles, wound counter-clockwise seen from outside.
    """

    __slots__ = ('vertices', 'faces', '_sphere')
    kind = _support.CONVEX_MESH

    def __init__(self, vertices) -> None:
        from scipy.spatial import ConvexHull, QhullError

        points = _points(vertices, 'ConvexMesh.vertices')
        try:
            hull = ConvexHull(points)
        except (QhullError, ValueError) as error:
            first_line = str(error).strip().splitlines()[0] if str(error).strip() else ''
            raise ValueError(f'ConvexMesh.vertices have no convex hull with a volume '
                             f'({len(points)} points): {first_line}') from None
        remap = np.full(len(points), -1, dtype=np.int64)
        remap[hull.vertices] = np.arange(len(hull.vertices))
        faces = remap[hull.simplices]
        self.vertices = points[hull.vertices]
        corners = self.vertices[faces]
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        inward = np.einsum('ij,ij->i', normals, hull.equations[:, :3]) < 0.0
        faces[inward] = faces[inward][:, ::-1]
        self.faces = faces
        self._packed = None
        self._sphere = None

    def vertex_adjacency(self) -> tuple[np.ndarray, np.ndarray]:
        """Hull edges as compressed rows: neighbours of vertex i are ``neighbours[o[i]:o[i+1]]``.

        Returns
        -------
        offsets : (k + 1,) int64
        neighbours : (2 e,) int64
        """
        edges = self.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
        edges = np.unique(np.sort(edges, axis=1), axis=0)
        directed = np.concatenate((edges, edges[:, ::-1]))
        directed = directed[np.lexsort((directed[:, 1], directed[:, 0]))]
        counts = np.bincount(directed[:, 0], minlength=len(self.vertices))
        offsets = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
        return offsets, directed[:, 1].astype(np.int64)

    def bounding_sphere(self) -> tuple[np.ndarray, float]:
        """Centre (3,) m and radius m of a sphere holding the shape, local frame."""
        if self._sphere is None:
            self._sphere = _bounding_sphere(self.vertices)
        return self._sphere

    def __repr__(self) -> str:
        return f'ConvexMesh({len(self.vertices)} hull vertices)'


class TriangleMesh:
    """A closed, consistently wound triangle surface, convex or not.

    Parameters
    ----------
    vertices : (n, 3) float, m, local frame
        Welded: a corner shared by several triangles is one row.
    faces : (m, 3) int
        Counter-clockwise seen from outside. Every edge must be shared by exactly two faces
        that traverse it in opposite directions, and no face may have zero area: the sign of the
        distance (pseudonormals) needs both.
    name : str, optional
        Names the mesh (e.g. its file) in error messages; kept as ``name``.

    Raises
    ------
    MeshError
        When the surface is open, non-manifold, inconsistently wound or has a degenerate face.
    """

    __slots__ = ('vertices', 'faces', 'name', '_sphere', '__weakref__')
    kind = _support.TRIANGLE_MESH

    def __init__(self, vertices, faces, *, name: str = 'TriangleMesh') -> None:
        vertices = _points(vertices, f'{name}: vertices')
        faces = np.array(faces)
        if (faces.ndim != 2 or faces.shape[1] != 3 or len(faces) < 4
                or not np.issubdtype(faces.dtype, np.integer)):
            raise MeshError(f'{name}: faces must be an (m >= 4, 3) integer array, '
                            f'got shape {faces.shape} {faces.dtype}')
        faces = faces.astype(np.int64)
        if faces.min() < 0 or faces.max() >= len(vertices):
            raise MeshError(f'{name}: a face index is outside 0..{len(vertices) - 1}')
        _check_closed_and_wound(vertices, faces, name)
        self.vertices = vertices
        self.faces = faces
        self.name = name
        self._sphere = None

    def support(self, direction) -> np.ndarray:
        """Farthest vertex along ``direction`` (3,): the support of the convex hull, m.

        The direction is scaled to a largest component of 1 first (``norms.scaled3``), so that
        no dot product underflows or overflows.
        """
        scaled = np.array(scaled3(*(float(c) for c in direction)))
        return self.vertices[np.argmax(self.vertices @ scaled)]

    def bounding_sphere(self) -> tuple[np.ndarray, float]:
        """Centre (3,) m and radius m of a sphere holding the shape, local frame."""
        if self._sphere is None:
            self._sphere = _bounding_sphere(self.vertices)
        return self._sphere

    def __repr__(self) -> str:
        return f'TriangleMesh({len(self.vertices)} vertices, {len(self.faces)} faces)'


def _bounding_sphere(vertices: np.ndarray) -> tuple[np.ndarray, float]:
    """Compute the sphere once per mesh (it reads every vertex): the shapes keep it."""
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    centre.setflags(write=False)
    offsets = vertices - centre
    return centre, float(np.hypot(np.hypot(offsets[:, 0], offsets[:, 1]), offsets[:, 2]).max())


def _check_closed_and_wound(vertices: np.ndarray, faces: np.ndarray, name: str) -> None:
    corners = vertices[faces]
    areas2 = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                     corners[:, 2] - corners[:, 0]), axis=1)
    if np.any(areas2 == 0.0):
        raise MeshError(f'{name}: face {int(np.argmin(areas2))} has zero area')
    directed = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    key = directed[:, 0] * len(vertices) + directed[:, 1]
    reverse = directed[:, 1] * len(vertices) + directed[:, 0]
    unique, counts = np.unique(key, return_counts=True)
    if np.any(counts > 1):
        edge = unique[np.argmax(counts > 1)]
        raise MeshError(f'{name}: edge {divmod(int(edge), len(vertices))} is used twice in the '
                        'same direction (inconsistent winding or a non-manifold edge)')
    missing = ~np.isin(reverse, unique)
    if np.any(missing):
        edge = directed[np.argmax(missing)]
        raise MeshError(f'{name}: edge {tuple(int(v) for v in edge)} belongs to one face only '
                        '(the surface is not closed)')
