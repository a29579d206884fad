"""Where the kernels' machine code is cached, and how processes starting together share it."""
import os
import subprocess
import sys

from collision_engine import _jit, _kernels

HOLD = """
import sys, time
from collision_engine._jit import compiling
with compiling(lambda line: print('announced', flush=True)):
    print('compiling', time.time(), flush=True)
    time.sleep(float(sys.argv[1]))
    print('done', time.time(), flush=True)
"""


def test_the_kernels_are_cached_under_the_fingerprint_of_every_kernel_module():
    path = _kernels.query_point._cache._cache_path
    assert path == str(_jit.CACHE_DIR)
    modules = {p.name for p in _jit._kernel_modules()}
    assert {'_jit.py', 'support.py', 'gjk.py', 'epa.py', 'bvh.py', '_kernels.py'} <= modules
    assert 'scene.py' not in modules  # no kernel of its own: editing it keeps the cache


def test_one_process_compiles_while_the_others_wait_and_only_it_announces(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    first = subprocess.Popen([sys.executable, '-c', HOLD, '1.5'], env=env, text=True,
                             stdout=subprocess.PIPE)
    assert first.stdout.readline().strip() == 'announced'
    assert first.stdout.readline().startswith('compiling')
    second = subprocess.run([sys.executable, '-c', HOLD, '0'], env=env, text=True,
                            capture_output=True, timeout=60)
    first_done = float(first.stdout.readline().split()[1])
    assert first.wait(timeout=60) == 0 and second.returncode == 0
    lines = second.stdout.splitlines()
    assert lines[0].startswith('compiling')  # no announcement: the cache was there
    assert float(lines[0].split()[1]) >= first_done  # and only once the first had finished


def test_an_unwritable_user_cache_falls_back_to_the_package(tmp_path):
    blocked = tmp_path / 'file'
    blocked.write_text('not a folder')
    out = subprocess.run([sys.executable, '-c', 'from collision_engine._jit import CACHE_DIR; '
                          'print(CACHE_DIR)'], env=dict(os.environ, NUMBA_CACHE_DIR=str(blocked)),
                         capture_output=True, text=True, check=True).stdout.strip()
    assert out.endswith(_jit.CACHE_DIR.name) and '__pycache__' in out
