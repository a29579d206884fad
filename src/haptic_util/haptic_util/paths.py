"""Resolve file parameters, including ``package://<pkg>/<path>`` URIs as in URDF.

A scene shipped with a package is then found on any install, whether built by colcon or by this
repository's own set-up, as long as the package's prefix is on ``AMENT_PREFIX_PATH``.
"""
import os
import pathlib

from ament_index_python.packages import get_package_share_directory, PackageNotFoundError

from haptic_util.executor import StartupError

__all__ = ['resolve_path']

PACKAGE_SCHEME = 'package://'


def resolve_path(value: str, *, what: str) -> pathlib.Path:
    """Return an existing file for a plain path or a ``package://`` URI; ``what`` names it."""
    if not value:
        raise StartupError(f'{what} is empty: give a path or package://<pkg>/<path>')
    if value.startswith(PACKAGE_SCHEME):
        package, _, relative = value[len(PACKAGE_SCHEME):].partition('/')
        try:
            path = pathlib.Path(get_package_share_directory(package)) / relative
        except (PackageNotFoundError, ValueError, OSError):
            raise StartupError(
                f'{what} {value!r}: package {package!r} is not installed '
                f'(AMENT_PREFIX_PATH={os.environ.get("AMENT_PREFIX_PATH", "")!r})') from None
    else:
        path = pathlib.Path(value).expanduser()
    if not path.is_file():
        raise StartupError(f'{what} {value!r}: no such file ({path})')
    return path
