"""Our signed distance on extreme geometry: tiny, huge, far, thin, grazing, degenerate, NaN.

    .venv/bin/python bench/extreme_cases.py [--points 200] [--seed 0] [--json PATH]

Each case queries ``collision_engine.distance`` (the public one-shape API, default request) on
a few hundred points and reports, against exact ground truth (``ground_truth/distances.py``:
analytic for boxes and cylinders, brute force with a winding-number sign for meshes; points
are taken to the local frame here with numpy, not with the engine's ``Pose``): the largest
error in metres and as a fraction of the object's size, the most iterations, the statuses, and
the agreement with FCL (``collision_engine.cross_validation.FclCrossValidator``: the largest
``|ours - FCL|``, and how many points FCL disagreed on beyond its own error model plus 1e-9 of
the object's size; FCL is unsigned on a triangle mesh, so magnitudes are compared there).
Cases whose outcome is an exception (NaN input, a flat point set) report the exception.

Importable: ``rows()`` returns the table as ``ExtremeRow``s and ``format_rows`` prints it.
"""

import argparse
from dataclasses import dataclass
import math
import multiprocessing
import os
import tempfile
from typing import Callable

from bench import result_files
from ground_truth import distances
import numpy as np
from scipy.spatial.transform import Rotation

from collision_engine import (Box, ConvexMesh, Cylinder, distance, Pose, STATUS_NOT_CONVERGED,
                              STATUS_OK, TriangleMesh)
from collision_engine.cross_validation import FclCrossValidator

__all__ = ['ExtremeRow', 'format_rows', 'rows', 'main']

GRAZE = 1e-12  # [m] offset of the grazing points from the surface
FCL_TOLERANCE = 1e-9  # of the object's size, on top of FCL's own error model
FCL_TIMEOUT = 60.0  # [s] for FCL's answers to one case
STATUS_NAMES = {STATUS_OK: 'OK', STATUS_NOT_CONVERGED: 'NOT_CONVERGED'}


@dataclass(frozen=True)
class ExtremeRow:
    """One case: how far our answers were from the truth, and from FCL's.

    Attributes
    ----------
    case : str
    scale : float, m
        The object's largest extent.
    points : int
    max_error, max_relative_error : float
        Largest ``|ours - truth|``, m, and that divided by ``scale`` (NaN when it raised).
    max_iterations : int
    statuses : str
        Count per status, e.g. ``'OK 200'``.
    fcl_max_discrepancy : float, m
    fcl_disagreements : int
    outcome : str
        ``'answered'``, or the exception raised.
    """

    case: str
    scale: float
    points: int
    max_error: float
    max_relative_error: float
    max_iterations: int
    statuses: str
    fcl_max_discrepancy: float
    fcl_disagreements: int
    outcome: str


@dataclass(frozen=True)
class _Case:
    name: str
    shape: object
    rotation: np.ndarray
    translation: np.ndarray
    local_truth: Callable[[np.ndarray], np.ndarray]
    local_points: np.ndarray
    scale: float


