"""Loading triangle meshes (STL, OBJ, PLY) and checking they can carry an exact signed distance.

A signed distance to a mesh is only defined when the mesh bounds a solid: every edge shared by
exactly two faces, faces wound consistently and outward, no face without a normal, no surface
crossing itself. `load_mesh` enforces all of that at load time, so a defect is reported once,
naming the file, instead of surfacing as a wrong sign in the haptic loop. It parses through
trimesh, imported on first use so that scenes of primitives never import it.

Vertices are welded on exact coordinates (no tolerance: merging nearly equal vertices would move
the surface) and returned in metres after `scale`.
"""

from dataclasses import dataclass
import io
from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from collision_engine.errors import MeshError

__all__ = ['MAX_EXTENT', 'MIN_EXTENT', 'MeshData', 'SUPPORTED_SUFFIXES', 'load_mesh']

SUPPORTED_SUFFIXES = ('.stl', '.obj', '.ply')
MAX_EXTENT = 10.0    # m: larger is almost surely a file in millimetres read as metres
MIN_EXTENT = 1e-4    # m: smaller is almost surely a file in metres scaled as millimetres
_STL_HEADER_BYTES = 84       # 80-byte comment and a little-endian uint32 triangle count
_STL_TRIANGLE_BYTES = 50     # normal and three corners as float32, then a uint16
# A face is degenerate when its normal is below the rounding of the cross product that gives it.
_DEGENERATE_RELATIVE_AREA = 8.0 * np.finfo(np.float64).eps


@dataclass(frozen=True, eq=False)
class MeshData:
    """A closed, outward-wound triangle mesh in metres, ready for signed distance.

    Attributes
    ----------
    vertices : (n, 3) float64, m, mesh frame
        Welded: no two rows are equal, and every row is used by a face. Read-only.
    faces : (m, 3) int64
        Vertex indices, counter-clockwise seen from outside. Read-only.
    path : pathlib.Path
        The file it came from.
    is_convex : bool
        True when the mesh is its own convex hull (within trimesh's planar tolerance).
    warnings : tuple of str
        What was repaired on load (zero-area faces dropped, inside-out winding inverted).
    """

    vertices: np.ndarray
    faces: np.ndarray
    path: Path
    is_convex: bool
    warnings: tuple[str, ...] = ()


def load_mesh(path: str | Path, *, scale: float = 1.0,
              check_self_intersection: bool = True) -> MeshData:
    """Read and validate a triangle mesh for exact signed distance.

    Parameters
    ----------
    path : str or pathlib.Path
        An .stl (ASCII or binary), .obj or .ply file.
    scale : float
        Factor from file units to metres: 0.001 for a file in millimetres.
    check_self_intersection : bool
        Reject surfaces that touch or cross themselves (``self_intersection``: compiled, an AABB
        tree as broadphase; triangles sharing a corner or an edge count only where they meet
        beyond it). About 30 ms for the shipped hand's 11k triangles once compiled.

    Returns
    -------
    MeshData

    Raises
    ------
    MeshError
        Naming the file and the defect: missing, unreadable, empty, truncated or unparsable file,
        unsupported format, NaN/Inf coordinates, no faces, an absurd size after `scale`, open or
        non-manifold surface, inconsistent winding, separate bodies wound opposite ways, no
        enclosed volume, self-intersection.
    """
    path = Path(path)
    scale = _checked_scale(path, scale)
    vertices, faces = _parse(path, _read_bytes(path))
    _check_extent(path, vertices[faces].reshape(-1, 3) * scale, scale)
    kept, warnings = _non_degenerate(path, vertices, faces)
    vertices, faces = _weld(vertices, faces[kept])
    vertices = vertices * scale
    _check_closed_manifold(path, faces)
    _check_consistent_winding(path, faces)
    _check_one_fan_per_vertex(path, faces)
    if _wound_inward(path, vertices, faces):
        faces = np.ascontiguousarray(faces[:, ::-1])
        warnings.append(f'{path}: faces were wound inward (inside-out); inverted them')
    if check_self_intersection:
        _check_self_intersection(path, vertices, faces, kept)
    is_convex = _is_convex(vertices, faces)
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return MeshData(vertices, faces, path, is_convex, tuple(warnings))


def _some(indices: np.ndarray, shown: int = 5) -> str:
    """Format the first few `indices` for a message."""
    text = ', '.join(str(i) for i in indices[:shown])
    return text + (', ...' if len(indices) > shown else '')


def _checked_scale(path: Path, scale: float) -> float:
    try:
        value = float(scale)
    except (TypeError, ValueError):
        value = np.nan
    if isinstance(scale, bool) or not (np.isfinite(value) and value > 0.0):
        raise MeshError(f'{path}: scale must be a positive finite number, got {scale!r}')
    return value


