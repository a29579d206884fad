"""The robot site built from its parameters: the defaults are the cores' own, a bad set is refused.

``bench/teleop_lockstep.py`` builds its remote site through the assembly from the default
parameters; its figures are those of the cores' defaults only while these agree.
"""
import dataclasses

import numpy as np
import pytest

from haptic_contract.teleop import CommandLimits, HAND_SPEED
from robot_site.assembly import (admission_config, follower, follower_safety, ft_sensor,
                                 impedance_robot, robot_safety, tissue)
from robot_site.force_envelope import EnvelopeConfig
from robot_site.ft_sensor import ForceTorqueSensorConfig
from robot_site.impedance_robot import ImpedanceRobotConfig
from robot_site.params import FollowerParams, SimulatedRobotParams
from robot_site.safety import SafetyConfig
from robot_site.tissue import ABDOMEN, PlaneSurface
from teleop_protocol.admission import AdmissionConfig

SKIN = PlaneSurface([0.0, 0.0, -0.025], [0.0, 0.0, 1.0])


def same_fields(built, expected) -> dict:
    """Return each field of two configs that differs (arrays compared element by element)."""
    return {field.name: (getattr(built, field.name), getattr(expected, field.name))
            for field in dataclasses.fields(expected)
            if not np.array_equal(getattr(built, field.name), getattr(expected, field.name))}


def test_the_default_robot_is_the_cores_default_on_the_abdomen():
    params = SimulatedRobotParams()
    environment = tissue(params, SKIN)
    assert environment.law == ABDOMEN and environment.surface is SKIN
    assert same_fields(impedance_robot(params, environment).config,
                       ImpedanceRobotConfig()) == {}
    assert same_fields(ft_sensor(params).config, ForceTorqueSensorConfig()) == {}


def test_the_robot_bounds_the_patient_force_itself_and_never_latches_a_hard_stop():
    params = SimulatedRobotParams(target_timeout=0.2)
    config = robot_safety(params).config
    assert same_fields(config, SafetyConfig(
        robot_stiffness=params.stiffness, link_timeout=0.2,
        envelope=EnvelopeConfig(hard_stop=float('inf')))) == {}


def test_the_default_follower_has_the_safety_and_door_of_the_cores_defaults():
    params = dataclasses.replace(FollowerParams(), link_timeout=0.3)
    assert same_fields(follower_safety(params).config,
                       SafetyConfig(robot_stiffness=1500.0, link_timeout=0.3)) == {}
    assert admission_config(params) == AdmissionConfig()
    limits = CommandLimits(np.full(3, -0.4), np.full(3, 0.4), HAND_SPEED)
    built = follower(params, limits, None)
    assert (built.config.scheme, built.config.robot_stiffness) == ('model', 1500.0)
    assert built.limits is limits and built.estimator is not None


def test_the_follower_keeps_the_bound_it_is_given():
    params = FollowerParams()
    safety = follower_safety(params)
    limits = CommandLimits(np.full(3, -0.4), np.full(3, 0.4), HAND_SPEED)
    assert follower(params, limits, None, safety=safety).safety is safety


@pytest.mark.parametrize('build, params', [
    (follower_safety, FollowerParams(force_margin=25.0)),
    (robot_safety, SimulatedRobotParams(release_force=21.0)),
    (admission_config, FollowerParams(max_command_age=-1.0)),
])
def test_a_bad_parameter_set_is_refused_when_built(build, params):
    with pytest.raises(ValueError):
        build(params)
