"""The shapes' validation, hulls and bounding spheres."""

import numpy as np
import pytest

from collision_engine.errors import MeshError
from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere, TriangleMesh

CUBE_VERTICES = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0)
                          for z in (-1.0, 1.0)])
CUBE_FACES = np.array([
    [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
    [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
])


@pytest.mark.parametrize('make, field', [
    (lambda: Box([1.0, -1.0, 1.0]), r'Box.size\[1\]'),
    (lambda: Box([1.0, 1.0]), 'Box.size'),
    (lambda: Box([1.0, 1.0, np.nan]), r'Box.size\[2\]'),
    (lambda: Sphere(0.0), 'Sphere.radius'),
    (lambda: Sphere('a'), 'Sphere.radius'),
    (lambda: Cylinder(1.0, np.inf), 'Cylinder.height'),
    (lambda: Capsule(-1.0, 1.0), 'Capsule.radius'),
    (lambda: ConvexMesh(np.zeros((5, 2))), 'ConvexMesh.vertices'),
    (lambda: ConvexMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]), 'volume'),
])
def test_bad_shapes_name_the_field(make, field):
    with pytest.raises(ValueError, match=field):
        make()


def test_convex_mesh_keeps_the_hull_wound_outward():
    rng = np.random.default_rng(0)
    cloud = np.concatenate([CUBE_VERTICES, rng.uniform(-0.9, 0.9, size=(50, 3))])
    hull = ConvexMesh(cloud)
    assert sorted(map(tuple, hull.vertices)) == sorted(map(tuple, CUBE_VERTICES))
    corners = hull.vertices[hull.faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    assert np.all(np.einsum('ij,ij->i', normals, corners.mean(axis=1)) > 0.0)
    offsets, neighbours = hull.vertex_adjacency()
    edges = {(i, int(j)) for i in range(8) for j in neighbours[offsets[i]:offsets[i + 1]]}
    assert all((j, i) in edges for i, j in edges)
    # Every cube edge is a hull edge (the face diagonals may be too).
    for i in range(8):
        for j in range(8):
            if np.sum(hull.vertices[i] != hull.vertices[j]) == 1:
                assert (i, j) in edges


def test_triangle_mesh_accepts_a_closed_outward_surface():
    mesh = TriangleMesh(CUBE_VERTICES, CUBE_FACES)
    np.testing.assert_array_equal(mesh.support([1.0, 2.0, 3.0]), [1.0, 1.0, 1.0])


@pytest.mark.parametrize('faces, defect', [
    (CUBE_FACES[:-1], 'not closed'),
    (np.concatenate([CUBE_FACES[:-1], [CUBE_FACES[-1][::-1]]]), 'same direction'),
    (np.concatenate([CUBE_FACES, [[0, 1, 1]]]), 'zero area'),
    (CUBE_FACES + 1, 'outside'),
    (CUBE_FACES.astype(float), 'integer'),
])
def test_triangle_mesh_rejects_what_breaks_the_sign(faces, defect):
    with pytest.raises(MeshError, match=f'hand.stl: .*{defect}'):
        TriangleMesh(CUBE_VERTICES, faces, name='hand.stl')


@pytest.mark.parametrize('shape', [
    Box([0.2, 0.1, 0.05]), Sphere(0.05), Cylinder(0.025, 0.1), Capsule(0.025, 0.1),
    ConvexMesh(CUBE_VERTICES + [3.0, 0.0, 0.0]), TriangleMesh(CUBE_VERTICES - 2.0, CUBE_FACES),
], ids=lambda s: type(s).__name__)
def test_bounding_sphere_holds_the_support_points(shape):
    centre, radius = shape.bounding_sphere()
    rng = np.random.default_rng(1)
    for direction in rng.normal(size=(200, 3)):
        assert np.linalg.norm(shape.support(direction) - centre) <= radius * (1 + 1e-12)
