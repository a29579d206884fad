"""Angle-weighted pseudonormals of a closed triangle mesh: the sign of its distance field.

Bærentzen and Aanæs (2005, IEEE TVCG 11(3)) prove that for a closed, consistently wound mesh,
a point q whose nearest surface point is x on feature F (a face, an edge or a vertex) is outside
exactly when ``(q - x) . N_F > 0``, where N_F is the face normal, the sum of the two adjacent
face normals for an edge, or the sum of the incident face normals weighted by their angles at
the vertex. Built once in numpy; the kernel only reads them.
"""

import numpy as np

__all__ = ['Pseudonormals', 'pseudonormals']


class Pseudonormals:
    """Unit outward pseudonormals of every face, edge and vertex of a mesh.

    Attributes
    ----------
    face : (m, 3) float64
    edge : (e, 3) float64
    vertex : (n, 3) float64
    face_edges : (m, 3) int64
        ``face_edges[f, k]`` is the edge of face f opposite its corner k.
    """

    __slots__ = ('face', 'edge', 'vertex', 'face_edges')

    def __init__(self, face, edge, vertex, face_edges) -> None:
        self.face, self.edge, self.vertex, self.face_edges = face, edge, vertex, face_edges


def _unit(vectors: np.ndarray) -> np.ndarray:
    """Rows divided by their norms, each row first divided by its largest |component|.

    Faces a few 1e-160 m across have cross products whose squares underflow: unscaled, their
    normals would be 0/0.
    """
    scaled = vectors / np.max(np.abs(vectors), axis=1, keepdims=True)
    return scaled / np.linalg.norm(scaled, axis=1, keepdims=True)


def pseudonormals(vertices: np.ndarray, faces: np.ndarray) -> Pseudonormals:
    """Pseudonormals of a closed, consistently wound mesh with no zero-area face.

    Parameters
    ----------
    vertices : (n, 3) float, m
    faces : (m, 3) int, counter-clockwise seen from outside

    Returns
    -------
    Pseudonormals
    """
    corners = vertices[faces]
    # Each face moved to its first corner and scaled to a largest offset of 1: normals and
    # angles do not change, and no cross product of a tiny face underflows.
    corners = corners - corners[:, :1]
    corners /= np.max(np.abs(corners), axis=(1, 2))[:, None, None]
    face = _unit(np.cross(corners[:, 1], corners[:, 2]))
    vertex = np.zeros_like(vertices)
    for k in range(3):
        u = corners[:, (k + 1) % 3] - corners[:, k]
        w = corners[:, (k + 2) % 3] - corners[:, k]
        angle = np.arctan2(np.linalg.norm(np.cross(u, w), axis=1), np.einsum('ij,ij->i', u, w))
        np.add.at(vertex, faces[:, k], angle[:, None] * face)
    opposite = np.stack([faces[:, [1, 2]], faces[:, [2, 0]], faces[:, [0, 1]]], axis=1)
    edge_keys = np.sort(opposite.reshape(-1, 2), axis=1)
    _, edge_of_corner = np.unique(edge_keys, axis=0, return_inverse=True)
    face_edges = edge_of_corner.reshape(-1, 3).astype(np.int64)
    edge = np.zeros((face_edges.max() + 1, 3))
    np.add.at(edge, face_edges.ravel(), np.repeat(face, 3, axis=0))
    return Pseudonormals(face, _unit(edge), _unit(vertex), face_edges)
