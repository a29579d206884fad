"""Scripted targets for the operator's hand: where the user means the tip to be, over time.

Two kinds of script: :class:`WaypointScript` (user waypoints, each leg a minimum-jerk move) and
:class:`TappingScript` (approach a surface site along its normal, press to a depth inside,
retract, move on). The factories :func:`hand_dorsum_tapping`, :func:`cylinder_side_tapping` and
:func:`cuboid_face_tapping` rebuild the paper's three ~10 s tapping experiments;
:func:`probe_sweep` presses a probe's face on a surface and rolls, slides and yaws it.

Scripts know no geometry engine: the caller passes ``project(point) -> (surface_point,
outward_normal)``, built from its scene, and the factories' nominal aim points are only where to
look for the surface. Their defaults assume the paper's layout: the wand starting at (0, 0, 0), the
object centred at (0, 0, -0.075) m below it. Times are seconds from the script's start; positions
m and angles rad in the workspace frame.
"""

from bisect import bisect_right
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, NamedTuple, Protocol, Sequence

import numpy as np

from haptic_contract.checks import finite_number, finite_vector, whole_number
from haptic_wand_driver.device import Workspace
from haptic_wand_driver.pose_table import PoseFileError, PoseTable, read_pose_csv

__all__ = [
    'CUBOID_FACE_AIMS',
    'CYLINDER_SIDE_AIMS',
    'HAND_DORSUM_AIMS',
    'Projection',
    'Script',
    'ScriptError',
    'TappingScript',
    'TappingSite',
    'Target',
    'TargetComponents',
    'WaypointScript',
    'cuboid_face_tapping',
    'cylinder_side_tapping',
    'hand_dorsum_tapping',
    'probe_sweep',
]

Projection = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
"""``project(point (3,)) -> (surface_point (3,), outward_normal (3,))``, m, workspace frame."""

_WAYPOINT_FIELDS = ('t', 'x', 'y', 'z', 'roll', 'yaw')
_REQUIRED_WAYPOINT_FIELDS = _WAYPOINT_FIELDS[:4]
_SHORTEST_MOVE = 0.1
"""Shortest time (s) a scripted hand takes for any move between taps."""


class ScriptError(ValueError):
    """A script cannot be built as asked; the message names the file, waypoint or tap."""


class Target(NamedTuple):
    """Where the hand wants the tip at one instant.

    coordinates : (5,) float: x, y, z [m], roll, yaw [rad].
    rates : (5,) float: their time derivatives [m/s, rad/s].
    """

    coordinates: np.ndarray
    rates: np.ndarray


TargetComponents = tuple[tuple[float, ...], tuple[float, ...]]
"""A target as two tuples of 5 floats, coordinates and rates, as in :class:`Target`."""

_AT_REST = (0.0,) * 5


class Script(Protocol):
    """A target as a function of time; holds its last target after ``duration``.

    A script may also offer ``target_components(t) -> TargetComponents``, the same target as
    floats, which the simulated hand then calls on every substep instead of :meth:`target`.
    """

    duration: float

    def target(self, t: float) -> Target:
        """Return the target at ``t`` seconds from the script's start."""


def _minimum_jerk(tau: float) -> tuple[float, float]:
    """Return s(tau) and ds/dtau of the rest-to-rest minimum-jerk profile (Flash & Hogan 1985)."""
    return (tau ** 3 * (10.0 + tau * (-15.0 + 6.0 * tau)),
            30.0 * tau ** 2 * (1.0 - tau) ** 2)


