"""One site of a telerobotic session on a full ROS 2 Jazzy install: what both launch files share.

    ros2 launch haptic_bringup remote_site.launch.py endpoint:=tls/0.0.0.0:7447 certs:=DIR
    ros2 launch haptic_bringup operator_site.launch.py endpoint:=tls/HOST:7447 certs:=DIR

The same site as ``haptic_site`` starts (``haptic_bringup.site``), with the same parameters: the
site's nodes and its gateway in one process, with ``record:=`` its own bag, and with
``imaging:=true`` the remote site's imager in a process of its own (the operator's records it).
The remote site listens on ``endpoint``, the operator's connects to it. The site stands or falls
together: when its process exits because the other site stopped, or the operator's experiment
ends, the launch stops the rest. Imported by the launch files only (``launch`` comes with a full
install).
"""
import os
import pathlib
import tempfile

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
import yaml

from haptic_bringup.launch_actions import AllOrNothing, hear_sigint, imager, local_discovery
from haptic_bringup.launcher import gateway_remap, LoopConfig, site_nodes
from haptic_bringup.site import site_parameters, SiteConfig
from haptic_contract.teleop import SCHEMES

__all__ = ['site_launch_description']

ARGUMENTS = (  # name, default, description
    ('endpoint', '', 'remote: where to listen (tls/0.0.0.0:7447); operator: the remote site to '
     'connect to (tls/HOST:7447)'),
    ('certs', '', "this site's files from haptic_certs (ca.pem, <role>.pem, <role>.key)"),
    ('insecure', 'false', 'plaintext tcp/ endpoint, no certificates (warned at every start)'),
    ('scheme', 'model', 'bilateral scheme, the same on both sites: direct | tdpa | model'),
    ('record', '', "record this site's topics to this bag directory"),
    ('experiment', '', "operator: the operator's script (default: the scripted scan)"),
    ('duration', '0.0', "operator: stop after this many seconds (0: the script's length)"),
    ('delay', '0.0', 'emulated one-way delay added to what this site sends [s]'),
    ('jitter', '0.0', 'standard deviation of the emulated delay [s]'),
    ('loss', '0.0', 'probability that the emulated link loses a message'),
    ('params_file', '', 'extra parameters YAML'),
    ('imaging', 'false', "remote: image the probe's view (operator: record it)"),
)


def _site(role: str, context) -> SiteConfig:
    def argument(name: str) -> str:
        return LaunchConfiguration(name).perform(context)

    link = {'delay': float(argument('delay')), 'jitter': float(argument('jitter')),
            'loss': float(argument('loss'))}
    loop = LoopConfig(composed=True, teleop=argument('scheme'), link=link,
                      domain_id=int(os.environ.get('ROS_DOMAIN_ID', '0')),
                      experiment=argument('experiment') or None,
                      duration=float(argument('duration')), record=argument('record') or None,
                      params_file=argument('params_file') or None,
                      imaging=argument('imaging').lower() == 'true')
    endpoint = (argument('endpoint'),)
    return SiteConfig(role, loop, listen=endpoint if role == 'remote' else (),
                      connect=endpoint if role == 'operator' else (),
                      certs=argument('certs') or None,
                      insecure=argument('insecure').lower() == 'true')


def _processes(context, role: str):
    site = _site(role, context)
    if site.loop.teleop not in SCHEMES:
        raise ValueError(f'scheme:={site.loop.teleop!r}: choose direct, tdpa or model')
    with tempfile.NamedTemporaryFile('w', prefix=f'{role}_site_', suffix='.yaml',
                                     delete=False) as out:
        yaml.safe_dump(site_parameters(site), out)
    parameters = str(pathlib.Path(out.name))
    together = AllOrNothing()
    actions = together.add(role, Node(  # its gateway and its recorder, if any, in its process
        package='haptic_bringup', executable='composed',
        arguments=list(site_nodes(site.loop, role)), ros_arguments=gateway_remap(role),
        parameters=[parameters], output='screen'))
    if role == 'remote' and site.loop.imaging:
        actions += together.add('probe_imager', imager(parameters))
    return actions


def site_launch_description(role: str) -> LaunchDescription:
    """Return the launch description of ``role``'s site."""
    hear_sigint()
    return LaunchDescription([
        local_discovery(),
        *(DeclareLaunchArgument(name, default_value=default, description=description)
          for name, default, description in ARGUMENTS),
        OpaqueFunction(function=_processes, args=[role]),
    ])
