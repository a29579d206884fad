"""Resolve file parameters, including ``package://<pkg>/<path>`` URIs as in URDF.

A scene shipped with a package is then found on any install, whether built by colcon or by this
repository's own set-up, as long as the package's prefix is on ``AMENT_PREFIX_PATH``.

A ``package://`` URI names a file inside its package's share folder, and nothing else: the path
after the package must be relative, ``..`` is resolved before the check, and so are symlinks,
so that neither ``package://pkg//etc/passwd``, ``package://pkg/../../etc/passwd`` nor a link
in the share folder pointing out of it reaches a file elsewhere. (An install whose share folder
holds links into a source tree, as ``colcon build --symlink-install`` makes, is refused by the
same rule: give such files by their plain path.)
"""
import os
import pathlib

from ament_index_python.packages import get_package_share_directory, PackageNotFoundError

__all__ = ['PACKAGE_SCHEME', 'package_file', 'resolve_path']

PACKAGE_SCHEME = 'package://'


def resolve_path(value: str, *, what: str) -> pathlib.Path:
    """Return an existing file for a plain path or a ``package://`` URI; ``what`` names it.

    Raises
    ------
    StartupError
        Naming ``what`` and the value: empty, no such file, an unknown package, or a
        ``package://`` URI that leaves its package's share folder.
    """
    from haptic_util.executor import StartupError  # rclpy: only nodes resolve this way

    if not value:
        raise StartupError(f'{what} is empty: give a path or package://<pkg>/<path>')
    if value.startswith(PACKAGE_SCHEME):
        try:
            path = package_file(value)
        except ValueError as error:
            raise StartupError(f'{what} {error}') from None
    else:
        path = pathlib.Path(value).expanduser()
    if not path.is_file():
        raise StartupError(f'{what} {value!r}: no such file ({path})')
    return path


def package_file(uri: str) -> pathlib.Path:
    """Map ``package://<pkg>/<relative>`` to its path inside the package's share folder.

    Imports nothing of ROS but ament_index_python, so that pure cores (a scene file's mesh) can
    take such URIs too. The file need not exist.

    Raises
    ------
    ValueError
        Naming the URI: an unknown package, or a path that is absolute, names no file, or leaves
        the share folder (by '..' or through a symbolic link).
    """
    package, _, relative = uri[len(PACKAGE_SCHEME):].partition('/')
    try:
        share = pathlib.Path(get_package_share_directory(package, print_warning=False))
    except (PackageNotFoundError, ValueError, OSError):
        raise ValueError(
            f'{uri!r}: package {package!r} is not installed '
            f'(AMENT_PREFIX_PATH={os.environ.get("AMENT_PREFIX_PATH", "")!r})') from None
    if pathlib.PurePosixPath(relative).is_absolute():
        raise ValueError(f'{uri!r}: the path after package://{package}/ must be relative to '
                         f'its share folder ({share}), not absolute')
    normalised = os.path.normpath(relative) if relative else '.'
    if normalised == '.' or normalised == '..' or normalised.startswith('../'):
        raise ValueError(f'{uri!r}: names no file inside the share folder of package '
                         f'{package!r} ({share})')
    path = share / normalised
    if not path.resolve().is_relative_to(share.resolve()):
        raise ValueError(f'{uri!r}: leaves the share folder of package {package!r} ({share}) '
                         f'through a symbolic link to {path.resolve()}')
    return path