class WaypointScript:
    """Waypoints joined by minimum-jerk legs that start and end at rest.

    Parameters
    ----------
    times : (n,) float, s
        Strictly increasing, >= 0. Before the first the target is the first waypoint.
    coordinates : (n, 5) float
        x, y, z [m], roll, yaw [rad] per waypoint.
    workspace : Workspace
        Every waypoint must lie inside it (then so does every leg: the workspace is convex).

    Raises
    ------
    ScriptError
        Naming the waypoint and what is wrong.
    """

    def __init__(self, times, coordinates, *, workspace: Workspace = Workspace()):
        try:
            table = PoseTable(times, coordinates)
        except ValueError as error:
            raise ScriptError(f'waypoints: {error}') from None
        if table.times[0] < 0.0:
            raise ScriptError(f'waypoint 0: time {table.times[0]!r} s is negative')
        for index, coordinate in enumerate(table.coordinates):
            if not workspace.contains(coordinate):
                raise ScriptError(f'waypoint {index}: {coordinate.tolist()} lies outside the '
                                  f'workspace {workspace}')
        self._times = table.times
        self._coordinates = table.coordinates
        self._time_list = table.times.tolist()
        waypoints = table.coordinates.tolist()
        self._at_first = (tuple(waypoints[0]), _AT_REST)
        self._at_last = (tuple(waypoints[-1]), _AT_REST)
        # Per leg, as floats: its start (5), the displacement to its end (5), its duration.
        self._legs = [(start, [b - a for a, b in zip(start, end)], t1 - t0)
                      for start, end, t0, t1 in zip(waypoints, waypoints[1:], self._time_list,
                                                    self._time_list[1:])]

    @classmethod
    def from_rows(cls, rows: Sequence[Sequence[float]], *,
                  workspace: Workspace = Workspace()) -> 'WaypointScript':
        """Build from rows (t, x, y, z) or (t, x, y, z, roll, yaw); omitted angles are zero."""
        padded = []
        for index, row in enumerate(rows):
            if len(row) not in (4, 6):
                raise ScriptError(f'waypoint {index}: expected (t, x, y, z) or '
                                  f'(t, x, y, z, roll, yaw), got {row!r}')
            padded.append([*row, 0.0, 0.0][:6])
        if not padded:
            raise ScriptError('waypoints: the list is empty')
        try:
            array = np.array(padded, dtype=np.float64)
        except ValueError as error:
            raise ScriptError(f'waypoints: not all numbers: {error}') from None
        return cls(array[:, 0], array[:, 1:], workspace=workspace)

    @classmethod
    def from_file(cls, path: str | Path, *,
                  workspace: Workspace = Workspace()) -> 'WaypointScript':
        """Read waypoints from CSV (pose-table columns) or YAML.

        The YAML form is a list under ``waypoints``, each a mapping with ``t, x, y, z`` and
        optionally ``roll, yaw``::

            waypoints:
              - {t: 0.0, x: 0.0, y: 0.0, z: 0.0}
              - {t: 1.5, x: 0.0, y: 0.0, z: -0.05, yaw: 0.2}
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == '.csv':
            try:
                table = read_pose_csv(path)
            except PoseFileError as error:
                raise ScriptError(str(error)) from None
            rows = np.column_stack([table.times, table.coordinates])
        elif suffix in ('.yaml', '.yml'):
            rows = _read_yaml_waypoints(path)
        else:
            raise ScriptError(f'{path}: unsupported waypoint file type {suffix!r}; use .csv, '
                              f'.yaml or .yml')
        try:
            return cls.from_rows(rows, workspace=workspace)
        except ScriptError as error:
            raise ScriptError(f'{path}: {error}') from None

    @property
    def times(self) -> np.ndarray:
        """(n,) float, s: the waypoint times."""
        return self._times

    @property
    def coordinates(self) -> np.ndarray:
        """(n, 5) float: the waypoints, x, y, z [m], roll, yaw [rad]."""
        return self._coordinates

    @property
    def duration(self) -> float:
        """Time of the last waypoint, s."""
        return float(self._times[-1])

    def target(self, t: float) -> Target:
        """Return the target at ``t`` seconds from the start."""
        coordinates, rates = self.target_components(t)
        return Target(np.array(coordinates), np.array(rates))

    def target_components(self, t: float) -> TargetComponents:
        """Return :meth:`target` as floats: the simulated hand's per-substep path."""
        times = self._time_list
        if t <= times[0]:
            return self._at_first
        if t >= times[-1]:
            return self._at_last
        leg = bisect_right(times, t) - 1
        (x, y, z, roll, yaw), (dx, dy, dz, droll, dyaw), span = self._legs[leg]
        fraction, speed = _minimum_jerk((t - times[leg]) / span)
        speed /= span  # written out per joint: a comprehension costs 3x more in Python 3.11
        return ((x + fraction * dx, y + fraction * dy, z + fraction * dz,
                 roll + fraction * droll, yaw + fraction * dyaw),
                (speed * dx, speed * dy, speed * dz, speed * droll, speed * dyaw))


