"""A timed table of wand poses, and its CSV form (shared by replay and waypoint scripts).

CSV layout: a header row, then one row per pose. Columns ``t, x, y, z`` (s, m) are required; the
orientation is either ``roll, yaw`` (rad), or ``qx, qy, qz, qw`` (a quaternion without pitch), or
absent (zero). Other columns are ignored, so a recording may carry more.
"""

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from haptic_contract.wand import roll_yaw_from_quaternion

__all__ = ['PoseFileError', 'PoseTable', 'read_pose_csv', 'write_pose_csv']

_POSITION_COLUMNS = ('t', 'x', 'y', 'z')
_ANGLE_COLUMNS = ('roll', 'yaw')
_QUATERNION_COLUMNS = ('qx', 'qy', 'qz', 'qw')


class PoseFileError(ValueError):
    """A pose file is missing, unreadable or malformed; the message names the file and row."""


@dataclass(frozen=True, eq=False)
class PoseTable:
    """Poses at strictly increasing times.

    Parameters
    ----------
    times : (n,) float, s
        Strictly increasing, n >= 1.
    coordinates : (n, 5) float
        x, y, z [m], roll, yaw [rad] per time.
    """

    times: np.ndarray
    coordinates: np.ndarray

    def __post_init__(self):
        times = np.array(self.times, dtype=np.float64)
        coordinates = np.array(self.coordinates, dtype=np.float64)
        if times.ndim != 1 or times.size == 0 or coordinates.shape != (times.size, 5):
            raise ValueError(f'a pose table needs times (n,) and coordinates (n, 5), n >= 1; got '
                             f'{times.shape} and {coordinates.shape}')
        not_finite = ~(np.isfinite(times) & np.all(np.isfinite(coordinates), axis=1))
        if np.any(not_finite):
            raise ValueError(f'pose {int(np.flatnonzero(not_finite)[0])} (counting from 0): '
                             f'time and coordinates must be finite')
        steps = np.diff(times)
        if np.any(steps <= 0.0):
            row = int(np.flatnonzero(steps <= 0.0)[0]) + 1
            raise ValueError(f'pose {row} (counting from 0): time {times[row]!r} s does not '
                             f'increase on the previous {times[row - 1]!r} s')
        times.flags.writeable = False
        coordinates.flags.writeable = False
        object.__setattr__(self, 'times', times)
        object.__setattr__(self, 'coordinates', coordinates)


def _orientation_columns(header: list[str], path: Path) -> tuple[str, ...]:
    """Return the orientation columns this header has: roll, yaw; the quaternion; or none."""
    for names, other in ((_ANGLE_COLUMNS, _QUATERNION_COLUMNS),
                         (_QUATERNION_COLUMNS, _ANGLE_COLUMNS)):
        present = [name in header for name in names]
        if any(present) and not all(present):
            raise PoseFileError(f'{path}: header has {", ".join(n for n in names if n in header)} '
                                f'but not all of {", ".join(names)}')
        if all(present) and any(name in header for name in other):
            raise PoseFileError(f'{path}: give the orientation as roll, yaw or as qx, qy, qz, '
                                f'qw, not both')
        if all(present):
            return names
    return ()


def _roll_yaw(orientation: list[float]) -> tuple[float, float]:
    """Return (roll, yaw) from the orientation column values (two angles, a quaternion, none)."""
    if len(orientation) == 4:
        return roll_yaw_from_quaternion(orientation)
    return tuple(orientation) or (0.0, 0.0)


def read_pose_csv(path: str | Path) -> PoseTable:
    """Read a pose table from CSV (see the module docstring for the columns).

    Raises
    ------
    PoseFileError
        Naming the file, and the line and column where it applies.
    """
    path = Path(path)
    try:
        with path.open(newline='') as stream:
            rows = list(csv.reader(stream))
    except OSError as error:
        raise PoseFileError(f'{path}: cannot read pose CSV: {error.strerror or error}') from None
    except (UnicodeDecodeError, csv.Error) as error:
        raise PoseFileError(f'{path}: not a text CSV file: {error}') from None
    if not rows:
        raise PoseFileError(f'{path}: empty file; expected a header with t, x, y, z')
    header = [name.strip() for name in rows[0]]
    missing = [name for name in _POSITION_COLUMNS if name not in header]
    if missing:
        raise PoseFileError(f'{path}: header {header} lacks column(s) {", ".join(missing)}')
    columns = [header.index(name)
               for name in (*_POSITION_COLUMNS, *_orientation_columns(header, path))]
    times, coordinates = [], []
    for line, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise PoseFileError(f'{path}, line {line}: {len(row)} fields, header has '
                                f'{len(header)}')
        try:
            values = [float(row[column]) for column in columns]
            roll, yaw = _roll_yaw(values[4:])
        except ValueError as error:
            raise PoseFileError(f'{path}, line {line}: {error}') from None
        times.append(values[0])
        coordinates.append((*values[1:4], roll, yaw))
    if not times:
        raise PoseFileError(f'{path}: header but no poses')
    try:
        return PoseTable(np.array(times), np.array(coordinates))
    except ValueError as error:
        raise PoseFileError(f'{path}: {error}') from None


def write_pose_csv(path: str | Path, table: PoseTable) -> None:
    """Write ``table`` as CSV with columns t, x, y, z, roll, yaw, at full float precision."""
    with Path(path).open('w', newline='') as stream:
        writer = csv.writer(stream)
        writer.writerow([*_POSITION_COLUMNS, *_ANGLE_COLUMNS])
        for t, row in zip(table.times, table.coordinates):
            writer.writerow([repr(float(value)) for value in (t, *row)])
