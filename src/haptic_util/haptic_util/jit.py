"""The project's one numba decorator: its compile options, and where kernels are cached.

One place sets the compile options, so no kernel can drift: ``cache=True`` so that a second
process loads machine code instead of compiling (seconds saved), and no ``fastmath``: it lets
LLVM assume there are no infinities, and the searches start from ``best = inf``.
``error_model='numpy'`` makes a division by zero give inf/NaN (which the kernels test for)
instead of raising from compiled code.

numba caches beside the source, so every install (a ``colcon build``, a venv) would compile
again, and a build must leave the sources as it found it. So a kernel compiled through ``jit``
is cached in a per-user folder (``$NUMBA_CACHE_DIR`` or ``~/.cache``, by install), stamped with
its source file as numba's own cache is: a module of kernels that call only their own needs no
more (``collision_engine._jit`` adds a fingerprint of all its modules for the engine's, which
call one another). Only numba is imported here, so a package's core can compile a kernel
without loading another package.
"""

import os
from pathlib import Path
import tempfile

from numba import njit
from numba.core import caching

__all__ = ['USER_CACHE', 'jit', 'writable']

USER_CACHE = Path(os.environ.get('NUMBA_CACHE_DIR') or Path(
    os.environ.get('XDG_CACHE_HOME') or Path.home() / '.cache')) / 'haptic_toolkit'


def writable(folder: Path) -> bool:
    """Whether ``folder`` exists or can be made, and a file can be written in it."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
        return True
    except OSError:
        return False


class _UserCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """numba's cache locator for the kernels compiled through ``jit``.

    Under the per-user folder, by package and where it is installed (numba's own subpath: the
    folder's name and a hash of its path), so that two checkouts of different code never
    overwrite each other's kernels; stamped with the source file, as numba's own.
    """

    def __init__(self, py_func, py_file) -> None:
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._folder = USER_CACHE / self.get_suitable_cache_subpath(py_file)

    def get_cache_path(self) -> str:
        return str(self._folder)

    @classmethod
    def from_function(cls, py_func, py_file):
        if Path(py_file).resolve() not in _KERNEL_FILES:
            return None
        locator = cls(py_func, py_file)
        return locator if writable(locator._folder) else None


_KERNEL_FILES: set = set()  # the modules with kernels compiled through jit
if _UserCacheLocator not in caching.CacheImpl._locator_classes:
    caching.CacheImpl._locator_classes.insert(0, _UserCacheLocator)


def jit(function):
    """Compile ``function`` with the project's numba options (see the module docstring)."""
    _KERNEL_FILES.add(Path(function.__code__.co_filename).resolve())
    return njit(cache=True, error_model='numpy', nogil=True)(function)
