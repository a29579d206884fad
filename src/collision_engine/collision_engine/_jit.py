"""Where the engine's compiled kernels are cached; they compile through the project's ``jit``.

The decorator and its options are ``haptic_util.jit``'s, the project's one. The cache: numba
keys a cached kernel on its own file, yet an entry point's machine code includes the kernels it
calls from other modules: after an edit to ``gjk.py`` the cached ``_kernels`` code would
silently be the old algorithm. And it caches beside the source, so every install (a ``colcon
build``, a venv) compiles again, and three nodes started together compiled three times over
(about 60 s on two cores). So the kernels are cached under a fingerprint of every kernel
module's content, in a per-user folder (``$NUMBA_CACHE_DIR`` or ``~/.cache``; the package's
``__pycache__`` when that is not writable): a changed kernel module means another folder
(nothing is deleted, so nothing races), and every install of the same code shares one cache.
``compiling`` lets one process compile while the others wait for its cache, and says so in one
line.

Another package's kernels compiled through ``jit`` (the ultrasound image's, the driver's servo
loop) live in one module that calls only its own, so numba's stamp of that file is enough
(``haptic_util.jit``).
"""

import contextlib
import fcntl
import functools
import hashlib
from pathlib import Path
from typing import Callable, Iterator

from numba.core import caching

from haptic_util.jit import jit, USER_CACHE, writable

__all__ = ['jit', 'compiling', 'CACHE_DIR']

_PACKAGE = Path(__file__).resolve().parent
_USES_JIT = 'from collision_engine._jit import jit'


@functools.lru_cache(maxsize=None)
def _kernel_modules() -> tuple:
    """Return the package's modules that compile kernels (they import ``jit``), and this one."""
    return tuple(sorted(path for path in _PACKAGE.glob('*.py')
                        if path.name == '_jit.py' or _USES_JIT in path.read_text()))


def _fingerprint() -> str:
    digest = hashlib.sha256()
    for path in _kernel_modules():
        digest.update(path.name.encode() + b'\0' + path.read_bytes())
    return digest.hexdigest()[:16]


def _cache_dir() -> Path:
    """Return the per-user cache of this fingerprint, or the package's own if not writable."""
    fingerprint = _fingerprint()
    candidates = (USER_CACHE / 'collision_engine' / fingerprint,
                  _PACKAGE / '__pycache__' / fingerprint)
    return next((folder for folder in candidates if writable(folder)), candidates[0])


CACHE_DIR = _cache_dir()


class _FingerprintLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """numba's cache locator for this package's kernels: under ``CACHE_DIR``, stamped with it."""

    def __init__(self, py_func, py_file) -> None:
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno

    def get_cache_path(self) -> str:
        return str(CACHE_DIR)

    def get_source_stamp(self) -> str:
        return CACHE_DIR.name

    @classmethod
    def from_function(cls, py_func, py_file):
        if Path(py_file).resolve().parent != _PACKAGE:
            return None  # another library's function: numba's own locators
        return super().from_function(py_func, py_file)


if _FingerprintLocator not in caching.CacheImpl._locator_classes:  # before jit's own
    caching.CacheImpl._locator_classes.insert(0, _FingerprintLocator)


@contextlib.contextmanager
def compiling(announce: Callable[[str], None]) -> Iterator[None]:
    """Hold the cache's lock while the caller warms the kernels up.

    The first process to come compiles, and ``announce`` says so first; the others wait for it
    and then load its machine code. A cache that cannot be written is compiled in every process.
    """
    try:
        CACHE_DIR.mkdir(parents=True, exist_ok=True)
        lock = open(CACHE_DIR / 'compile.lock', 'w')
    except OSError:
        announce(f'compiling the collision kernels (no writable cache at {CACHE_DIR})')
        yield
        return
    with lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        done = CACHE_DIR / 'complete'
        if not done.exists():
            announce('compiling the collision kernels for this code and machine, once (about '
                     f'20 s; later starts load them from {CACHE_DIR})')
        yield
        done.touch()