def _read_bytes(path: Path) -> bytes:
    if path.suffix.lower() not in SUPPORTED_SUFFIXES:
        raise MeshError(f'{path}: unsupported mesh format {path.suffix!r}: use one of '
                        f'{", ".join(SUPPORTED_SUFFIXES)}')
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise MeshError(f'{path}: no such mesh file') from None
    except OSError as error:
        raise MeshError(f'{path}: cannot read the mesh file: {error.strerror or error}') from None
    if not data:
        raise MeshError(f'{path}: empty file (0 bytes)')
    return data


def _parse(path: Path, data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) float64 in file units and faces (m, 3) int64, as the file has them."""
    kind = path.suffix.lower()[1:]
    if kind == 'stl':
        _check_stl_layout(path, data)
    import trimesh
    try:
        mesh = trimesh.load_mesh(io.BytesIO(data), file_type=kind, process=False)
        vertices = np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3)
        faces = np.asarray(mesh.faces, dtype=np.int64)
    except Exception as error:  # the parsers raise many types on malformed input
        raise MeshError(f'{path}: cannot parse as {kind.upper()}: '
                        f'{type(error).__name__}: {error}') from error
    if faces.size == 0:
        raise MeshError(f'{path}: no faces (a {kind.upper()} with {len(vertices)} vertices '
                        f'and no triangles)')
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise MeshError(f'{path}: faces are not triangles (shape {faces.shape})')
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise MeshError(f'{path}: face indices outside the {len(vertices)} vertices '
                        f'(from {faces.min()} to {faces.max()})')
    not_finite = ~np.all(np.isfinite(vertices), axis=1)
    if np.any(not_finite):
        raise MeshError(f'{path}: {np.count_nonzero(not_finite)} vertices have NaN or Inf '
                        f'coordinates (0-based: {_some(np.flatnonzero(not_finite))})')
    return vertices, faces


def _check_stl_layout(path: Path, data: bytes) -> None:
    """Catch truncated and garbage STL here: trimesh would log them and return no faces."""
    if len(data) >= _STL_HEADER_BYTES:
        count = int.from_bytes(data[80:_STL_HEADER_BYTES], 'little')
        expected = _STL_HEADER_BYTES + _STL_TRIANGLE_BYTES * count
        if len(data) == expected:
            return  # binary, even if the comment starts with "solid", as some exporters do
    if data.lstrip()[:5].lower() == b'solid':
        if b'endsolid' not in data[-1024:].lower():
            raise MeshError(f'{path}: truncated ASCII STL: it does not end with "endsolid"')
        return
    if len(data) < _STL_HEADER_BYTES:
        raise MeshError(f'{path}: truncated or garbage binary STL: {len(data)} bytes, shorter '
                        f'than the {_STL_HEADER_BYTES}-byte header')
    raise MeshError(f'{path}: truncated or garbage binary STL: the header declares {count} '
                    f'triangles ({expected} bytes) but the file has {len(data)} bytes')


def _non_degenerate(path: Path, vertices: np.ndarray,
                    faces: np.ndarray) -> tuple[np.ndarray, list[str]]:
    """Find the faces with an area, and warn naming the others if there are any."""
    degenerate = _degenerate(vertices[faces])
    if np.all(degenerate):
        raise MeshError(f'{path}: no faces: all {len(faces)} faces have zero area')
    if not np.any(degenerate):
        return np.arange(len(faces)), []
    dropped = np.flatnonzero(degenerate)
    return np.flatnonzero(~degenerate), [f'{path}: dropped {len(dropped)} zero-area faces '
                                         f'(0-based, as read: {_some(dropped)})']


def _degenerate(corners: np.ndarray) -> np.ndarray:
    """(m,) bool: faces whose area is zero to rounding, so that they have no normal."""
    edges = corners[:, [1, 2, 0]] - corners
    doubled_area = np.linalg.norm(np.cross(edges[:, 0], -edges[:, 2]), axis=1)
    longest_squared = np.max(np.sum(edges ** 2, axis=2), axis=1)
    return doubled_area <= _DEGENERATE_RELATIVE_AREA * longest_squared


def _weld(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices with exactly equal coordinates and drop unused ones, keeping file order.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int

    Returns
    -------
    vertices : (k, 3) float64
        The distinct used vertices, in the order of their first row in the file.
    faces : (m, 3) int64
    """
    used, face_to_used = np.unique(faces, return_inverse=True)
    points = vertices[used] + 0.0  # -0.0 becomes 0.0, so the two weld
    unique, first, inverse = np.unique(points, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))
    welded_faces = rank[inverse.reshape(-1)][face_to_used.reshape(faces.shape)]
    return np.ascontiguousarray(unique[order]), welded_faces


def _check_extent(path: Path, points: np.ndarray, scale: float) -> None:
    """Reject sizes that no haptic scene has: almost always a unit mistake."""
    extent = float(np.max(np.ptp(points, axis=0)))
    if extent > MAX_EXTENT:
        raise MeshError(f'{path}: {extent:.4g} m across after scale {scale:g}, over '
                        f'{MAX_EXTENT:g} m: looks like millimetres read as metres: '
                        f'set scale: 0.001')
    if extent < MIN_EXTENT:
        raise MeshError(f'{path}: {extent:.3g} m across after scale {scale:g}, under '
                        f'{MIN_EXTENT:g} m: looks like metres scaled as millimetres: '
                        f'check scale')


