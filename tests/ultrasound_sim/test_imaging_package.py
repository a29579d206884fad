"""The package as a whole: its exports resolve, and its core imports no ROS.

Run in a fresh interpreter: the test suite's own imports would otherwise hide what it pulls in.
"""

import subprocess
import sys

PROBE = '''
import sys
import ultrasound_sim
for name in ultrasound_sim.__all__:
    getattr(ultrasound_sim, name)
settings = ultrasound_sim.ProbeSettings()
print(sorted({'rclpy', 'trimesh', 'fcl', 'pymust'} & set(sys.modules)))
'''


def test_exports_resolve_and_no_ros_is_imported():
    result = subprocess.run([sys.executable, '-c', PROBE], capture_output=True, text=True,
                            check=True, cwd='/')
    assert result.stdout.strip() == '[]'