def _box_surface(size, count: int, offset: float, rng) -> np.ndarray:
    """Points ``offset`` m off random points of a box's faces, half inside, half outside."""
    half = 0.5 * np.asarray(size, dtype=np.float64)
    axis = rng.integers(0, 3, count)
    side = rng.choice([-1.0, 1.0], count)
    points = rng.uniform(-0.9, 0.9, (count, 3)) * half
    sign = np.where(np.arange(count) < count // 2, -1.0, 1.0)
    points[np.arange(count), axis] = side * (half[axis] + sign * offset)
    return points


def _cylinder_side(radius: float, height: float, count: int, offset: float,
                   rng) -> np.ndarray:
    """Points ``offset`` m off random points of a cylinder's curved side, half inside."""
    angle = rng.uniform(0.0, 2.0 * np.pi, count)
    sign = np.where(np.arange(count) < count // 2, -1.0, 1.0)
    r = radius + sign * offset
    z = rng.uniform(-0.4, 0.4, count) * height
    return np.column_stack((r * np.cos(angle), r * np.sin(angle), z))


def _around(shape_size, count: int, rng) -> np.ndarray:
    """Points uniform in twice the bounding box of an extent (3,) centred at the origin."""
    return rng.uniform(-1.0, 1.0, (count, 3)) * np.asarray(shape_size, dtype=np.float64)


def _box_case(name: str, size, count: int, rng, *, rotation=None, translation=(0, 0, 0),
              graze: bool = False) -> _Case:
    size = np.asarray(size, dtype=np.float64)
    near = _box_surface(size, count - count // 2, 1e-3 * size.min(), rng)
    points = (_box_surface(size, count, GRAZE, rng) if graze
              else np.vstack((_around(size, count // 2, rng), near)))
    return _Case(name, Box(size), np.eye(3) if rotation is None else rotation,
                 np.asarray(translation, dtype=np.float64),
                 lambda p: distances.box_signed_distance(p, size), points, float(size.max()))


def _cylinder_case(name: str, radius: float, height: float, count: int, rng, *,
                   graze: bool = False) -> _Case:
    extent = np.array([radius, radius, 0.5 * height])
    near = _cylinder_side(radius, height, count - count // 2, 1e-3 * radius, rng)
    points = (_cylinder_side(radius, height, count, GRAZE, rng) if graze
              else np.vstack((_around(2 * extent, count // 2, rng), near)))
    return _Case(name, Cylinder(radius, height), np.eye(3), np.zeros(3),
                 lambda p: distances.cylinder_signed_distance(p, radius, height), points,
                 float(max(2 * radius, height)))


def _mesh_case(name: str, shape, count: int, rng) -> _Case:
    """Points GRAZE m off random points of a closed mesh (or hull), truth by brute force."""
    points, _ = distances.sample_near_surface(shape.vertices, shape.faces, count, GRAZE, rng)
    extent = shape.vertices.max(axis=0) - shape.vertices.min(axis=0)
    return _Case(name, shape, np.eye(3), np.zeros(3),
                 lambda p: distances.mesh_signed_distance(p, shape.vertices, shape.faces)[0],
                 points, float(extent.max()))


def _cube_with_ties(edge: float) -> tuple[ConvexMesh, np.ndarray]:
    """Build a cube hull from duplicated, coplanar and collinear points; and query points.

    The queries lie on the lines through the cube's centre and its face centres, edge
    midpoints and corners, so every support GJK asks for is tied between 4 or 2 vertices.
    """
    half = 0.5 * edge
    corners = np.array([[x, y, z] for x in (-half, half) for y in (-half, half)
                        for z in (-half, half)])
    face_centres = np.vstack((np.eye(3), -np.eye(3))) * half
    edge_midpoints = np.array([c for c in {tuple(np.where(np.arange(3) == k, 0.0, corner))
                                           for corner in corners for k in range(3)}])
    hull = ConvexMesh(np.vstack((corners, corners, corners, face_centres, edge_midpoints)))
    directions = np.vstack((face_centres, edge_midpoints, corners)) / half
    distances = np.array([-0.9, -0.5, -1e-6, -GRAZE, GRAZE, 1e-6, 0.5, 2.0]) * half
    units = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    queries = directions[:, None, :] * half + distances[None, :, None] * units[:, None, :]
    return hull, queries.reshape(-1, 3)


def _hand() -> TriangleMesh:
    from collision_engine.mesh_io import load_mesh

    mesh = load_mesh(distances.hand_mesh_path(), scale=0.001, check_self_intersection=False)
    return TriangleMesh(mesh.vertices, mesh.faces)


def _cases(count: int, rng) -> list[_Case]:
    cylinder_hull = ConvexMesh(np.array([[0.025 * np.cos(a), 0.025 * np.sin(a), z]
                                         for a in np.linspace(0, 2 * np.pi, 38, endpoint=False)
                                         for z in (-0.05, 0.05)]))
    needle = np.array([1.0, 1e-6, 1e-6])
    needle_corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-5e-7, 5e-7)
                               for z in (-5e-7, 5e-7)])
    hull, tie_points = _cube_with_ties(0.1)
    rotation = Rotation.from_euler('xyz', [0.3, -0.7, 1.1]).as_matrix()
    return [
        _box_case('box, 1e-4 m', (1e-4, 1e-4, 1e-4), count, rng),
        _cylinder_case('cylinder, 1e-4 m', 5e-5, 1e-4, count, rng),
        _box_case('box, 1e3 m', (1e3, 1e3, 1e3), count, rng),
        _cylinder_case('cylinder, 1e3 m', 500.0, 1e3, count, rng),
        _box_case('box 0.1 m, offset 1e3 m, rotated', (0.1, 0.1, 0.1), count, rng,
                  rotation=rotation, translation=(1e3, -1e3, 1e3)),
        _box_case('box, aspect 1e6 (plate 1 x 1 x 1e-6 m)', (1.0, 1.0, 1e-6), count, rng),
        _box_case('box, aspect 1e6 (needle 1 x 1e-6 x 1e-6 m)', needle, count, rng),
        _Case('hull of the needle (8 corners), aspect 1e6', ConvexMesh(needle_corners),
              np.eye(3), np.zeros(3), lambda p: distances.box_signed_distance(p, needle),
              _box_case('', needle, count, rng).local_points, 1.0),
        _box_case('box 0.1 m, points 1e-12 m off a face', (0.2, 0.1, 0.1), count, rng,
                  graze=True),
        _cylinder_case('cylinder, points 1e-12 m off the side', 0.025, 0.1, count, rng,
                       graze=True),
        _mesh_case('hull (76 vertices), points 1e-12 m off a face', cylinder_hull, count, rng),
        _mesh_case('hand mesh, points 1e-12 m off a face', _hand(), min(count, 100), rng),
        _Case('cube hull from duplicated, coplanar, collinear points (tied supports)', hull,
              np.eye(3), np.zeros(3),
              lambda p: distances.box_signed_distance(p, (0.1, 0.1, 0.1)), tie_points, 0.1),
    ]


def _evaluate(case: _Case) -> ExtremeRow:
    pose = Pose(case.rotation, case.translation)
    world = case.local_points @ case.rotation.T + case.translation
    truth = case.local_truth((world - case.translation) @ case.rotation)
    results = [distance(case.shape, pose, point) for point in world]
    errors = np.abs(np.array([r.distance for r in results]) - truth)
    statuses = {}
    for result in results:
        name = STATUS_NAMES.get(result.status, str(result.status))
        statuses[name] = statuses.get(name, 0) + 1
    fcl_discrepancy, fcl_disagreements, fcl_outcome = _fcl_agreement(case, pose, world, results)
    max_error = float(errors.max())
    return ExtremeRow(case.name, case.scale, len(world), max_error, max_error / case.scale,
                      max(r.iterations for r in results),
                      ', '.join(f'{k} {v}' for k, v in statuses.items()), fcl_discrepancy,
                      fcl_disagreements, fcl_outcome)


def _fcl_agreement(case: _Case, pose: Pose, world: np.ndarray, results: list) -> tuple:
    """Compare our answers with FCL's, in a child process: FCL can abort on thin shapes.

    Returns (largest |ours - FCL| m, disagreements, outcome): the outcome is ``'answered'``,
    or FCL's last error line when its process died (NaN and 0 then).
    """
    context = multiprocessing.get_context('fork')
    receiver, sender = context.Pipe(duplex=False)
    with tempfile.TemporaryFile() as stderr:
        child = context.Process(target=_fcl_child, args=(case, pose, world, results, sender,
                                                         stderr.fileno()))
        child.start()
        sender.close()
        try:
            answer = receiver.recv() if receiver.poll(FCL_TIMEOUT) else None
        except EOFError:  # it died before answering
            answer = None
        child.join(FCL_TIMEOUT)
        stderr.seek(0)
        said = stderr.read().decode(errors='replace')
    if answer is None or child.exitcode != 0:
        return math.nan, 0, f'answered; FCL aborted its process: {_abort_cause(said, child)}'
    return answer[0], answer[1], 'answered'


def _abort_cause(said: str, child) -> str:
    """Extract FCL's own error message from what its process printed, else its exit code."""
    lines = [line.strip() for line in said.splitlines()]
    for marker in ('Original error message:', 'what():'):
        for line in lines:
            if marker in line:
                return line.split(marker, 1)[1].strip().rsplit('): ', 1)[-1]
    return f'exit code {child.exitcode}'


def _fcl_child(case: _Case, pose: Pose, world: np.ndarray, results: list, sender,
               stderr: int) -> None:
    os.dup2(stderr, 2)
    validator = FclCrossValidator([case.shape], [pose], tolerance=FCL_TOLERANCE * case.scale)
    discrepancies = [validator.check(0, point, result.distance, result.point)[1]
                     for point, result in zip(world, results)]
    sender.send((float(np.nanmax(discrepancies)), validator.stats.disagreements))


def _raised(case: str, scale: float, attempt: Callable[[], object]) -> ExtremeRow:
    """Run an input that must be refused; the row says what was raised."""
    try:
        attempt()
    except ValueError as error:
        outcome = f'{type(error).__name__}: {error}'
    else:
        outcome = 'answered (expected a ValueError)'
    return ExtremeRow(case, scale, 1, math.nan, math.nan, 0, '-', math.nan, 0, outcome)


def rows(points: int = 200, seed: int = 0) -> list[ExtremeRow]:
    """Evaluate every case (a few seconds for 200 points a case)."""
    rng = np.random.default_rng(seed)
    table = [_evaluate(case) for case in _cases(points, rng)]
    box = Box((0.1, 0.1, 0.1))
    table.append(_raised('NaN in the query point', 0.1,
                         lambda: distance(box, Pose(), (math.nan, 0.0, 0.0))))
    table.append(_raised('Inf in the query point', 0.1,
                         lambda: distance(box, Pose(), (0.0, math.inf, 0.0))))
    table.append(_raised('flat point set (4 coplanar points) as a ConvexMesh', 1.0,
                         lambda: ConvexMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])))
    return table


def format_rows(table: list[ExtremeRow]) -> str:
    """Format the rows as a fixed-width text table."""
    lines = [f'{"case":<72} {"size m":>7} {"n":>4} {"max err m":>9} {"err/size":>8} '
             f'{"iter":>4} {"FCL |d| m":>9} {"FCL dis":>7}  statuses / outcome']
    for r in table:
        tail = '; '.join(t for t in (r.statuses, r.outcome) if t not in ('-', 'answered'))
        lines.append(f'{r.case:<72} {r.scale:7.0e} {r.points:4d} {r.max_error:9.1e} '
                     f'{r.max_relative_error:8.1e} {r.max_iterations:4d} '
                     f'{r.fcl_max_discrepancy:9.1e} {r.fcl_disagreements:7d}  {tail}')
    return '\n'.join(lines)


def main(argv=None) -> None:
    """Print the extreme-geometry table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--points', type=int, default=200, help='query points per case')
    parser.add_argument('--seed', type=int, default=0)
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    table = rows(args.points, args.seed)
    print(format_rows(table))
    result_files.write(args.json, table)


if __name__ == '__main__':
    main()