def _read_yaml_waypoints(path: Path) -> list[list[float]]:
    """Return rows (t, x, y, z, roll, yaw) from a YAML waypoint file, or raise naming the key."""
    import yaml

    try:
        document = yaml.safe_load(path.read_text())
    except OSError as error:
        raise ScriptError(f'{path}: cannot read waypoints: {error.strerror or error}') from None
    except (yaml.YAMLError, UnicodeDecodeError) as error:
        raise ScriptError(f'{path}: not valid YAML: {error}') from None
    if not isinstance(document, dict) or 'waypoints' not in document:
        raise ScriptError(f'{path}: expected a mapping with key "waypoints"')
    entries = document['waypoints']
    if not isinstance(entries, list) or not entries:
        raise ScriptError(f'{path}: "waypoints" must be a non-empty list')
    rows = []
    for index, entry in enumerate(entries):
        where = f'{path}: waypoints[{index}]'
        if not isinstance(entry, dict):
            raise ScriptError(f'{where}: expected a mapping with t, x, y, z, got {entry!r}')
        unknown = sorted(set(map(str, entry)) - set(_WAYPOINT_FIELDS))
        if unknown:
            raise ScriptError(f'{where}: unknown field(s) {", ".join(unknown)}; allowed: '
                              f'{", ".join(_WAYPOINT_FIELDS)}')
        missing = [name for name in _REQUIRED_WAYPOINT_FIELDS if name not in entry]
        if missing:
            raise ScriptError(f'{where}: missing field(s) {", ".join(missing)}')
        row = []
        for name in _WAYPOINT_FIELDS:
            value = entry.get(name, 0.0)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ScriptError(f'{where}.{name}: expected a number, got {value!r}')
            row.append(float(value))
        rows.append(row)
    return rows


@dataclass(frozen=True, eq=False)
class TappingSite:
    """One place to tap.

    Parameters
    ----------
    point : (3,) float, m
        The surface point.
    normal : (3,) float
        Outward surface normal there (normalised on construction).
    roll, yaw : float, rad
        The wand's orientation while tapping it.
    """

    point: np.ndarray
    normal: np.ndarray
    roll: float = 0.0
    yaw: float = 0.0

    def __post_init__(self):
        point = finite_vector(self.point, 3, 'TappingSite.point', error=ScriptError)
        normal = finite_vector(self.normal, 3, 'TappingSite.normal', error=ScriptError)
        length = np.linalg.norm(normal)
        if length < 1e-9:
            raise ScriptError(f'TappingSite.normal must not be zero, got {normal.tolist()}')
        for name in ('roll', 'yaw'):
            finite_number(getattr(self, name), f'TappingSite.{name}', error=ScriptError)
        object.__setattr__(self, 'point', point)
        object.__setattr__(self, 'normal', normal / length)


def _descent_time(clearance: float, depth: float, approach_speed: float) -> float:
    """Return the time (s) of a minimum-jerk descent that crosses the surface at approach_speed.

    The descent runs from ``clearance`` outside the surface to ``depth`` inside it.
    """
    travel = clearance + depth
    roots = np.roots([6.0, -15.0, 10.0, 0.0, 0.0, -clearance / travel])
    real = roots[np.abs(roots.imag) < 1e-9].real
    crossing = real[(real >= 0.0) & (real <= 1.0)][0]
    return travel * _minimum_jerk(crossing)[1] / approach_speed


