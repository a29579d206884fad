"""Dot and cross products of 3-tuples, compiled: the kernels' shared vector arithmetic."""

from collision_engine._jit import jit

__all__ = ['cross3', 'dot3']


@jit
def dot3(u, v):
    """Return u · v."""
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


@jit
def cross3(u, v):
    """Return u × v."""
    return u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]
