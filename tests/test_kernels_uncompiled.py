"""The compiled kernels' tests once more with numba off (``NUMBA_DISABLE_JIT=1``), as Python.

Why: compiled code forgives what Python would refuse (an index past an array's end reads
memory, a float stored into an int array is truncated without a word), and a kernel that
compiles yet is wrong as Python has only one run that can tell. With the JIT off the same
functions run as the plain Python they are written in, so an exception shows where; the
tests' assertions are unchanged. The numba projects do the same in their CI. One subprocess,
the kernel modules' own tests, none of the long searches: about a minute with numba off.
"""
import os
import pathlib
import subprocess
import sys

TESTS = pathlib.Path(__file__).resolve().parent
KERNEL_TESTS = [
    'collision_engine/test_norms.py', 'collision_engine/test_signed_volumes.py',
    'collision_engine/test_support.py', 'collision_engine/test_gjk.py',
    'collision_engine/test_epa.py', 'collision_engine/test_box_box.py',
    'haptic_wand_driver/test_servo_loop.py', 'ultrasound_sim/test_kernels.py']
# Seconds each as Python: a thousand-vertex hull searched step by step (covered compiled).
SLOW = ['collision_engine/test_gjk.py::test_no_cycling_near_a_many_vertex_hull']


def test_the_kernel_tests_pass_with_numba_off():
    environment = {**os.environ, 'NUMBA_DISABLE_JIT': '1'}
    command = [sys.executable, '-m', 'pytest', '-q', '-p', 'no:cacheprovider',
               *(str(TESTS / path) for path in KERNEL_TESTS),
               *(f'--deselect={TESTS / path}' for path in SLOW)]
    result = subprocess.run(command, cwd=TESTS.parent, env=environment, capture_output=True,
                            text=True, timeout=900)
    assert result.returncode == 0, result.stdout[-6000:] + result.stderr[-3000:]
    assert ' passed' in result.stdout.splitlines()[-1]


def test_the_kernel_tests_listed_exist():
    """The list above names files and tests that are there (a rename would skip them)."""
    for path in KERNEL_TESTS + [slow.split('::')[0] for slow in SLOW]:
        assert (TESTS / path).is_file(), path
    for slow in SLOW:
        path, name = slow.split('::')
        assert f'def {name}(' in (TESTS / path).read_text()