def _approach_and_press_points(sites: Sequence[TappingSite], clearance: float, depth: float,
                               workspace: Workspace) -> tuple[list, list]:
    """Return per site the (5,) coordinates ``clearance`` outside and ``depth`` inside it."""
    approaches, presses = [], []
    for index, site in enumerate(sites):
        angles = [site.roll, site.yaw]
        approaches.append(np.concatenate([site.point + clearance * site.normal, angles]))
        presses.append(np.concatenate([site.point - depth * site.normal, angles]))
        for name, point in (('approach', approaches[-1]), ('press', presses[-1])):
            if not workspace.contains(point):
                raise ScriptError(f'tap {index}: {name} point {point.tolist()} (x, y, z, roll, '
                                  f'yaw) lies outside the workspace {workspace}')
    return approaches, presses


class TappingScript:
    """Tap a sequence of sites: approach along the normal, press, hold, retract, move on.

    From ``start`` the hand first moves, at the start's height, to above the first approach point,
    then straight down to it: in the paper's layout the objects sit below the start.
    Each tap then takes a descent from ``clearance`` outside the surface to ``depth`` inside,
    timed to cross the surface at ``approach_speed``, a hold of ``dwell``, and the reverse. The
    moves between taps share out what remains of ``duration``. Every leg is minimum-jerk.

    Parameters
    ----------
    sites : sequence of TappingSite
        Tapped in order, one tap each.
    duration : float, s
        When the last retract ends (with one site, the script may end sooner).
    start : (3,) float, m
        Where the tip starts (roll and yaw 0).
    clearance : float, m
        Approach point's distance outside the surface.
    depth : float, m
        How far inside the surface the hand aims; the rendered force stops the tip sooner.
    approach_speed : float, m/s
        Target speed along the normal when crossing the surface.
    dwell : float, s
        Hold at depth.
    move_speed : float, m/s
        Mean speed of the lead-in from ``start``.
    workspace : Workspace
        Every approach and press point must lie inside.
    """

    def __init__(self, sites: Sequence[TappingSite], *, duration: float = 10.0,
                 start=(0.0, 0.0, 0.0), clearance: float = 0.02, depth: float = 0.01,
                 approach_speed: float = 0.2, dwell: float = 0.2, move_speed: float = 0.2,
                 workspace: Workspace = Workspace()):
        for name, value in (('duration', duration), ('clearance', clearance), ('depth', depth),
                            ('approach_speed', approach_speed), ('dwell', dwell),
                            ('move_speed', move_speed)):
            finite_number(value, f'TappingScript {name}', minimum=0.0, strict=True,
                          error=ScriptError)
        if not sites:
            raise ScriptError('TappingScript needs at least one site')
        start = np.concatenate([finite_vector(start, 3, 'TappingScript start',
                                              error=ScriptError), [0.0, 0.0]])
        approaches, presses = _approach_and_press_points(sites, clearance, depth, workspace)
        descent = _descent_time(clearance, depth, approach_speed)
        above_first = np.concatenate([approaches[0][:2], start[2:3], approaches[0][3:]])
        times = [0.0]
        waypoints = [start]
        for point in (above_first, approaches[0]):
            distance = np.linalg.norm(point[:3] - waypoints[-1][:3])
            times.append(times[-1] + max(distance / move_speed, _SHORTEST_MOVE))
            waypoints.append(point)
        tap_time = 2.0 * descent + dwell
        move = (duration - times[-1] - len(sites) * tap_time) / max(len(sites) - 1, 1)
        if move < _SHORTEST_MOVE:
            raise ScriptError(
                f'TappingScript: {len(sites)} taps of {tap_time:.3f} s after a {times[-1]:.3f} '
                f's lead-in leave {move:.3f} s per move in {duration} s; at least '
                f'{_SHORTEST_MOVE} s is needed: fewer taps, a longer duration or a faster '
                f'approach')
        for index, (approach, press) in enumerate(zip(approaches, presses)):
            if index:
                times.append(times[-1] + move)
                waypoints.append(approach)
            times += [times[-1] + descent, times[-1] + descent + dwell, times[-1] + tap_time]
            waypoints += [press, press, approach]
        self._waypoints = WaypointScript(times, waypoints, workspace=workspace)
        self._sites = tuple(sites)

    @property
    def sites(self) -> tuple[TappingSite, ...]:
        """The sites, in tapping order."""
        return self._sites

    @property
    def duration(self) -> float:
        """When the last retract ends, s."""
        return self._waypoints.duration

    def target(self, t: float) -> Target:
        """Return the target at ``t`` seconds from the start."""
        return self._waypoints.target(t)

    def target_components(self, t: float) -> TargetComponents:
        """Return :meth:`target` as floats: the simulated hand's per-substep path."""
        return self._waypoints.target_components(t)


