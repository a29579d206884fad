"""A scene of posed shapes and its signed-distance queries.

``load_scene`` builds only what the file declares: a scene of primitives imports neither trimesh
nor fcl and builds no tree; a convex mesh is queried by GJK on its hull, without a tree; fcl is
imported only when the file turns cross-validation on. Every query is one compiled call: of a
point (the wand's tip, ``query``) or of a convex tool (the probe, ``query_tool``).
"""

from dataclasses import dataclass
import logging
import math
from pathlib import Path
import sys
from typing import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from collision_engine import _kernels
from collision_engine._jit import compiling
from collision_engine.distance import DistanceRequest
from collision_engine.errors import MeshError, SceneError
from collision_engine.gjk import STATUS_INVALID_INPUT
from collision_engine.results import BatchResult, QueryResult, ToolResult
from collision_engine.scene_file import (BoxSpec, CapsuleSpec, CrossValidationSpec,
                                         CylinderSpec, MaterialSpec, MeshSpec, read_scene,
                                         SphereSpec)
from collision_engine.shapes import Box, Capsule, ConvexMesh, Cylinder, Sphere, TriangleMesh
from collision_engine.tool import DEFAULT_SHELL_SPACING, load_tool, mount_tool, pack_tool
from collision_engine.transforms import Pose
from haptic_contract.checks import finite_number

__all__ = ['Scene', 'SceneObject', 'load_scene', 'surface_projection']

_LOG = logging.getLogger(__name__)
_query_tool = _kernels.query_tool  # one lookup fewer a call, in the haptic loop

DEFAULT_WORKSPACE_SIZE = 0.3  # m: the default wand workspace's largest edge


@dataclass(frozen=True, eq=False)
class SceneObject:
    """A shape placed in the scene.

    ``pose`` maps the shape's local frame to the scene frame; ``material`` is None for the
    renderer's defaults.
    """

    name: str
    shape: object
    pose: Pose
    material: MaterialSpec | None = None


def _point(point) -> tuple[float, float, float]:
    if type(point) is np.ndarray:
        point = point.tolist()
    try:
        x, y, z = point
        return float(x), float(y), float(z)
    except (TypeError, ValueError):
        raise ValueError(f'point must be 3 numbers (m), got {point!r}') from None


def _pose_values(pose) -> tuple:
    """Position (3) and quaternion (4, x y z w) of a tool pose that is not a pair of numbers.

    ``query_tool`` unpacks the pair form itself, inline, as the fast path; this is the rest: a
    ``Pose``, or a ValueError.
    """
    if isinstance(pose, Pose):
        return (*pose.translation.tolist(),
                *Rotation.from_matrix(pose.rotation).as_quat().tolist())
    raise ValueError(f'tool pose must be a Pose or (position (3,), quaternion (4,)), '
                     f'got {pose!r}') from None


def _invalid(point) -> ValueError:
    return ValueError(f'point must be finite, got {list(point)}')


