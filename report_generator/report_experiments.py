"""The paper's three experiments: the scenes the demo ran, and what the paper reported for each.

The paper's numbers are reference data typed in from it (*A toolkit for haptic force feedback in
a telerobotic ultrasound system*); the report prints them beside ours, labelled "paper".
"""

from dataclasses import dataclass
from pathlib import Path

from ground_truth import distances

__all__ = ['EXPERIMENTS', 'Experiment', 'PAPER', 'PAPER_TABLE_3', 'PaperReported']


@dataclass(frozen=True)
class PaperReported:
    """What the paper reports for one experiment: reference data, typed in from the paper.

    Lengths m, forces N; ``intervals`` are (start s, end s, Fx, Fy, Fz) rows of its table.
    """

    figure: int
    vertices: int
    mean_error: float
    error_source: str
    false_values: int
    collisions: int
    mean_force: tuple
    intervals: tuple = ()
    table: str = ''


PAPER = {
    'hand': PaperReported(
        figure=1, vertices=3660, mean_error=2.1e-2, error_source='abstract', false_values=0,
        collisions=11, mean_force=(0.998, 0.996, 0.345), table='Table 1', intervals=(
            (0.2, 0.45, 2.434, 1.542, 0.8417), (1.0, 1.3, 1.799, 1.407, 0.1984),
            (1.8, 2.1, 2.204, 1.647, 0.5779), (2.65, 3.05, 1.191, 2.791, -1.133),
            (3.88, 4.25, -0.2231, 0.2434, 0.2146), (4.6, 4.95, 0.003, 0.1909, 0.7829),
            (5.5, 5.9, 0.3367, 0.2689, 0.2665), (6.3, 6.65, 0.4804, 0.3912, 0.2679),
            (6.9, 7.3, 0.7628, 0.6750, 0.4729), (7.65, 8.1, 0.8455, 0.8792, 0.5574),
            (8.35, 8.7, 1.154, 0.9189, 0.7470))),
    'cylinder': PaperReported(
        figure=2, vertices=456, mean_error=3.44e-2, error_source='Table 2', false_values=6,
        collisions=9, mean_force=(0.3561, 1.711, 0.6248)),
    'cuboid': PaperReported(
        figure=3, vertices=36, mean_error=4.176e-2, error_source='Table 2', false_values=1,
        collisions=18, mean_force=(1.62, 0.477, 0.217), table='Table 4', intervals=(
            (0.50, 1.10, -2.1, 0.3, 0.3), (1.80, 2.40, -2.9, 1.1, 0.9),
            (3.10, 3.70, -1.8, 0.9, -0.3), (4.25, 4.75, -1.9, 0.5, 0.5),
            (5.40, 5.75, -0.5, 0.1, 0.2), (6.45, 6.80, -1.1, 0.2, 0.1),
            (7.40, 7.80, -0.8, 0.3, 0.2), (8.40, 8.75, -0.3, 0.1, 0.05),
            (9.25, 9.60, -1.4, 0.3, 0.43))),
}
PAPER_TABLE_3 = {'time': 8.436, 'velocity': (0.2055, 0.0087, 0.0069),
                 'distance_vector': (-9.685e-4, 1.967e-4, 1.268e-4),
                 'force': (0.3194, 0.0245, 0.0148)}


@dataclass(frozen=True)
class Experiment:
    """One of the paper's experiments: the scene the demo ran, and the paper's STL placed so."""

    name: str
    scene: str
    paper_scene: str
    description: str

    @property
    def scene_file(self) -> Path:
        """The shipped scene file the demo ran (the exact object)."""
        return distances.scene_path(self.scene)

    @property
    def paper_scene_file(self) -> Path:
        """The shipped scene file with the paper's STL placed as the exact object."""
        return distances.scene_path(self.paper_scene)


EXPERIMENTS = {
    'hand': Experiment('hand', 'hand', 'hand', 'dorsum of a hand (non-convex mesh)'),
    'cylinder': Experiment('cylinder', 'cylinder', 'paper_cylinder_stl',
                           'curved side of a cylinder r 0.025 m, h 0.1 m'),
    'cuboid': Experiment('cuboid', 'cuboid', 'paper_cuboid_stl',
                         'end face of a 0.2 x 0.1 x 0.1 m cuboid'),
}
