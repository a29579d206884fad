"""What a scene query returns: one ``QueryResult`` per point, or a ``BatchResult`` of arrays.

Sign rule, once for the package: the distance is positive outside, zero on the surface and
negative inside; the normal is the unit outward surface normal at the closest point. Every
vector is in the scene's frame, in metres. The wand tip is a sphere of the scene's
``tip_radius`` (0: a point): ``distance`` is that of the sphere's surface, while ``point`` stays
the closest point on the object's surface to the tip centre.
"""

from dataclasses import dataclass

import numpy as np

__all__ = ['QueryResult', 'BatchResult', 'ToolResult']


class _PackedRow:
    """The fields a point query and a tool query share, read from one packed output row.

    Built from one row (see ``_kernels``); the vectors are made on first access, so that a
    haptic loop reading a few fields pays only for those.
    """

    __slots__ = ('_row', '_names')

    def __init__(self, row: list, names: tuple) -> None:
        self._row = row
        self._names = names

    @property
    def row(self) -> list:
        """Return the packed output (``_kernels.OUT_SIZE`` floats), to copy many fields at once.

        distance, point (3), normal (3), object index, iterations, status, tip or tool witness
        (3), triangle, lower bound; a node writing a message takes its vectors from here without
        numpy.
        """
        return self._row

    @property
    def distance(self) -> float:
        """Signed distance to the nearest object, m (``inf`` when none)."""
        return self._row[0]

    @property
    def point(self) -> np.ndarray:
        """(3,) closest (witness) point on that object's surface, m."""
        return np.array(self._row[1:4])

    @property
    def normal(self) -> np.ndarray:
        """(3,) unit outward surface normal at ``point``."""
        return np.array(self._row[4:7])

    @property
    def object_index(self) -> int:
        """Index of the nearest object in ``Scene.objects`` (-1 for none)."""
        return int(self._row[7])

    @property
    def object(self) -> str | None:
        """Name of the nearest object, as in the scene file (None for none)."""
        index = int(self._row[7])
        return self._names[index] if index >= 0 else None

    @property
    def iterations(self) -> int:
        """GJK and EPA iterations spent (for a mesh: triangles tested, each in closed form)."""
        return int(self._row[8])

    @property
    def status(self) -> int:
        """0 OK, 1 NOT_CONVERGED (distance is the best upper bound), 2 NO_OBJECT."""
        return int(self._row[9])

    @property
    def triangle(self) -> int:
        """The mesh triangle ``point`` lies on (-1 for other shapes)."""
        return int(self._row[13])

    @property
    def lower_bound(self) -> float:
        """Lower bound on the distance from GJK, m (see ``DistanceResult.lower_bound``)."""
        return self._row[14]

    @property
    def in_collision(self) -> bool:
        """``distance <= 0``."""
        return self._row[0] <= 0.0


class QueryResult(_PackedRow):
    """The nearest object to one tip position (see ``_PackedRow`` for the shared fields).

    Attributes
    ----------
    cross_validated : bool
        True when this query was handed to the FCL cross-check. The check runs afterwards, on
        its own thread: its verdict goes to ``Scene.cross_validation_stats``, not here.
    """

    __slots__ = ('cross_validated',)

    def __init__(self, row: list, names: tuple, cross_validated: bool = False) -> None:
        super().__init__(row, names)
        self.cross_validated = cross_validated

    @property
    def tip(self) -> np.ndarray:
        """(3,) the tip position queried, m."""
        return np.array(self._row[10:13])

    @property
    def penetration(self) -> np.ndarray:
        """(3,) depth times the outward normal when in collision, else zero, m.

        The depth is ``-distance``: for a sphere tip, r minus the centre's distance.
        """
        if self._row[0] <= 0.0:
            return -self._row[0] * np.array(self._row[4:7])
        return np.zeros(3)

    def __repr__(self) -> str:
        return (f'QueryResult(object={self.object!r}, distance={self.distance!r}, '
                f'point={self._row[1:4]}, normal={self._row[4:7]}, status={self.status})')


@dataclass(frozen=True, eq=False)
class BatchResult:
    """The nearest object to each of n tip positions, as arrays (see ``QueryResult``).

    Attributes
    ----------
    distance : (n,) float64, m
    point : (n, 3) float64, m
    normal : (n, 3) float64
    object_index : (n,) int64, -1 for none
    iterations : (n,) int64
    status : (n,) int64
    triangle : (n,) int64
    lower_bound : (n,) float64, m
    names : tuple of str
        The scene's object names, indexed by ``object_index``.
    """

    distance: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    object_index: np.ndarray
    iterations: np.ndarray
    status: np.ndarray
    triangle: np.ndarray
    lower_bound: np.ndarray
    names: tuple

    @classmethod
    def from_rows(cls, rows: np.ndarray, names: tuple) -> 'BatchResult':
        """Split packed output rows (n, OUT_SIZE) into named arrays."""
        return cls(
            distance=rows[:, 0].copy(), point=rows[:, 1:4].copy(), normal=rows[:, 4:7].copy(),
            object_index=rows[:, 7].astype(np.int64), iterations=rows[:, 8].astype(np.int64),
            status=rows[:, 9].astype(np.int64), triangle=rows[:, 13].astype(np.int64),
            lower_bound=rows[:, 14].copy(), names=names)

    @property
    def object(self) -> list:
        """Nearest object's name per point (None for none)."""
        return [self.names[i] if i >= 0 else None for i in self.object_index]

    @property
    def in_collision(self) -> np.ndarray:
        """(n,) bool: ``distance <= 0``."""
        return self.distance <= 0.0


class ToolResult(_PackedRow):
    """The nearest object to a convex tool (``Scene.query_tool``), from one packed output row.

    The distance is positive apart and minus the penetration depth in overlap (against a
    non-convex mesh: the depth of the tool's deepest shell point, ``tool_mesh``); the normal is
    outward from the object, and ``tool_point - point = distance * normal``. Scene frame, m.
    The row's tip slot holds the tool's witness; ``iterations`` counts GJK and EPA iterations
    and the triangles the shell's point queries tested.
    """

    __slots__ = ()

    @property
    def tool_point(self) -> np.ndarray:
        """(3,) the witness point of the tool (its deepest point in overlap), m."""
        return np.array(self._row[10:13])

    @property
    def witness_points(self) -> np.ndarray:
        """(2, 3) ``point`` and ``tool_point``, m."""
        return np.array([self._row[1:4], self._row[10:13]])

    def __repr__(self) -> str:
        return (f'ToolResult(object={self.object!r}, distance={self.distance!r}, '
                f'point={self._row[1:4]}, tool_point={self._row[10:13]}, '
                f'normal={self._row[4:7]}, status={self.status})')