class Scene:
    """Posed shapes, queried for the signed distance to the nearest one.

    Not thread-safe: each query reuses scratch space and a warm-start hint kept in the scene.

    Parameters
    ----------
    objects : sequence of SceneObject
    frame_id : str
        The frame every pose, point and result is in (REP-103).
    tip_radius : float, m
        The tip is a sphere of this radius; 0 for a point.
    request : DistanceRequest, optional
        Tolerances and iteration caps (its ``guess`` is not used by scene queries).
    cross_validation : CrossValidationSpec, optional
        With ``fcl`` true, every ``every``-th ``query`` is checked against FCL, on a worker
        thread (``cross_validation.CrossValidationWorker``): call ``close`` when done.
    workspace_size : float, m
        The largest tool ``query_tool`` accepts (its bounding diameter): the workspace's size.
    shell_spacing : float, m
        The point shell's spacing of a tool against a non-convex mesh (``tool``).
    tool : MountedTool, optional
        The probe the scene file mounts on the wand (``tool.mount_tool``); None for a point or
        sphere tip. Kept for its user (``probe.query_probe``): no query reads it.
    """

    def __init__(self, objects, *, frame_id: str = 'world', tip_radius: float = 0.0,
                 request: DistanceRequest | None = None,
                 cross_validation: CrossValidationSpec | None = None,
                 workspace_size: float = DEFAULT_WORKSPACE_SIZE,
                 shell_spacing: float = DEFAULT_SHELL_SPACING, tool=None) -> None:
        self.objects = tuple(objects)
        self.tool = tool
        self.frame_id = frame_id
        self.tip_radius = finite_number(tip_radius, 'tip_radius', minimum=0.0, unit='m')
        self.workspace_size = finite_number(workspace_size, 'workspace_size', minimum=0.0,
                                            strict=True, unit='m')
        self.shell_spacing = finite_number(shell_spacing, 'shell_spacing', minimum=0.0,
                                           strict=True, unit='m')
        self.request = request or DistanceRequest()
        self._names = tuple(o.name for o in self.objects)
        shapes = [o.shape for o in self.objects]
        poses = [o.pose for o in self.objects]
        self._floats, self._ints = _kernels.pack_scene(
            shapes, poses, tip_radius=self.tip_radius, rel_tol=self.request.rel_tol,
            abs_tol=self.request.abs_tol, max_iterations=self.request.max_iterations,
            max_epa_iterations=self.request.max_epa_iterations)
        self._row = np.empty(_kernels.OUT_SIZE)
        self._tool = self._tool_pack = None
        self._validator = None
        if cross_validation is not None and cross_validation.fcl and self.objects:
            from collision_engine.cross_validation import CrossValidationWorker, FclCrossValidator

            self._validator = CrossValidationWorker(
                FclCrossValidator(shapes, poses, tolerance=cross_validation.tolerance,
                                  tip_radius=self.tip_radius),
                every=cross_validation.every)

    @property
    def names(self) -> tuple[str, ...]:
        """The objects' names, in order."""
        return self._names

    @property
    def cross_validation_stats(self):
        """Running FCL cross-check totals (``CrossValidationStats``), or None when off.

        The checks run behind the queries: ``wait_for_cross_validation`` first to count all.
        """
        return None if self._validator is None else self._validator.stats

    @property
    def cross_validation_disagreements(self) -> int:
        """FCL disagreements so far (0 when off): cheap enough for every answer."""
        return 0 if self._validator is None else self._validator.disagreements

    def wait_for_cross_validation(self, timeout: float | None = None) -> bool:
        """Wait until every sampled query so far is checked; false on timeout (true when off)."""
        return True if self._validator is None else self._validator.drain(timeout)

    def close(self) -> None:
        """Stop the cross-check's worker thread, if any (queries still work, unchecked)."""
        if self._validator is not None:
            self._validator.close()

    def warm_up(self, announce: Callable[[str], None] = _LOG.info, *, tool=None) -> None:
        """Compile (or load from cache) every kernel, so that the first real query is fast.

        The first call in a process takes seconds without numba's cache and about half a
        second with it; call this before a real-time loop starts (``load_scene`` does, without
        a tool). ``tool``: also ``query_tool``'s kernel, and the tool's pack (``tool``).
        ``announce`` gets one line when this process is the one that compiles.
        """
        with compiling(announce):
            self.query_many(np.zeros((1, 3)))
            _kernels.query_point(self._floats, self._ints, self._row, 0.0, 0.0, 0.0)
            self.query_within((0.0, 0.0, 0.0), 0.0)
            if tool is not None:
                self.query_tool(tool, ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))

    def query(self, point) -> QueryResult:
        """Signed distance from one tip position to the nearest object.

        Parameters
        ----------
        point : (3,) float, m, scene frame

        Returns
        -------
        QueryResult

        Raises
        ------
        ValueError
            If ``point`` is not 3 finite numbers.
        """
        x, y, z = _point(point)
        row = self._row
        _kernels.query_point(self._floats, self._ints, row, x, y, z)
        values = row.tolist()
        if values[9] == STATUS_INVALID_INPUT:
            raise _invalid((x, y, z))
        validator = self._validator
        if validator is None or values[7] < 0 or not validator.due():
            return QueryResult(values, self._names)
        submitted = validator.submit(int(values[7]), (x, y, z), values[0], values[1:4])
        return QueryResult(values, self._names, submitted)

    def query_many(self, points) -> BatchResult:
        """Signed distance from each of n tip positions to the nearest object (no FCL check).

        Parameters
        ----------
        points : (n, 3) float, m, scene frame

        Returns
        -------
        BatchResult
        """
        points = np.ascontiguousarray(points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 3:
            raise ValueError(f'points must have shape (n, 3), got {points.shape}')
        if not np.all(np.isfinite(points)):
            bad = int(np.argmin(np.all(np.isfinite(points), axis=1)))
            raise ValueError(f'points[{bad}] is not finite: {points[bad].tolist()}')
        rows = np.empty((len(points), _kernels.OUT_SIZE))
        _kernels.query_points(self._floats, self._ints, points, rows.reshape(-1))
        return BatchResult.from_rows(rows, self._names)

    def query_rows(self, points: np.ndarray) -> np.ndarray:
        """Return each point's packed row (n, ``_kernels.OUT_SIZE``), unchecked, for a hot loop.

        ``query_many`` without its checks and copies: ``points`` must be a C-contiguous
        (n, 3) float64 array of finite values (a validated pose's probe face is). Columns as
        ``_PackedRow.row``: distance, point (3), normal (3), object index, ...
        """
        rows = np.empty((len(points), _kernels.OUT_SIZE))
        _kernels.query_points(self._floats, self._ints, points, rows.reshape(-1))
        return rows

    def query_within(self, point, radius: float) -> list[QueryResult]:
        """Every object whose signed distance from the tip is at most ``radius``, nearest first.

        Parameters
        ----------
        point : (3,) float, m, scene frame
        radius : float, m

        Returns
        -------
        list of QueryResult
        """
        x, y, z = _point(point)
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            raise _invalid((x, y, z))
        if math.isnan(radius):
            raise ValueError('radius must not be NaN')
        rows = np.empty((len(self.objects), _kernels.OUT_SIZE))
        _kernels.query_each_object(self._floats, self._ints, rows.reshape(-1), x, y, z)
        rows = rows[rows[:, 0] <= radius]
        rows = rows[np.argsort(rows[:, 0], kind='stable')]
        return [QueryResult(row, self._names) for row in rows.tolist()]

    def query_tool(self, tool, pose) -> ToolResult:
        """Signed distance from a convex tool to the nearest object, with both witnesses.

        Convex objects are measured by the pair query (``narrowphase``: GJK apart, EPA or a
        closed form in overlap); a non-convex mesh by its tree and GJK per triangle apart, and
        in overlap by the deepest point of the tool's point shell (``tool_mesh``). One
        compiled call; the tool is validated and packed on its first query and kept.

        Parameters
        ----------
        tool : Box, Sphere, Cylinder, Capsule or ConvexMesh
            In its own frame (``tool.load_tool`` reads one from a mesh file).
        pose : Pose, or (position (3,), quaternion (4,))
            The tool's frame in the scene frame: m, and (x, y, z, w) of norm 1 within 1e-6.
            The pair form is the fast one (a ``Pose`` is converted to it on every call).

        Returns
        -------
        ToolResult

        Raises
        ------
        ValueError
            If the tool is not convex or is larger than ``workspace_size``, or the pose has
            NaN or infinite values or a quaternion that is not of unit norm.
        """
        if tool is not self._tool:  # one tool a loop, mostly: its pack is kept at hand
            self._tool_pack = pack_tool(tool, spacing=self.shell_spacing,
                                        workspace_size=self.workspace_size)
            self._tool = tool
        tool_floats, tool_ints = self._tool_pack
        try:
            (px, py, pz), (qx, qy, qz, qw) = pose
            px, py, pz, qx, qy, qz, qw = (float(px), float(py), float(pz), float(qx),
                                          float(qy), float(qz), float(qw))
        except (TypeError, ValueError):
            px, py, pz, qx, qy, qz, qw = _pose_values(pose)
        row = self._row
        _query_tool(self._floats, self._ints, tool_floats, tool_ints, row, px, py, pz, qx, qy,
                    qz, qw)
        values = row.tolist()
        if values[9] == STATUS_INVALID_INPUT:
            raise ValueError(f'tool pose must be a finite position and a unit quaternion '
                             f'(x, y, z, w), got {[px, py, pz]}, {[qx, qy, qz, qw]}')
        return ToolResult(values, self._names)

    def __repr__(self) -> str:
        return f'Scene(frame_id={self.frame_id!r}, objects={list(self._names)})'


def surface_projection(scene: Scene) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """``project(point) -> (closest surface point, outward normal)`` on a collision scene."""

    def project(point):
        result = scene.query(point)
        return result.point, result.normal
    return project


def load_scene(path, *, request: DistanceRequest | None = None,
               check_self_intersection: bool = True,
               announce: Callable[[str], None] = _LOG.info) -> Scene:
    """Read a scene file and build its scene, warmed up.

    Parameters
    ----------
    path : str or pathlib.Path
        The YAML scene (format in ``scene_file``).
    request : DistanceRequest, optional
        Tolerances and iteration caps.
    check_self_intersection : bool
        Reject self-intersecting meshes (``mesh_io.load_mesh``, compiled; no fcl), whose signed
        distance would have wrong signs. On by default; off only to load a huge mesh faster.
    announce : callable str -> None
        Told in one line when this process compiles the kernels (see ``Scene.warm_up``).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        For a bad scene file (see ``read_scene``).
    MeshError
        For a mesh file that cannot carry a signed distance: the scene file as given, the key
        and the mesh file, then the defect.
    """
    spec = read_scene(path)
    objects = []
    for index, declared in enumerate(spec.objects):
        try:
            shape = _build_shape(declared.shape, check_self_intersection)
        except MeshError as error:
            raise MeshError(f'{spec.path}: objects[{index}].shape.mesh.file: {error}') from None
        objects.append(SceneObject(declared.name, shape, declared.pose, declared.material))
    tool = None if spec.tool is None else _mount(spec)
    scene = Scene(objects, frame_id=spec.frame_id, tip_radius=spec.tip_radius,
                  request=request, cross_validation=spec.cross_validation, tool=tool)
    scene.warm_up(announce, tool=None if tool is None else tool.shape)
    return scene


def _mount(spec):
    """Build and mount the scene file's tool; errors name the file and the key."""
    declared = spec.tool
    if isinstance(declared.shape, MeshSpec):
        try:
            _import_trimesh_without_fcl()
            shape = load_tool(declared.shape.file, scale=declared.shape.scale)
        except MeshError as error:
            raise MeshError(f'{spec.path}: tool.shape.mesh.file: {error}') from None
    else:
        shape = _build_shape(declared.shape, False)
    try:
        return mount_tool(shape, declared.offset, face_spacing=declared.face_spacing,
                          workspace_size=DEFAULT_WORKSPACE_SIZE)
    except ValueError as error:
        raise SceneError(f'{spec.path}: tool: {error}') from None


def _build_shape(spec, check_self_intersection: bool):
    if isinstance(spec, BoxSpec):
        return Box(spec.size)
    if isinstance(spec, SphereSpec):
        return Sphere(spec.radius)
    if isinstance(spec, CylinderSpec):
        return Cylinder(spec.radius, spec.height)
    if isinstance(spec, CapsuleSpec):
        return Capsule(spec.radius, spec.length)
    from collision_engine.mesh_io import load_mesh

    _import_trimesh_without_fcl()
    mesh = load_mesh(Path(spec.file), scale=spec.scale,
                     check_self_intersection=check_self_intersection)
    convex = mesh.is_convex if spec.convex is None else spec.convex
    if convex:
        return ConvexMesh(mesh.vertices)
    return TriangleMesh(mesh.vertices, mesh.faces, name=str(spec.file))


def _import_trimesh_without_fcl() -> None:
    """Import trimesh with fcl hidden, unless either is loaded already.

    ``import trimesh`` imports fcl when it is installed (for trimesh's collision manager, which
    nothing here uses), which would load fcl for every mesh scene. Hidden, trimesh keeps a
    stand-in that raises on use, and a later ``import fcl`` (cross-validation) loads the real
    one.
    """
    if 'trimesh' in sys.modules or 'fcl' in sys.modules:
        return
    sys.modules['fcl'] = None
    try:
        import trimesh  # noqa: F401
    finally:
        del sys.modules['fcl']