def _edge_counts(edges: np.ndarray) -> np.ndarray:
    """How many times each distinct row of `edges` (k, 2) occurs."""
    return np.unique(edges, axis=0, return_counts=True)[1]


def _directed_edges(faces: np.ndarray) -> np.ndarray:
    """(3m, 2) int: each face's edges in its winding order."""
    return faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)


def _check_closed_manifold(path: Path, faces: np.ndarray) -> None:
    counts = _edge_counts(np.sort(_directed_edges(faces), axis=1))
    boundary, non_manifold = np.count_nonzero(counts == 1), np.count_nonzero(counts > 2)
    if boundary or non_manifold:
        raise MeshError(f'{path}: not watertight: {boundary} boundary edges (one face) and '
                        f'{non_manifold} non-manifold edges (three or more faces); every edge '
                        f'must be shared by exactly two faces')


def _check_consistent_winding(path: Path, faces: np.ndarray) -> None:
    """On a closed manifold, neighbours wound alike run their shared edge in opposite ways."""
    same_way = np.count_nonzero(_edge_counts(_directed_edges(faces)) > 1)
    if same_way:
        raise MeshError(f'{path}: inconsistent winding: {same_way} edges are run the same way '
                        f'by both their faces (some faces are flipped)')


def _check_one_fan_per_vertex(path: Path, faces: np.ndarray) -> None:
    """Reject vertices where separate fans of faces meet, as at the tips of two touching cones.

    There the surface is not a manifold and no vertex normal gives the sign. Corner k of face f is
    node 3f + k; across each edge, a corner is joined to the same vertex's corner in the face on
    the other side. A vertex whose corners form more than one group is such a pinch. Needs a
    closed, consistently wound mesh, where each directed edge (a, b) has exactly one twin (b, a).
    """
    edges = _directed_edges(faces)
    keys = edges[:, 0] * (faces.max() + 1) + edges[:, 1]
    order = np.argsort(keys)
    twin = order[np.searchsorted(keys[order], edges[:, 1] * (faces.max() + 1) + edges[:, 0])]
    following = 3 * (twin // 3) + (twin + 1) % 3  # the twin's end: this edge's start vertex
    corners = len(edges)
    graph = coo_matrix((np.ones(corners), (np.arange(corners), following)),
                       shape=(corners, corners))
    _, fan = connected_components(graph, directed=False)
    vertex_fans = np.unique(np.stack([faces.reshape(-1), fan], axis=1), axis=0)[:, 0]
    pinched = np.flatnonzero(np.bincount(vertex_fans) > 1)
    if len(pinched):
        raise MeshError(f'{path}: not a manifold at {len(pinched)} vertices where separate '
                        f'fans of faces meet (0-based, welded: {_some(pinched)})')


def _wound_inward(path: Path, vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Tell whether every body encloses negative volume; raise if the bodies disagree.

    The volume is the sum of the signed tetrahedra (origin, a, b, c), per connected body.
    """
    corners = vertices[faces]
    tetra = np.einsum('ij,ij->i', corners[:, 0], np.cross(corners[:, 1], corners[:, 2])) / 6.0
    edges = _directed_edges(faces)
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])),
                       shape=(len(vertices),) * 2)
    body_count, body_of_vertex = connected_components(graph, directed=False)
    volume = np.bincount(body_of_vertex[faces[:, 0]], weights=tetra, minlength=body_count)
    smallest = np.finfo(np.float64).eps * float(np.max(np.ptp(vertices, axis=0))) ** 3
    flat = np.count_nonzero(np.abs(volume) <= smallest)
    if flat:
        raise MeshError(f'{path}: encloses no volume: {flat} of its {body_count} bodies are flat')
    inward = np.count_nonzero(volume < 0.0)
    if 0 < inward < body_count:
        raise MeshError(f'{path}: {inward} of its {body_count} separate bodies are wound inward '
                        f'and the others outward; hollow bodies (inner shells) are not supported')
    return inward == body_count


def _check_self_intersection(path: Path, vertices: np.ndarray, faces: np.ndarray,
                             file_index: np.ndarray) -> None:
    """Raise naming the file and a pair of faces, as read, if the surface meets itself."""
    from collision_engine.self_intersection import self_intersections

    count, first, second = self_intersections(vertices, faces)
    if count:
        raise MeshError(f'{path}: self-intersecting: {count} pairs of triangles touch or cross, '
                        f'e.g. triangles {file_index[first]} and {file_index[second]} '
                        f'(0-based, as read)')


def _is_convex(vertices: np.ndarray, faces: np.ndarray) -> bool:
    import trimesh
    return bool(trimesh.Trimesh(vertices, faces, process=False).is_convex)
