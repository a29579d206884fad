"""The paper's own collision code (``paper_method.py``) replayed along our recorded paths.

It runs on the paper's STL object placed as ours, on the same tip positions and recorded
twists, so its distance, flag and force can be set sample by sample beside ours.
"""

from dataclasses import dataclass

import numpy as np
from report_generator.paper_method import PaperMethod, stl_vertex_rows
from report_generator.report_experiments import Experiment

from collision_engine import read_scene

__all__ = ['PaperReplay', 'paper_rows', 'replay_paper']


@dataclass(frozen=True, eq=False)
class PaperReplay:
    """The paper's code on our trajectory, sample by sample.

    flag (n,) bool, unsigned and signed distance (n,) m, outcome per sample (n,) str, force
    (n, 3) N, and the STL rows (m, 3) m it used.
    """

    flag: np.ndarray
    distance: np.ndarray
    signed: np.ndarray
    outcome: np.ndarray
    force: np.ndarray
    rows: np.ndarray


def paper_rows(experiment: Experiment) -> tuple[np.ndarray, object]:
    """Read the paper's STL vertex rows for an experiment, placed as our object (world, m)."""
    spec = read_scene(experiment.paper_scene_file).objects[0]
    rows = stl_vertex_rows(spec.shape.file, scale=spec.shape.scale)
    return rows @ spec.pose.rotation.T + spec.pose.translation, spec.material


def replay_paper(experiment: Experiment, tips: np.ndarray, velocity: np.ndarray) -> PaperReplay:
    """Run the paper's flag, distance and force on every recorded tip position."""
    rows, material = paper_rows(experiment)
    method = PaperMethod(rows, stiffness=float(material.stiffness[0]), damping=material.damping)
    answers = [method.query(tip) for tip in tips]
    force = np.array([method.force_for(a, tip, v) for a, tip, v in zip(answers, tips, velocity)])
    return PaperReplay(np.array([a.in_collision for a in answers]),
                       np.array([a.distance.distance for a in answers]),
                       np.array([a.signed_distance for a in answers]),
                       np.array([a.distance.outcome for a in answers]), force, rows)
