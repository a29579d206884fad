"""The operator's end of the bilateral schemes: wand → command, feedback → what the hand feels.

Why: the operator's site must stay safe and stable whatever the link does. The leader answers
every wand pose at once from the newest feedback it holds, never waiting on the link:

- ``direct``: the patient's force, scaled, as the wand's force (the baseline; with delay, the
  force acts on an old motion and gives energy back);
- ``tdpa``: the same force through the operator's passivity controller, which books the energy
  at this port against what the robot's port has sent into the link (``remote_probe.tdpa``);
- ``model``: the remote site's estimated plane, mapped into the wand's workspace with the
  scaled gains, for the device to render at its own servo rate.

Feedback older than ``link_timeout`` (on this site's clock: the sites share none) gives zero
force and no model; an older or repeated feedback is ignored by its stamp. The link's round trip
is measured from the echoed command stamps, as NTP does (``RoundTripEstimator``).
"""
from dataclasses import dataclass
import math

import numpy as np

from remote_probe._checks import finite_number
from remote_probe.link import RoundTripEstimator
from remote_probe.tdpa import OperatorPassivity
from remote_probe.teleop import Command, Feedback, RemotePlane, SCHEMES
from remote_probe.workspace_map import WorkspaceMap

__all__ = ['Leader', 'LeaderConfig']


@dataclass(frozen=True)
class LeaderConfig:
    """Parameters of the operator's end.

    Parameters
    ----------
    scheme : str
        One of ``SCHEMES``.
    force_scale : float
        Felt force per patient force.
    position_scale : float
        Robot motion per wand motion.
    link_timeout : float, s
        Feedback older than this (since it arrived) is not rendered.
    """

    scheme: str = 'model'
    force_scale: float = 0.3
    position_scale: float = 1.0
    link_timeout: float = 0.1

    def __post_init__(self):
        if self.scheme not in SCHEMES:
            raise ValueError(f'scheme {self.scheme!r} is not one of {list(SCHEMES)}')
        finite_number(self.link_timeout, 'link_timeout', minimum=0.0, strict=True)


class Leader:
    """The operator's end of the link.

    Parameters
    ----------
    config : LeaderConfig
    wand_start, robot_start : (3,) float, m
        Where the wand and the probe are when the session starts (the first anchors).
    """

    def __init__(self, config: LeaderConfig, wand_start, robot_start) -> None:
        self.config = config
        self.map = WorkspaceMap(config.position_scale, config.force_scale, wand_start,
                                robot_start)
        self.passivity = OperatorPassivity()
        self.round_trip = RoundTripEstimator()
        self._feedback: Feedback | None = None
        self._heard = -math.inf  # this site's clock when the newest feedback came

    def receive(self, now: float, feedback: Feedback) -> bool:
        """Take ``feedback`` arrived at ``now`` (s); False if it is not newer than the held one."""
        if self._feedback is not None and feedback.stamp <= self._feedback.stamp:
            return False
        self._feedback, self._heard = feedback, now
        self.passivity.books.receive(feedback.energy_in)
        if feedback.echo > 0.0:
            replied = feedback.stamp
            self.round_trip.add(feedback.echo, replied - feedback.echo_hold, replied, now)
        return True

    def live(self, now: float) -> bool:
        """Whether feedback came within ``link_timeout`` before ``now``."""
        return now - self._heard <= self.config.link_timeout

    def command(self, stamp: float, wand, wand_velocity) -> Command:
        """Return the command for the wand's pose stamped ``stamp`` (s, this site's clock)."""
        return Command(stamp, self.map.to_robot(wand), self.map.velocity_to_robot(wand_velocity),
                       self.passivity.books.energy_in)

    def force(self, now: float, wand_velocity, dt: float) -> np.ndarray:
        """Return the force (3,) N on the wand for the next ``dt`` s (``direct`` and ``tdpa``).

        Zero while the link is silent or the clutch is engaged.
        """
        patient = np.zeros(3)
        if self.live(now) and not self.map.clutched:
            patient = self._feedback.force
        if self.config.scheme == 'tdpa':
            patient = self.passivity.control(patient, self.map.velocity_to_robot(wand_velocity),
                                             dt)
        return self.config.force_scale * patient

    def plane(self, now: float) -> RemotePlane | None:
        """Return the contact plane in the wand's frame, felt gains (``model``); None: free.

        None too while the link is silent or the clutch is engaged.
        """
        if not self.live(now) or self.map.clutched or self._feedback.plane is None:
            return None
        remote = self._feedback.plane
        return RemotePlane(self.map.to_wand(remote.point), remote.normal,
                           self.map.felt_gain(remote.stiffness),
                           self.map.felt_gain(remote.damping))
