"""The paper's force origin: each object's vertex centroid, for the comparison law only.

The paper pushed along tip − centroid, where the centroid is the plain mean of the STL's vertex
rows (three per triangle, shared vertices counted again). A primitive has no rows; its centre is
what the paper's tessellations averaged to, so that stands in.
"""
import numpy as np

__all__ = ['vertex_centroids']


def vertex_centroids(spec) -> dict:
    """Object name → (3,) float, m, world frame: the mean of its STL vertex rows, or its centre.

    ``spec`` is a collision_engine SceneSpec; mesh files are loaded (trimesh) only here.
    """
    centroids = {}
    for obj in spec.objects:
        local = np.zeros(3)
        if hasattr(obj.shape, 'file'):
            from collision_engine.mesh_io import load_mesh
            mesh = load_mesh(obj.shape.file, scale=obj.shape.scale)
            local = mesh.vertices[mesh.faces].reshape(-1, 3).mean(axis=0)
        centroids[obj.name] = obj.pose.rotation @ local + obj.pose.translation
    return centroids
