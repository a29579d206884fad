"""The core stays free of ROS and of trimesh (which only the phantom's script needs).

Run in a fresh interpreter, so that what other tests imported does not count.
"""
import subprocess
import sys

PROBE = '''
import sys
import remote_probe.ft_sensor, remote_probe.impedance_robot, remote_probe.link
import remote_probe.model_estimation, remote_probe.phantom, remote_probe.safety
import remote_probe.relay, remote_probe.tissue
remote_probe.relay.message_class('geometry_msgs/msg/PoseStamped')
print(sorted({'rclpy', 'trimesh', 'scipy', 'collision_engine'} & set(sys.modules)))
'''


def test_the_core_imports_neither_ros_nor_trimesh():
    result = subprocess.run([sys.executable, '-c', PROBE], capture_output=True, text=True,
                            check=True, cwd='/')
    assert result.stdout.strip() == '[]'
