"""The mounted probe against the scene: the whole tool's distance, and its face point by point.

One wand pose gives the tool's pose (the tip's pose times the tool's offset, ``tool.MountedTool``)
and the face points' positions. ``Scene.query_tool`` measures the tool (the nearest object, both
witnesses, the normal); ``Scene.query_rows`` measures each face point exactly, which is what the
contact law with torque sums (``force_renderer.probe``). Two compiled calls per pose.
"""
from dataclasses import dataclass

import numpy as np

from collision_engine.results import ToolResult

__all__ = ['ProbeResult', 'query_probe', 'rotation_matrix']


@dataclass(frozen=True, eq=False)
class ProbeResult:
    """The mounted tool against the scene, for one wand pose (scene frame, SI).

    Attributes
    ----------
    tool : ToolResult
        The whole tool: signed distance, witnesses on the object and on the tool, normal.
    distance : (n,) float64, m
        Each face point's signed distance to the nearest surface (the tool's radius taken off).
    points : (n, 3) float64, m
        The face points on the tool's surface (for a round tool: its core point moved by its
        radius toward the nearest surface).
    normals : (n, 3) float64
        The outward normal of the surface nearest each face point.
    """

    tool: ToolResult
    distance: np.ndarray
    points: np.ndarray
    normals: np.ndarray


def rotation_matrix(quaternion) -> np.ndarray:
    """Return the (3, 3) rotation of a unit quaternion (x, y, z, w)."""
    x, y, z, w = quaternion
    return np.array([
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
        [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
        [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)]])


def _product(a, b) -> tuple:
    """Hamilton product a b of quaternions (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def query_probe(scene, position, quaternion) -> ProbeResult:
    """Measure the scene's mounted tool (``scene.tool``) at a wand pose.

    Parameters
    ----------
    scene : Scene
        With a tool (``load_scene`` of a file with a ``tool:`` section).
    position : (3,) float, m, scene frame
        The tip.
    quaternion : (4,) float
        The tip's orientation, (x, y, z, w), unit.

    Returns
    -------
    ProbeResult

    Raises
    ------
    ValueError
        If the pose is not finite or the quaternion not of unit norm (``Scene.query_tool``).
    """
    mounted = scene.tool
    rotation = rotation_matrix(quaternion)
    tip = np.asarray(position, dtype=np.float64)
    offset = mounted.offset
    tool_position = tip + rotation @ offset.translation
    tool = scene.query_tool(mounted.shape, (tool_position.tolist(),
                                            _product(quaternion, mounted.offset_quaternion)))
    cores = tip + mounted.face @ rotation.T
    rows = scene.query_rows(cores)
    distance, normals = rows[:, 0], rows[:, 4:7]
    radius = mounted.radius
    if radius == 0.0:
        return ProbeResult(tool, distance, cores, normals)
    return ProbeResult(tool, distance - radius, cores - radius * normals, normals)
