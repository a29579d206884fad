"""The patient's site on its own machine: the robot and the follower, and the gateway that listens.

    ros2 launch haptic_bringup remote_site.launch.py endpoint:=tls/0.0.0.0:7447 certs:=DIR
        [scheme:=model] [record:=<bag dir>]

See ``haptic_bringup.site_launch`` for every argument; ``haptic_site remote`` does the same
without launch.
"""
from haptic_bringup.site_launch import site_launch_description


def generate_launch_description():
    return site_launch_description('remote')
