"""The local launcher's pieces: environment, parameters, and the discovery's expectations."""
import dataclasses
import os
import pathlib
import sys

import pytest
import yaml

from haptic_bringup.launcher import (expected_endpoints, imager_argv, loop_environment,
                                     LoopConfig, node_parameters, parse_args, site_nodes,
                                     teleop_endpoints)
from haptic_bringup.site import parse_args as site_args, site_config


def test_children_discover_on_localhost_only_in_the_chosen_domain(tmp_path, monkeypatch):
    monkeypatch.delenv('ROS_AUTOMATIC_DISCOVERY_RANGE', raising=False)
    env = loop_environment(17, tmp_path / 'log')
    assert env['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'
    assert env['ROS_DOMAIN_ID'] == '17'
    assert env['ROS_LOG_DIR'] == str(tmp_path / 'log')
    assert any(pathlib.Path(p).samefile(sys.prefix)
               for p in env['AMENT_PREFIX_PATH'].split(os.pathsep))


def test_a_discovery_range_the_user_exported_is_kept(tmp_path, monkeypatch):
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'SUBNET')
    assert loop_environment(17, tmp_path / 'log')['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'SUBNET'


def test_parameters_layer_package_defaults_a_user_file_and_the_options(tmp_path):
    user = tmp_path / 'mine.yaml'
    user.write_text(yaml.safe_dump({'force_renderer': {'ros__parameters': {
        'stiffness': [500.0, 500.0, 500.0]}}}))
    config = LoopConfig(scene='scene.yaml', experiment='hand', record=str(tmp_path / 'bag'),
                        params_file=str(user),
                        overrides={'force_renderer': {'force_limit': 3.0}})
    merged = node_parameters(config)
    force = merged['force_renderer']['ros__parameters']
    assert force['stiffness'] == [500.0, 500.0, 500.0]  # the user's file over the default
    assert force['force_limit'] == 3.0  # an override over both
    assert force['damping'] == [0.8, 0.8, 0.8]  # the package default stays
    driver = merged['wand_driver']['ros__parameters']
    assert driver['experiment'] == 'hand' and driver['scene_file'] == 'scene.yaml'
    assert driver['wait_for_recorder'] is True
    assert merged['recorder']['ros__parameters']['output'] == str(tmp_path / 'bag')
    assert merged['collision_engine']['ros__parameters']['scene_file'] == 'scene.yaml'


def test_the_loop_is_closed_when_every_stream_has_its_publisher_and_subscribers():
    full = expected_endpoints(LoopConfig(record='bag'))
    assert full['/wand/pose'] == (1, 2)  # the collision node and the recorder
    assert full['/collision/state'] == (1, 2)
    assert full['/wand/wrench'] == full['/wand/contact_model'] == (1, 1)  # the recorder
    partial = expected_endpoints(LoopConfig(nodes=('collision_engine', 'force_renderer')))
    assert partial['/wand/pose'] == (0, 1) and partial['/collision/state'] == (1, 1)
    composed = expected_endpoints(LoopConfig(record='bag', composed=True))  # records itself
    assert set(composed.values()) == {(1, 0)}


def test_the_composed_loop_and_each_site_record_themselves_into_the_session(tmp_path):
    loop = node_parameters(LoopConfig(record=str(tmp_path / 'bag'), composed=True))
    assert loop['recorder']['ros__parameters']['output'] == str(tmp_path / 'bag')
    assert loop['wand_driver']['ros__parameters']['wait_for_recorder'] is False  # no need
    config = LoopConfig(teleop='model', record=str(tmp_path / 'scan'), imaging=True)
    sites = node_parameters(config)
    assert 'recorder' not in sites
    operator = sites['operator_recorder']['ros__parameters']
    remote = sites['remote_recorder']['ros__parameters']
    assert operator['output'] == str(tmp_path / 'scan' / 'operator')
    assert remote['output'] == str(tmp_path / 'scan' / 'remote') and remote['prefix'] == '/remote'
    # Each site's gateway is in its process, before the recorder (built last, destroyed last).
    assert site_nodes(config, 'operator') == ('wand_driver', 'teleop_leader', 'site_gateway',
                                              'operator_recorder')
    # The imager is a process of its own beside the remote site's, as ros2 run starts it.
    assert site_nodes(config, 'remote') == ('sim_robot', 'teleop_follower', 'site_gateway',
                                            'remote_recorder')
    assert imager_argv(config, ['--ros-args'])[1:] == ['-m', 'ultrasound_sim.node', '--ros-args']
    assert operator['topics'][-1] == '/probe/image'  # recorded where it is seen
    blind = LoopConfig(teleop='model', record=str(tmp_path / 'blind'))  # no imaging by default
    assert site_nodes(blind, 'remote') == ('sim_robot', 'teleop_follower', 'site_gateway',
                                           'remote_recorder')
    # The gateway as a process of its own (the baseline): the crossing streams are DDS
    # endpoints at each site; in the site's process, they are handed over there.
    apart = dataclasses.replace(blind, gateway_in_process=False)
    assert site_nodes(apart, 'remote') == ('sim_robot', 'teleop_follower', 'remote_recorder')
    for domain in (blind.domain_id, blind.remote_domain_id):
        for topic in ('/teleop/command', '/teleop/feedback'):
            assert teleop_endpoints(blind)[domain][topic][1] == 0
            assert teleop_endpoints(apart)[domain][topic][1] == 1
    assert '/probe/image' not in node_parameters(blind)['operator_recorder'][
        'ros__parameters']['topics']
    assert '/probe/image' not in teleop_endpoints(blind)[blind.remote_domain_id]
    assert teleop_endpoints(config)[config.remote_domain_id]['/probe/image'] == (1, 1)
    remote_graph = teleop_endpoints(config)[config.remote_domain_id]
    blind_graph = teleop_endpoints(blind)[blind.remote_domain_id]
    # The imager takes the TCP pose over DDS, one subscriber more.
    assert remote_graph['/robot/tcp_pose'][1] == blind_graph['/robot/tcp_pose'][1] + 1
    remote = site_config(site_args(['remote', '--listen', 'tls/0.0.0.0:7447', '--insecure',
                                    '--imaging']))
    assert remote.loop.imaging and parse_args(['--teleop', 'model', '--imaging']).imaging
    assert not parse_args(['--teleop', 'model']).imaging


def test_both_ends_wait_out_the_link_s_spread_a_trace_s_included(tmp_path):
    def bounds(link):
        merged = node_parameters(LoopConfig(teleop='model', link=link))
        leader = merged['teleop_leader']['ros__parameters']
        follower = merged['teleop_follower']['ros__parameters']
        assert leader['link_timeout'] == follower['link_timeout']
        assert leader['max_feedback_age'] == follower['max_command_age']
        assert leader['max_stamp_lead'] == follower['max_stamp_lead']
        return leader['link_timeout'], leader['max_feedback_age'], leader['max_stamp_lead']
    assert bounds({}) == (0.1, 0.1, 0.05)  # the nodes' own defaults on a steady link
    assert bounds({'delay': 0.5, 'jitter': 0.1}) == pytest.approx((0.6, 0.6, 0.55))
    trace = tmp_path / 'trace.csv'
    trace.write_text('time,delay\n0.0,0.1\n1.0,0.3\n')  # one SD of 0.1 s
    assert bounds({'delay_trace': str(trace)}) == pytest.approx((0.6, 0.6, 0.55))
    assert bounds({'delay_trace': str(trace), 'jitter': 0.1}) == pytest.approx(
        (0.1 + 5 * 0.1 * 2 ** 0.5,) * 2 + (0.05 + 5 * 0.1 * 2 ** 0.5,))
