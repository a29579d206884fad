"""Which scanlines are coupled to the skin, from the probe's contact face.

A real probe lifted into air shows nothing: sound does not cross the air gap. The collision
engine measures the probe's contact face point by point (``collision_engine.probe``: a grid of
points on the face, each one's signed distance to the skin), and the force comes from that
contact; the image comes from the same one. Each element's distance is taken along the array
from the face's columns (the nearest surface over a column across the array, linear between
columns, extended linearly past the outer ones), and its scanline is coupled when that is at
most the gel's film, ``settings.coupling_gap``. Exact for a flat skin under a tilted face.
"""

import numpy as np

from ultrasound_sim.geometry import scan_geometry
from ultrasound_sim.settings import ProbeSettings

__all__ = ['scanline_coupling']

_SAME_COLUMN = 1e-9  # m: face points this close along the array share a column


def scanline_coupling(face_points, face_distance, settings: ProbeSettings) -> np.ndarray:
    """Return which scanlines are coupled to the skin.

    Parameters
    ----------
    face_points : (n, 3) float, m, probe frame
        The contact face's points (``MountedTool.face`` when the probe frame is the tip's).
    face_distance : (n,) float, m
        Each point's signed distance to the skin (``ProbeResult.distance``): negative pressed
        in, positive lifted off. A NaN counts as lifted off.
    settings : ProbeSettings

    Returns
    -------
    (scanlines,) bool

    Raises
    ------
    ValueError
        If the shapes do not match or the points are not finite.
    """
    points = np.asarray(face_points, dtype=np.float64)
    distance = np.asarray(face_distance, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) == 0 \
            or distance.shape != (len(points),):
        raise ValueError(f'face_points must be (n, 3) and face_distance (n,), got '
                         f'{points.shape} and {distance.shape}')
    if not np.all(np.isfinite(points)):
        raise ValueError('face_points: must be finite')
    distance = np.where(np.isnan(distance), np.inf, distance)
    columns, column_of = np.unique(np.round(points[:, 1] / _SAME_COLUMN), return_inverse=True)
    nearest = np.full(len(columns), np.inf)
    np.minimum.at(nearest, column_of.ravel(), distance)
    along = columns * _SAME_COLUMN
    elements = scan_geometry(settings).origins[:, 0]
    if len(along) == 1:
        return np.full(len(elements), nearest[0] <= settings.coupling_gap)
    at = np.interp(elements, along, nearest)
    for end, (a, b) in ((elements < along[0], (0, 1)), (elements > along[-1], (-2, -1))):
        with np.errstate(invalid='ignore'):  # inf - inf: a lifted end stays lifted
            slope = (nearest[b] - nearest[a]) / (along[b] - along[a])
            at[end] = nearest[a] + slope * (elements[end] - along[a])
        at[end & ~np.isfinite(at)] = np.inf
    return at <= settings.coupling_gap
