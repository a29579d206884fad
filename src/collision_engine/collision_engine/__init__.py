"""Exact signed distance between a haptic wand tip and a scene, with our own GJK.

A pure core: numpy, scipy and numba; trimesh only for scenes with mesh files, python-fcl only
for scenes that turn on cross-validation; no ROS. Typical use::

    from collision_engine import Box, load_scene
    scene = load_scene('scenes/hand.yaml')      # validated, built and warmed up
    result = scene.query((0.0, 0.01, -0.02))    # m, scene frame
    result.distance, result.normal              # signed (negative inside), unit outward
    probe = Box([0.04, 0.01, 0.02])             # any convex shape, in its own frame
    contact = scene.query_tool(probe, ((0.0, 0.0, -0.03), (0.0, 0.0, 0.0, 1.0)))
    contact.distance, contact.witness_points    # signed; on the object, on the tool

``distance_between(shape_a, pose_a, shape_b, pose_b)`` is the same for two posed convex shapes.
"""

from collision_engine.convex_pair import distance_between, PairResult
from collision_engine.distance import distance, DistanceRequest, DistanceResult
from collision_engine.errors import MeshError, SceneError
from collision_engine.gjk import (STATUS_INVALID_INPUT, STATUS_NO_OBJECT, STATUS_NOT_CONVERGED,
                                  STATUS_OK)
from collision_engine.results import BatchResult, QueryResult, ToolResult
from collision_engine.scene import load_scene, Scene, SceneObject, surface_projection
from collision_engine.scene_file import read_scene, SceneSpec
from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere, TriangleMesh
from collision_engine.tool import load_tool
from collision_engine.transforms import Pose

__all__ = [
    'BatchResult', 'Box', 'Capsule', 'ConvexMesh', 'Cylinder', 'DistanceRequest',
    'DistanceResult', 'MeshError', 'PairResult', 'Pose', 'QueryResult', 'Scene', 'SceneError',
    'SceneObject', 'SceneSpec', 'Sphere', 'STATUS_INVALID_INPUT', 'STATUS_NO_OBJECT',
    'STATUS_NOT_CONVERGED', 'STATUS_OK', 'ToolResult', 'TriangleMesh', 'distance',
    'distance_between', 'load_scene', 'load_tool', 'read_scene', 'surface_projection',
]
