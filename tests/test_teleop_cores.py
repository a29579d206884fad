"""The sites' and the link's cores stay free of ROS and of trimesh (which the phantom needs).

Run in a fresh interpreter, so that what other tests imported does not count.
"""
import subprocess
import sys

PROBE = '''
import sys
import robot_site.ft_sensor, robot_site.impedance_robot, link_emulator.link
import robot_site.model_estimation, robot_site.phantom, robot_site.safety
import link_emulator.relay, robot_site.tissue, teleop_leader.leader, teleop_protocol.round_trip
link_emulator.relay.message_class('geometry_msgs/msg/PoseStamped')
print(sorted({'rclpy', 'trimesh', 'scipy', 'collision_engine'} & set(sys.modules)))
'''


def test_the_cores_import_neither_ros_nor_trimesh():
    result = subprocess.run([sys.executable, '-c', PROBE], capture_output=True, text=True,
                            check=True, cwd='/')
    assert result.stdout.strip() == '[]'
