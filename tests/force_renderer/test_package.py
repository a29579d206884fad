"""The package as a whole: what it exports, and that its core stays free of ROS and heavy imports.

Run in a fresh interpreter: the test suite's own path set-up would otherwise shadow the package.
"""

import pathlib
import re
import subprocess
import sys

PROBE = '''
import sys
import force_renderer
for name in force_renderer.__all__:
    getattr(force_renderer, name)
heavy = sorted({'rclpy', 'scipy', 'numba', 'trimesh', 'fcl'} & set(sys.modules))
print(heavy)
'''


def test_exports_resolve_and_nothing_heavy_is_imported():
    result = subprocess.run([sys.executable, '-c', PROBE], capture_output=True, text=True,
                            check=True, cwd='/')
    assert result.stdout.strip() == '[]'


def test_the_virtual_wall_harness_is_not_in_the_package():
    """The closed-loop wall simulation is a test harness (``ground_truth/virtual_wall.py``)."""
    probe = 'import importlib.util; print(importlib.util.find_spec("force_renderer.virtual_wall"))'
    result = subprocess.run([sys.executable, '-c', probe], capture_output=True, text=True,
                            check=True, cwd='/')
    assert result.stdout.strip() == 'None'
    sources = pathlib.Path(__file__).resolve().parents[2] / 'src'
    importing = [path for path in sources.rglob('*.py')
                 if re.search(r'^\s*(from|import)\s+\S*virtual_wall', path.read_text(), re.M)]
    assert importing == []
