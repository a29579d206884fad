"""What the report measures on one experiment: errors, false values, contacts, force directions.

Ours is what the engine published (from the bag); the paper's is its code replayed on the same
path; both are judged against the exact truth at the same tip positions.
"""

from dataclasses import dataclass
import math

import numpy as np
from report_generator.report_paper_replay import PaperReplay
from report_generator.report_recordings import CONTACT_SAMPLES, Recording
from report_generator.report_truth import Truth

from haptic_bringup.contacts import FELT_FORCE, MIN_FORCE

__all__ = ['FALSE_ERROR', 'FELT_FORCE', 'MAX_ANGLE', 'Measures', 'STRONG_FORCE', 'SIGN_FLOOR',
           'angle_stats', 'angles_to_normal', 'error_summary', 'false_events', 'false_samples',
           'measure', 'runs']

FALSE_ERROR = 1e-3  # [m] an answer farther than this from the truth is a false value
STRONG_FORCE = 0.05  # [N] every applied force this strong must point within MAX_ANGLE
MAX_ANGLE = 5.0  # [deg] of the exact outward normal
SIGN_FLOOR = 1e-9  # [m] nearer the surface than this, the sign is not judged


def runs(mask, min_samples: int = 1) -> list[tuple[int, int]]:
    """Index ranges [start, stop) of the runs of True in ``mask`` at least ``min_samples`` long."""
    flags = np.concatenate(([0], np.asarray(mask, dtype=np.int8), [0]))
    edges = np.flatnonzero(np.diff(flags))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2]) if b - a >= min_samples]


def false_samples(answer, truth, *, threshold: float = FALSE_ERROR,
                  sign_floor: float = SIGN_FLOOR) -> np.ndarray:
    """(n,) bool: no answer (NaN), ``|answer - truth| > threshold``, or the wrong sign.

    The sign is judged only where the truth is farther than ``sign_floor`` from the surface.
    """
    answer, truth = np.asarray(answer, dtype=float), np.asarray(truth, dtype=float)
    with np.errstate(invalid='ignore'):
        wrong_sign = (np.abs(truth) > sign_floor) & (np.sign(answer) != np.sign(truth))
        return ~np.isfinite(answer) | (np.abs(answer - truth) > threshold) | wrong_sign


def false_events(answer, truth, **options) -> tuple[int, int]:
    """Count false values as events (runs of consecutive false samples), and as samples."""
    false = false_samples(answer, truth, **options)
    return len(runs(false)), int(np.count_nonzero(false))


def error_summary(answer, truth) -> dict:
    """Mean and largest ``|answer - truth|`` over the answered samples, m; and the unanswered."""
    error = np.abs(np.asarray(answer, dtype=float) - np.asarray(truth, dtype=float))
    answered = np.isfinite(error)
    if not answered.any():
        return {'mean': math.nan, 'max': math.nan, 'unanswered': int(error.size)}
    return {'mean': float(error[answered].mean()), 'max': float(error[answered].max()),
            'unanswered': int(np.count_nonzero(~answered))}


def angles_to_normal(force, normal, *, min_force: float = MIN_FORCE) -> np.ndarray:
    """(n,) degrees between each force and unit normal; NaN where the force is below min_force."""
    force, normal = np.asarray(force, dtype=float), np.asarray(normal, dtype=float)
    magnitude = np.linalg.norm(force, axis=-1)
    with np.errstate(invalid='ignore', divide='ignore'):
        cosine = np.einsum('...i,...i->...', force, normal) / magnitude
    angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    return np.where(magnitude > min_force, angle, np.nan)


def angle_stats(angles: np.ndarray) -> tuple[float, float]:
    """Mean and largest of the angles that are not NaN; NaN, NaN when there are none."""
    kept = angles[np.isfinite(angles)]
    return (float(kept.mean()), float(kept.max())) if kept.size else (math.nan, math.nan)


@dataclass(frozen=True, eq=False)
class Measures:
    """Everything the report says about one experiment, computed from its arrays."""

    ours: dict
    paper: dict
    ours_events: tuple
    paper_events: tuple
    ours_angles: np.ndarray
    paper_angles: np.ndarray
    ours_all_angles: np.ndarray
    paper_all_angles: np.ndarray
    strong_angles: np.ndarray
    paper_missed: int
    paper_false_flags: int
    truth_contacts: int
    paper_contacts: int
    outcomes: dict


def measure(recording: Recording, truth: Truth, replay: PaperReplay) -> Measures:
    """Errors, false values, contacts and force directions of ours and of the paper's code."""
    session = recording.session
    inside = truth.distance < 0.0

    def in_contact(force, min_force):
        return np.where(inside, angles_to_normal(force, truth.normal, min_force=min_force),
                        np.nan)

    outcomes = {k: int(np.count_nonzero(replay.outcome == k))
                for k in ('converged', 'cap', 'hang')}
    return Measures(
        ours=error_summary(session.distance, truth.distance),
        paper=error_summary(replay.signed, truth.distance),
        ours_events=false_events(session.distance, truth.distance),
        paper_events=false_events(replay.signed, truth.distance),
        ours_angles=in_contact(session.applied, FELT_FORCE),
        paper_angles=in_contact(replay.force, FELT_FORCE),
        ours_all_angles=in_contact(session.applied, MIN_FORCE),
        paper_all_angles=in_contact(replay.force, MIN_FORCE),
        strong_angles=angles_to_normal(session.applied, truth.normal, min_force=STRONG_FORCE),
        paper_missed=int(np.count_nonzero(inside & ~replay.flag)),
        paper_false_flags=int(np.count_nonzero(~inside & replay.flag)),
        truth_contacts=len(runs(inside, CONTACT_SAMPLES)),
        paper_contacts=len(runs(replay.flag, CONTACT_SAMPLES)),
        outcomes=outcomes)
