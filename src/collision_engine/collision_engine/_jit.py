"""The one numba decorator every compiled kernel of the engine uses.

One place sets the compile options, so no kernel can drift: ``cache=True`` so that a second
process loads machine code from ``__pycache__`` instead of compiling (seconds saved), and no
``fastmath``: it lets LLVM assume there are no infinities, and the searches here start from
``best = inf``. ``error_model='numpy'`` makes a division by zero give inf/NaN (which the kernels
test for) instead of raising from compiled code.

numba keys a cached kernel on its own file only, yet an entry point's cached machine code
includes the kernels it calls from other modules: after an edit to ``gjk.py`` the cached
``_kernels`` code would silently be the old algorithm. So the package's cache files are dropped
whenever any kernel module changes.
"""

import hashlib
from pathlib import Path

from numba import njit

__all__ = ['jit']

_PACKAGE = Path(__file__).resolve().parent
_KERNEL_MODULES = ('_jit.py', 'norms.py', 'support.py', 'signed_volumes.py', 'gjk.py', 'epa.py',
                   'bvh.py', '_kernels.py', 'self_intersection.py', 'winding.py')
_FINGERPRINT = _PACKAGE / '__pycache__' / 'kernels.sha256'


def _drop_stale_cache() -> None:
    """Delete numba's cache files of this package if a kernel module changed since."""
    digest = hashlib.sha256()
    for name in _KERNEL_MODULES:
        digest.update((_PACKAGE / name).read_bytes())
    fingerprint = digest.hexdigest()
    try:
        if _FINGERPRINT.is_file() and _FINGERPRINT.read_text() == fingerprint:
            return
        for stale in (*_FINGERPRINT.parent.glob('*.nbi'), *_FINGERPRINT.parent.glob('*.nbc')):
            stale.unlink(missing_ok=True)
        _FINGERPRINT.parent.mkdir(exist_ok=True)
        _FINGERPRINT.write_text(fingerprint)
    except OSError:
        pass  # a read-only install: its sources do not change, nor does its cache


_drop_stale_cache()


def jit(function):
    """Compile ``function`` with the engine's numba options (see the module docstring)."""
    return njit(cache=True, error_model='numpy', nogil=True)(function)
