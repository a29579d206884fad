"""Angle-weighted pseudonormals on a cube and a tetrahedron, known there in closed form."""

import numpy as np

from collision_engine.pseudonormals import pseudonormals

CUBE_VERTICES = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0)
                          for z in (-1.0, 1.0)])
CUBE_FACES = np.array([
    [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
    [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
])


def test_cube_faces_edges_and_corners():
    normals = pseudonormals(CUBE_VERTICES, CUBE_FACES)
    # Face normals are the axes; a corner's is its diagonal whatever the triangulation (the
    # angle weighting makes the two triangles of a split face count as the face once).
    centroids = CUBE_VERTICES[CUBE_FACES].mean(axis=1)
    axis = np.argmax(np.abs(centroids), axis=1)
    expected_face = np.zeros((12, 3))
    expected_face[np.arange(12), axis] = np.sign(centroids[np.arange(12), axis])
    np.testing.assert_allclose(normals.face, expected_face, atol=1e-15)
    np.testing.assert_allclose(normals.vertex, CUBE_VERTICES / np.sqrt(3.0), atol=1e-15)
    # Each edge: a cube edge has the diagonal of its two faces, a face diagonal its face's.
    for f in range(12):
        for k in range(3):
            a, b = CUBE_FACES[f, (k + 1) % 3], CUBE_FACES[f, (k + 2) % 3]
            midpoint = 0.5 * (CUBE_VERTICES[a] + CUBE_VERTICES[b])
            expected = np.where(np.abs(midpoint) == 1.0, midpoint, 0.0)
            expected /= np.linalg.norm(expected)
            np.testing.assert_allclose(normals.edge[normals.face_edges[f, k]], expected,
                                       atol=1e-15)


def test_edges_are_shared_by_their_two_faces():
    normals = pseudonormals(CUBE_VERTICES, CUBE_FACES)
    counts = np.bincount(normals.face_edges.ravel())
    assert len(counts) == 18 and np.all(counts == 2)


def test_regular_tetrahedron_corner_points_away_from_the_centre():
    vertices = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0],
                         [-1.0, -1.0, 1.0]])
    faces = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    normals = pseudonormals(vertices, faces)
    np.testing.assert_allclose(normals.vertex, vertices / np.sqrt(3.0), atol=1e-15)
    assert np.all(np.einsum('ij,ij->i', normals.face, vertices[faces].mean(axis=1)) > 0)
    assert normals.edge.shape == (6, 3)
    # An edge's pseudonormal bisects its two faces, pointing out through the edge's midpoint.
    for f in range(4):
        for k in range(3):
            a, b = faces[f, (k + 1) % 3], faces[f, (k + 2) % 3]
            midpoint = 0.5 * (vertices[a] + vertices[b])
            np.testing.assert_allclose(normals.edge[normals.face_edges[f, k]],
                                       midpoint / np.linalg.norm(midpoint), atol=1e-15)


def test_normals_of_a_cube_1e_160_across_are_those_of_the_unit_cube():
    # Its cross products are ~1e-320: their squares underflow unless rows are scaled first.
    tiny = pseudonormals(CUBE_VERTICES * 1e-160, CUBE_FACES)
    unit = pseudonormals(CUBE_VERTICES, CUBE_FACES)
    for found, expected in ((tiny.face, unit.face), (tiny.edge, unit.edge),
                            (tiny.vertex, unit.vertex)):
        np.testing.assert_allclose(found, expected, rtol=0, atol=1e-15)