def _facing_yaw(normal: np.ndarray, heading: float, yaw_limit: float) -> float:
    """Yaw that turns the wand from ``heading`` toward a mostly horizontal push into the surface.

    A push steeper than 45 degrees keeps yaw 0; the result is clipped to +-yaw_limit.
    """
    push = -normal[:2]
    if np.linalg.norm(push) < np.sqrt(0.5):
        return 0.0
    turn = (np.arctan2(push[1], push[0]) - heading + np.pi) % (2.0 * np.pi) - np.pi
    return float(np.clip(turn, -yaw_limit, yaw_limit))


def _tapping_from_aims(project: Projection, aim_points, taps: int, heading: float,
                       workspace: Workspace, options) -> TappingScript:
    """Project each aim point onto the surface and tap the sites, cycling through the aims."""
    aims = np.asarray(aim_points, dtype=np.float64)
    if aims.ndim != 2 or aims.shape[1] != 3 or len(aims) == 0:
        raise ScriptError(f'aim_points must be (n, 3), n >= 1, got shape {aims.shape}')
    sites = []
    for index in range(whole_number(taps, 'taps', error=ScriptError)):
        aim = aims[index % len(aims)]
        point, normal = project(aim)
        try:
            site = TappingSite(point, normal)
        except ScriptError as error:
            raise ScriptError(f'tap {index}: project({aim.tolist()}) gave an unusable site: '
                              f'{error}') from None
        sites.append(replace(site, yaw=_facing_yaw(site.normal, heading, workspace.yaw_limit)))
    return TappingScript(sites, workspace=workspace, **options)


def _serpentine(columns, rows, constant: float, axes: tuple[int, int, int]) -> np.ndarray:
    """Grid points visited row by row, alternating direction, so consecutive taps are close."""
    points = []
    for row_index, row in enumerate(rows):
        ordered = columns if row_index % 2 == 0 else columns[::-1]
        for column in ordered:
            point = np.empty(3)
            point[list(axes)] = (column, row, constant)
            points.append(point)
    return np.array(points)


HAND_DORSUM_AIMS = _serpentine(np.linspace(-0.015, 0.035, 6), (-0.06, -0.03), -0.035,
                               (0, 1, 2))[:11]
"""(11, 3) m: 2 cm above the back of a hand lying palm down, fingers along +y, its bounding box
centred at (0, 0, -0.075) (the back at z ~ -0.055 for y < 0), zig-zagging in x."""

CYLINDER_SIDE_AIMS = np.array([
    (0.05 * np.sin(angle), -0.05 * np.cos(angle), height)
    for angle, height in zip(np.radians(np.linspace(-24.0, 24.0, 9)), [-0.065, -0.085] * 5)])
"""(9, 3) m: beside the curved side of an upright r = 0.025 m, h = 0.1 m cylinder centred at
(0, 0, -0.075), on its -y side, sweeping +-24 degrees around the axis at two heights."""

CUBOID_FACE_AIMS = _serpentine(np.array([-0.03, 0.0, 0.03]), (-0.055, -0.075, -0.095), -0.13,
                               (1, 2, 0))
"""(9, 3) m: a 3 x 3 grid beside the -x end face (x = -0.1) of the 0.2 x 0.1 x 0.1 m cuboid
centred at (0, 0, -0.075), its long edge along x."""


