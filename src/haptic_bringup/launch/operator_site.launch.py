"""The operator's site on its own machine: the wand and the leader, and the gateway that dials.

    ros2 launch haptic_bringup operator_site.launch.py endpoint:=tls/REMOTE_HOST:7447
        certs:=DIR [scheme:=model] [record:=<bag dir>] [experiment:=<file>] [duration:=<s>]

See ``haptic_bringup.site_launch`` for every argument; ``haptic_site operator`` does the same
without launch.
"""
from haptic_bringup.site_launch import site_launch_description


def generate_launch_description():
    return site_launch_description('operator')
