"""Generalized winding number of a closed triangle mesh at a point, compiled.

Jacobson, Kavan and Sorkine-Hornung (2013): the sum of the solid angles the triangles subtend at
the point, over 4 pi: 1 inside a closed, outward-wound mesh, 0 outside, whatever the mesh's
convexity. Each solid angle by Van Oosterom and Strackee (1983):
tan(omega / 2) = det[a b c] / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|), a, b, c the corners
relative to the point. It shares nothing with the engine's own sign rule (pseudonormals of the
nearest feature), which is why the FCL cross-check uses it to check our signs. Compiled without
the GIL, so that the cross-check's thread never holds up a query's.
"""

import math

from collision_engine._jit import jit

__all__ = ['winding_number']


@jit
def winding_number(corners, px, py, pz):
    """Winding number at p of triangles ``corners`` (t, 3, 3), m, in p's frame."""
    total = 0.0
    for t in range(corners.shape[0]):
        ax, ay, az = corners[t, 0, 0] - px, corners[t, 0, 1] - py, corners[t, 0, 2] - pz
        bx, by, bz = corners[t, 1, 0] - px, corners[t, 1, 1] - py, corners[t, 1, 2] - pz
        cx, cy, cz = corners[t, 2, 0] - px, corners[t, 2, 1] - py, corners[t, 2, 2] - pz
        la = math.sqrt(ax * ax + ay * ay + az * az)
        lb = math.sqrt(bx * bx + by * by + bz * bz)
        lc = math.sqrt(cx * cx + cy * cy + cz * cz)
        volume = ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
        denominator = (la * lb * lc + (ax * bx + ay * by + az * bz) * lc
                       + (bx * cx + by * cy + bz * cz) * la + (cx * ax + cy * ay + cz * az) * lb)
        total += math.atan2(volume, denominator)
    return total / (2.0 * math.pi)