def hand_dorsum_tapping(project: Projection, *, aim_points=HAND_DORSUM_AIMS, taps: int = 11,
                        workspace: Workspace = Workspace(), **options) -> TappingScript:
    """Script the paper's first experiment: 11 taps on the dorsum of a hand model in ~10 s.

    ``options`` go to :class:`TappingScript` (duration, clearance, depth, approach_speed, ...).
    The pushes are mostly downward, so yaw stays 0.
    """
    return _tapping_from_aims(project, aim_points, taps, 0.0, workspace, options)


def cylinder_side_tapping(project: Projection, *, aim_points=CYLINDER_SIDE_AIMS, taps: int = 9,
                          workspace: Workspace = Workspace(), **options) -> TappingScript:
    """Script the paper's second experiment: 9 taps on the curved side of a cylinder in ~10 s.

    The default aims push toward +y; the wand yaws from that heading to face each site,
    within the workspace's yaw limit. ``options`` go to :class:`TappingScript`.
    """
    return _tapping_from_aims(project, aim_points, taps, 0.5 * np.pi, workspace, options)


def cuboid_face_tapping(project: Projection, *, aim_points=CUBOID_FACE_AIMS, taps: int = 9,
                        workspace: Workspace = Workspace(), **options) -> TappingScript:
    """Script the paper's third experiment: 9 taps on the -x face of a cuboid in ~10 s (Table 4).

    The pushes go toward +x, so the rendered force is along -x, as in the paper's Table 4.
    ``options`` go to :class:`TappingScript`.
    """
    return _tapping_from_aims(project, aim_points, taps, 0.0, workspace, options)


PROBE_SWEEP = (
    # (t s, x m, roll, yaw) in units of the sweep's slide and tilt; z from the surface.
    (1.8, 0.0, 0.0, 0.0), (2.2, 0.0, 0.0, 0.0),    # press, settle
    (3.2, 0.0, 1.0, 0.0), (3.5, 0.0, 1.0, 0.0),    # roll +tilt, hold
    (5.0, 0.0, -1.0, 0.0), (5.3, 0.0, -1.0, 0.0),  # roll -tilt, hold
    (6.3, 1.0, 0.0, 0.0),                          # flat again, sliding
    (7.3, 1.0, 0.0, 1.0), (8.3, -1.0, 0.0, -1.0),  # yaw +tilt, then slide back yawing -tilt
    (9.0, 0.0, 0.0, 0.0),                          # back to the middle, flat
)
"""The pressed legs of :func:`probe_sweep`, after the approach (1 s) and before the lift."""


def probe_sweep(project: Projection, *, start=(0.0, 0.0, 0.0), tilt: float = np.radians(20.0),
                depth: float = 0.04, slide: float = 0.02, clearance: float = 0.005,
                workspace: Workspace = Workspace()) -> WaypointScript:
    """Script a probe pressed on the surface below ``start``: rolled, slid and yawed, ~10 s.

    The hand aims ``depth`` below the surface (m, along -z: its spring, not the depth reached,
    sets the press), rolls the face by +-``tilt`` (rad) in place, slides ``slide`` (m) along x
    each way and yaws +-``tilt`` while sliding; every position is projected on the surface
    straight below it, so the sweep follows a curved one. Lifts to ``clearance`` above at 9.8 s.
    """
    start = np.asarray(start, dtype=np.float64)

    def below(x: float) -> float:
        point, normal = project(start + (x, 0.0, 0.0))
        point, normal = np.asarray(point, dtype=float), np.asarray(normal, dtype=float)
        if not (np.all(np.isfinite(point)) and normal[2] > 0.5):
            raise ScriptError(f'probe sweep: no upward surface below {start + (x, 0, 0)}: '
                              f'project gave {point.tolist()}, normal {normal.tolist()}')
        return float(point[2])

    above = below(0.0) + clearance
    rows = [(0.0, *start, 0.0, 0.0), (1.0, start[0], start[1], above, 0.0, 0.0)]
    for t, x, roll, yaw in PROBE_SWEEP:
        rows.append((t, start[0] + x * slide, start[1], below(x * slide) - depth, roll * tilt,
                     yaw * tilt))
    rows.append((9.8, start[0], start[1], above, 0.0, 0.0))
    return WaypointScript.from_rows(rows, workspace=workspace)
