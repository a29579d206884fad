"""The collision engine's exceptions, in one module.

Both subclass `ValueError`, so a caller that catches bad input generically still catches them.
Their messages always name the file and the key, field or defect.
"""

__all__ = ['MeshError', 'SceneError']


class SceneError(ValueError):
    """A scene file that cannot be read, or a key or value in it that is wrong."""


class MeshError(ValueError):
    """A mesh file that cannot be read, or whose geometry cannot be trusted for signed distance."""
