"""Each parameter has one owner, its node's parameters dataclass: the YAML files repeat it.

A package's ``config/<file>.yaml`` is what the launchers load first. A value there that differs
from the dataclass's default is a second default (a node started without the file, a test, a
benchmark building the dataclass would run another value), and a key that is no field of it a
parameter the node ignores. So every key must be a field, and every value its default.
"""
import dataclasses
import importlib
import pathlib

import pytest
import yaml

SRC = pathlib.Path(__file__).resolve().parents[1] / 'src'
# config file -> node -> its parameters dataclass
FILES = {
    'collision_engine/config/collision_engine.yaml': {
        'collision_engine': 'collision_engine.params.CollisionNodeParams'},
    'force_renderer/config/force_renderer.yaml': {
        'force_renderer': 'force_renderer.params.ForceRendererParams'},
    'haptic_wand_driver/config/haptic_wand_driver.yaml': {
        'wand_driver': 'haptic_wand_driver.params.WandDriverParams'},
    'robot_site/config/robot_site.yaml': {
        'sim_robot': 'robot_site.params.SimulatedRobotParams',
        'teleop_follower': 'robot_site.params.FollowerParams'},
    'teleop_leader/config/teleop_leader.yaml': {
        'teleop_leader': 'teleop_leader.params.LeaderParams'},
    'ultrasound_sim/config/ultrasound_sim.yaml': {
        'probe_imager': 'ultrasound_sim.params.ProbeImagerParams'},
    'site_gateway/config/site_gateway.yaml': {
        'site_gateway': 'site_gateway.gateway.GatewayParams'},
}
NODE_FILES = [(path, node, dotted) for path, nodes in FILES.items()
              for node, dotted in nodes.items()]


def defaults(dotted: str) -> dict:
    """Return the fields of the dataclass at ``dotted`` with their default values."""
    module, name = dotted.rsplit('.', 1)
    cls = getattr(importlib.import_module(module), name)
    return {field.name: (field.default if field.default is not dataclasses.MISSING
                         else field.default_factory()) for field in dataclasses.fields(cls)}


@pytest.mark.parametrize('path, node, dotted', NODE_FILES)
def test_each_value_in_a_parameter_file_is_its_dataclass_default(path, node, dotted):
    written = yaml.safe_load((SRC / path).read_text())[node]['ros__parameters']
    owned = defaults(dotted)
    assert sorted(set(written) - set(owned)) == [], f'{path}: {node} has no such parameter'
    differ = {key: (value, owned[key]) for key, value in written.items()
              if (tuple(value) if isinstance(value, list) else value) != owned[key]}
    assert differ == {}, f'{path}: {node}: (file, dataclass) differ'


def test_every_parameter_file_is_checked():
    """The table names every node of every package's config file (a new one is not skipped)."""
    found = {(str(path.relative_to(SRC)), node)
             for path in SRC.glob('*/config/*.yaml')
             for node in (yaml.safe_load(path.read_text()) or {})
             if 'ros__parameters' in (yaml.safe_load(path.read_text())[node] or {})}
    assert found == {(path, node) for path, node, _ in NODE_FILES}
