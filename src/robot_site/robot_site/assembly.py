"""The robot site built from its parameters, without rclpy: its nodes and the benches call it.

The simulated robot: ``tissue`` (the patient's law on a surface), ``impedance_robot`` pressing
it, ``ft_sensor`` at its wrist and ``robot_safety``, the patient's bound on its own state. The
follower: ``follower_safety``, ``follower_config`` and ``admission_config`` from its parameters
(checked at start), and ``follower`` of them, for the limits the robot reports and the surface
the site sees.
"""
from typing import Callable

import numpy as np

from haptic_contract.teleop import CommandLimits
from robot_site.follower import Follower, FollowerConfig
from robot_site.ft_sensor import ForceTorqueSensor, ForceTorqueSensorConfig
from robot_site.impedance_robot import Environment, ImpedanceRobot, ImpedanceRobotConfig
from robot_site.model_estimation import ContactModelEstimator, EstimatorConfig
from robot_site.params import envelope, FollowerParams, SimulatedRobotParams
from robot_site.safety import PatientSafety, SafetyConfig
from robot_site.tissue import HuntCrossley, Surface, Tissue
from teleop_protocol.admission import Admission, AdmissionConfig

__all__ = ['admission_config', 'follower', 'follower_config', 'follower_safety', 'ft_sensor',
           'impedance_robot', 'robot_safety', 'tissue']


def tissue(params: SimulatedRobotParams, surface: Surface) -> Tissue:
    """Return the patient's Hunt–Crossley tissue under ``surface``."""
    return Tissue(HuntCrossley(params.tissue_stiffness, params.tissue_exponent,
                               params.tissue_damping), surface)


def impedance_robot(params: SimulatedRobotParams, environment: Environment) -> ImpedanceRobot:
    """Return the impedance-controlled arm, its TCP pressing ``environment``."""
    return ImpedanceRobot(ImpedanceRobotConfig(
        mass=params.mass, stiffness=params.stiffness, max_speed=params.max_speed,
        workspace_lower=np.array(params.workspace_lower),
        workspace_upper=np.array(params.workspace_upper),
        initial_position=np.array(params.initial_position)), environment=environment)


def ft_sensor(params: SimulatedRobotParams) -> ForceTorqueSensor:
    """Return the wrist's force/torque sensor: its bias, noise, bandwidth and seed."""
    return ForceTorqueSensor(ForceTorqueSensorConfig(
        force_bias=np.array(params.force_bias), force_noise=params.force_noise,
        bandwidth=params.sensor_bandwidth, seed=params.seed))


def robot_safety(params: SimulatedRobotParams) -> PatientSafety:
    """Return the robot's own patient bound: its spring, its targets' silence, no hard stop."""
    return PatientSafety(SafetyConfig(
        robot_stiffness=params.stiffness, max_patient_force=params.max_patient_force,
        force_margin=params.force_margin, link_timeout=params.target_timeout,
        release_force=params.release_force, retract_speed=params.retract_speed,
        envelope=envelope(params)))


def follower_safety(params: FollowerParams) -> PatientSafety:
    """Return the follower's patient bound: the link's silence, the rejoin, the hard stop."""
    return PatientSafety(SafetyConfig(
        robot_stiffness=params.robot_stiffness,
        max_patient_force=params.max_patient_force, force_margin=params.force_margin,
        link_timeout=params.link_timeout, release_force=params.release_force,
        retract_speed=params.retract_speed, rejoin_speed=params.rejoin_speed,
        envelope=envelope(params, params.hard_stop_force)))


def follower_config(params: FollowerParams) -> FollowerConfig:
    """Return the follower's scheme, the robot's stiffness it assumes and its drift rate."""
    return FollowerConfig(params.scheme, params.robot_stiffness, params.drift_rate)


def admission_config(params: FollowerParams) -> AdmissionConfig:
    """Return the door the operator's commands pass: age, lead, session and rate."""
    return AdmissionConfig(max_age=params.max_command_age, max_lead=params.max_stamp_lead,
                           session_timeout=params.session_timeout,
                           max_rate=params.max_command_rate)


def follower(params: FollowerParams, limits: CommandLimits, surface: Callable | None, *,
             safety: PatientSafety | None = None) -> Follower:
    """Return the follower of a robot with ``limits``, seeing the patient's ``surface``.

    ``surface`` maps the TCP to the skin's nearest point and normal (None: only what contact
    teaches the model). ``safety``: the patient bound already built (the node's, which
    re-engages it), else a new one.
    """
    return Follower(follower_config(params),
                    follower_safety(params) if safety is None else safety, limits,
                    ContactModelEstimator(EstimatorConfig(force_noise=params.force_noise)),
                    surface=surface,
                    admission=Admission(admission_config(params)))
