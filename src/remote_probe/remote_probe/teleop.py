"""What crosses the link between the two sites, as plain values (the messages' content).

``Command`` goes from the operator to the robot with every wand pose; ``Feedback`` comes back.
Both are in the robot's base frame and SI units; the ROS nodes read them from and write them to
``haptic_msgs/TeleopCommand`` and ``TeleopFeedback``.
"""
from typing import NamedTuple

import numpy as np

__all__ = ['Command', 'Feedback', 'RemotePlane', 'SCHEMES']

SCHEMES = ('direct', 'tdpa', 'model')
"""The bilateral schemes: direct force reflection (the baseline), time-domain passivity on both
ports (Artigas et al. 2011), and model-mediated teleoperation (the device renders the remote
site's estimate of the contact)."""


class Command(NamedTuple):
    """The operator's command: a target for the probe's TCP.

    Attributes
    ----------
    stamp : float, s
        The wand pose's stamp, on the operator's clock.
    position : (3,) float, m
    velocity : (3,) float, m/s
    energy_in : float, J
        Energy into the link at the operator's port so far.
    """

    stamp: float
    position: np.ndarray
    velocity: np.ndarray
    energy_in: float


class RemotePlane(NamedTuple):
    """The contact as the robot's site estimates it: a plane, and gains seen from the command."""

    point: np.ndarray
    normal: np.ndarray
    stiffness: float
    damping: float


class Feedback(NamedTuple):
    """The robot's answer.

    Attributes
    ----------
    stamp : float, s
        When it was sent, on the robot site's clock.
    echo : float, s
        The newest command's stamp heard there (the operator's clock); 0 before any.
    echo_hold : float, s
        From receiving that command to sending this.
    force : (3,) float, N
        The patient's force on the probe, as measured (zero while the sensor is faulty).
    tcp : (3,) float, m
    energy_in : float, J
        Energy into the link at the robot's port so far.
    plane : RemotePlane or None
        The latest contact estimate; None before any contact.
    """

    stamp: float
    echo: float
    echo_hold: float
    force: np.ndarray
    tcp: np.ndarray
    energy_in: float
    plane: RemotePlane | None
