"""Contact intervals of a session: when the tip was inside, how deep, what force, which way.

The paper's Tables 1 and 4 list, per contact interval, the mean force per axis; here each
interval also says how far the force pointed from the surface normal, which the paper's
centroid law got wrong by up to 45 degrees on a cube face. The force is what the device applied
(``wand/applied_wrench``), what the hand felt.
"""
import dataclasses

import numpy as np

__all__ = ['ContactInterval', 'FELT_FORCE', 'REBOUND_HEIGHT', 'contact_intervals', 'contacts',
           'format_contacts']

MIN_FORCE = 1e-6  # [N] below this a force has no direction worth measuring
FELT_FORCE = 0.01  # [N] weaker forces (the damper's residue as a contact ends) are not judged
# [m] a tip that leaves the surface by less before it re-enters is still in the same contact:
# a felt rebound lifts by millimetres, a tip settling on a stiff wall by microns.
REBOUND_HEIGHT = 1e-4


@dataclasses.dataclass(frozen=True, eq=False)
class ContactInterval:
    """One stretch of consecutive samples with the tip inside an object."""

    start: float  # [s]
    end: float  # [s]
    object: str
    samples: int
    max_depth: float  # [m]
    mean_force: np.ndarray  # (3,) N
    peak_force: float  # [N]
    normal_angle: float  # [deg] mean angle of the forces >= FELT_FORCE to the outward normal

    @property
    def duration(self) -> float:
        return self.end - self.start


def contacts(distance: np.ndarray, *, min_samples: int = 3) -> list:
    """(first, stop) sample ranges of the contacts in a signed-distance series (m).

    A contact is a run of samples inside (distance < 0); two runs whose gap stays lower than
    ``REBOUND_HEIGHT`` above the surface are one contact; runs shorter than ``min_samples`` are
    grazes.
    """
    inside = np.asarray(distance) < 0.0
    edges = np.flatnonzero(np.diff(np.concatenate([[0], inside.astype(np.int8), [0]])))
    runs = []
    for first, stop in zip(edges[::2], edges[1::2]):
        if runs and np.max(distance[runs[-1][1]:first]) < REBOUND_HEIGHT:
            runs[-1] = (runs[-1][0], stop)
        else:
            runs.append((first, stop))
    return [(first, stop) for first, stop in runs if stop - first >= min_samples]


def contact_intervals(session, *, min_samples: int = 3) -> list:
    """List the contacts in time order (see ``contacts``)."""
    intervals = []
    for first, stop in contacts(session.distance, min_samples=min_samples):
        window = slice(first, stop)
        force = session.applied[window]
        answered = np.all(np.isfinite(force), axis=1)
        force, normal = force[answered], session.normal[window][answered]
        magnitude = np.linalg.norm(force, axis=1)
        felt = magnitude >= FELT_FORCE
        cosine = np.einsum('ij,ij->i', force[felt], normal[felt]) / magnitude[felt]
        angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
        intervals.append(ContactInterval(
            start=float(session.time[first]), end=float(session.time[stop - 1]),
            object=str(session.objects[first]), samples=int(stop - first),
            max_depth=float(-session.distance[window].min()),
            mean_force=force.mean(axis=0) if len(force) else np.full(3, np.nan),
            peak_force=float(magnitude.max()) if len(force) else float('nan'),
            normal_angle=float(angle.mean()) if len(angle) else float('nan')))
    return intervals


def format_contacts(intervals) -> str:
    """Format contact intervals as a plain-text table, one line each."""
    header = (f'{"#":>3} {"object":<10} {"start s":>8} {"end s":>7} {"depth mm":>9} '
              f'{"Fx N":>7} {"Fy N":>7} {"Fz N":>7} {"peak N":>7} {"∠normal °":>9}')
    lines = [header]
    for number, c in enumerate(intervals, 1):
        fx, fy, fz = c.mean_force
        lines.append(f'{number:>3} {c.object:<10} {c.start:8.3f} {c.end:7.3f} '
                     f'{1e3 * c.max_depth:9.3f} {fx:7.3f} {fy:7.3f} {fz:7.3f} '
                     f'{c.peak_force:7.3f} {c.normal_angle:9.3f}')
    return '\n'.join(lines)
