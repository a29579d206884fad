"""The package as a whole: what it exports, and that its core stays free of ROS and heavy imports.

Run in a fresh interpreter: the test suite's own path set-up would otherwise shadow the package.
"""

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
