"""A telerobotic session on a full ROS 2 Jazzy install: two sites, two domains, a link between.

    ros2 launch haptic_bringup teleop.launch.py scheme:=model delay:=0.05 [jitter:=0.005]
        [loss:=0.01] [reorder:=true] [delay_trace:=<csv>] [record:=<bag dir>]
        [remote_domain:=<id>] [experiment:=<waypoint file>] [duration:=<s>]
        [params_file:=<yaml>] [imaging:=true]

The operator's site (``wand_driver`` and ``teleop_leader``, one process) runs in the launch's
``ROS_DOMAIN_ID``; the remote site (``sim_robot`` and ``teleop_follower``, one process) in
``remote_domain`` (default: the next domain), with ``imaging:=true`` the probe's imager
(``probe_imager``, a process of its own) beside it; each site's gateway, a node of its process,
joins them over loopback mutual TLS with certificates made for the launch, the deployed path,
each emulating the link on what it sends (``haptic_bringup.site.loopback_gateway_parameters``).
``record:=DIR`` has each site's process record itself with the project's recorder, into the
session folder DIR (the bags ``operator`` and ``remote``, the remote site's topics under
``/remote/``), so a Ctrl-C to the whole launch loses nothing. Parameters come from each
package's config/, then ``params_file``, then these arguments, exactly as the local launcher
(``haptic_loop --teleop ...``) sets them. The session
stands or falls together, as the loop does: when one process exits, the launch stops the others.
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
from haptic_bringup.launcher import gateway_remap, LoopConfig, node_parameters, site_nodes
from haptic_bringup.site import loopback_gateway_parameters
from haptic_contract.teleop import SCHEMES

ARGUMENTS = (  # name, default, description
    ('scheme', 'model', 'bilateral scheme: direct | tdpa | model'),
    ('delay', '0.0', 'one-way link delay [s]'),
    ('jitter', '0.0', 'standard deviation of the delay [s]'),
    ('loss', '0.0', 'probability that a message is lost'),
    ('reorder', 'false', 'let a message overtake an earlier one'),
    ('delay_trace', '', 'replay one-way delays from a CSV (time,delay in s)'),
    ('remote_domain', '', "the remote site's DDS domain (default: ROS_DOMAIN_ID + 1)"),
    ('experiment', '', "the operator's script (default: the scripted scan)"),
    ('duration', '0.0', 'stop after this many seconds (0: the scan\'s own length)'),
    ('record', '', 'record both sites to this bag directory'),
    ('params_file', '', 'extra parameters YAML'),
    ('imaging', 'false', "the remote site images the probe's view (probe/image)"),
)


def _written(values: dict) -> str:
    with tempfile.NamedTemporaryFile('w', prefix='teleop_params_', suffix='.yaml',
                                     delete=False) as out:
        yaml.safe_dump(values, out)
    return out.name


def _config(context) -> LoopConfig:
    """Return the session as the local launcher would run it, from the launch arguments."""
    def argument(name: str) -> str:
        return LaunchConfiguration(name).perform(context)

    link = {'delay': float(argument('delay')), 'jitter': float(argument('jitter')),
            'loss': float(argument('loss')), 'reorder': argument('reorder').lower() == 'true'}
    if argument('delay_trace'):
        link['delay_trace'] = os.path.abspath(argument('delay_trace'))
    remote = argument('remote_domain')
    return LoopConfig(teleop=argument('scheme'), link=link,
                      domain_id=int(os.environ.get('ROS_DOMAIN_ID', '0')),
                      remote_domain=int(remote) if remote else None,
                      experiment=argument('experiment') or None,
                      duration=float(argument('duration')), record=argument('record') or None,
                      params_file=argument('params_file') or None,
                      imaging=argument('imaging').lower() == 'true')


def _processes(context):
    config = _config(context)
    if config.teleop not in SCHEMES:
        raise ValueError(f"scheme:={config.teleop!r}: choose direct, tdpa or model")
    parameters = _written(node_parameters(config))
    gateways = loopback_gateway_parameters(pathlib.Path(tempfile.mkdtemp(prefix='teleop_')),
                                           link=config.link)
    session = AllOrNothing()
    actions = []
    for site, domain in (('operator', config.domain_id), ('remote', config.remote_domain_id)):
        gateway = _written({f'{site}_gateway': {'ros__parameters': gateways[site]}})
        actions += session.add(site, Node(  # with its gateway, in its process
            package='haptic_bringup', executable='composed',
            arguments=list(site_nodes(config, site)), ros_arguments=gateway_remap(site),
            parameters=[parameters, gateway], additional_env={'ROS_DOMAIN_ID': str(domain)},
            output='screen'))
    if config.imaging:
        actions += session.add('probe_imager', imager(parameters, additional_env={
            'ROS_DOMAIN_ID': str(config.remote_domain_id)}))
    return actions


def generate_launch_description() -> LaunchDescription:
    hear_sigint()
    return LaunchDescription([
        local_discovery(),
        *(DeclareLaunchArgument(name, default_value=default, description=description)
          for name, default, description in ARGUMENTS),
        OpaqueFunction(function=_processes),
    ])
