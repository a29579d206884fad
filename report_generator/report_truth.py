"""The exact signed distance and outward normal along each recorded tip path.

From ``ground_truth/distances.py``, which shares no code with the engine: analytic for the box and
the cylinder, brute force with a winding-number sign for the hand.
"""

from dataclasses import dataclass

from bench import bench_collision
from ground_truth import distances
import numpy as np
from report_generator.report_experiments import Experiment

from collision_engine import read_scene
from collision_engine.mesh_io import load_mesh

__all__ = ['Truth', 'exact_truth']


@dataclass(frozen=True, eq=False)
class Truth:
    """The exact signed distance (n,) m and unit outward normal (n, 3) at each recorded tip."""

    distance: np.ndarray
    normal: np.ndarray


def exact_truth(experiment: Experiment, points: np.ndarray) -> Truth:
    """Exact signed distance and outward normal at world points (n, 3), m.

    Analytic for the box and the cylinder, with the normal as the central-difference gradient
    of the exact field; brute force for the mesh, with the normal along tip - closest point.
    """
    spec = read_scene(experiment.scene_file).objects[0]
    rotation, translation = spec.pose.rotation, spec.pose.translation

    def local(world):
        return (np.asarray(world) - translation) @ rotation

    shape = spec.shape
    if hasattr(shape, 'file'):
        mesh = load_mesh(shape.file, scale=shape.scale, check_self_intersection=False)
        signed, closest = distances.mesh_signed_distance(local(points), mesh.vertices,
                                                         mesh.faces)
        with np.errstate(invalid='ignore', divide='ignore'):
            normal = (local(points) - closest) / signed[:, None]
        return Truth(signed, normal @ rotation.T)
    if hasattr(shape, 'size'):
        def field(world):
            return distances.box_signed_distance(local(world), shape.size)
    else:
        def field(world):
            return distances.cylinder_signed_distance(local(world), shape.radius,
                                                      shape.height)
    return Truth(field(points), bench_collision._outward(field, points))
