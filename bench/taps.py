"""A stiff tap on the simulated wand, rendered on the device or held from the loop, step by step.

The hand pushes the wand from 5 mm above a wall (z < 0) to 10 mm into it, holds, and lifts it
clear: one second of 1 kHz ticks. Each tick the pose goes round the loop and comes back after
``round_trip`` ticks, either as a plane model that the device renders against its current state
every servo period (local), or as the wrench computed for that pose, which the device holds
(remote). Both run through the same ``LocalRenderer`` (a model, or a held wrench), so they differ
only in what reaches the device. A recording law sees every servo period: the tip's height and
the force rendered, for contacts, work and felt latency.

Shared by ``test_local_rendering.py`` and ``bench/servo_rate.py``; it shares no code with the
force law it checks but the device's own pieces.
"""
from collections import deque
from dataclasses import dataclass
import math
import time

import numpy as np

from haptic_bringup.contacts import contacts
from haptic_contract.contact_model import ContactModel
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.port_passivity import PortPassivity
from haptic_wand_driver.simulated import SimulatedWand, SimulatedWandConfig
from simulated_operator.hand import OperatorHand
from simulated_operator.scripts import WaypointScript

__all__ = ['TapResult', 'tap']

TICK = 0.001  # [s]
DURATION = 1.0  # [s]
MASS = 0.15  # [kg] the simulated wand's default
SCRIPT = [(0.0, 0.0, 0.0, 0.005), (0.3, 0.0, 0.0, -0.010), (0.6, 0.0, 0.0, -0.010),
          (0.8, 0.0, 0.0, 0.005)]


@dataclass(frozen=True)
class TapResult:
    """What one tap did, at servo resolution.

    Attributes
    ----------
    contacts : int
        Contacts with the wall (a lift under ``contacts.REBOUND_HEIGHT`` is no rebound).
    work : float, J
        Net work of the rendered force on the tip (> 0: energy given to the hand).
    depth : float, m
        Deepest penetration.
    peak_force : float, N
    felt_latency : float, s
        From the tip's first crossing into the wall (interpolated between servo periods) to
        the start of the first servo period with a force.
    substep_cost : (n,) float, s
        Wall time of each tick's servo periods, per period.
    """

    contacts: int
    work: float
    depth: float
    peak_force: float
    felt_latency: float
    substep_cost: np.ndarray


class _Recording:
    """The device's law, seen from inside its servo loop: every period's state and force."""

    def __init__(self, law: LocalRenderer) -> None:
        self.law = law
        self.rows = []  # (time, z, force z)

    def wrench(self, time_, coordinates, rates, period):
        force, torque = self.law.wrench(time_, coordinates, rates, period)
        self.rows.append((time_, coordinates[2], force[2]))
        return force, torque


def _wall_model(stiffness: float, tip) -> ContactModel:
    """Return the plane z = 0 as the force renderer sends it: 2 mm validity, 10 N limit."""
    fields = [0, 0, 'world', 'wall', 1, 1, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, *[stiffness] * 3,
              0.8, 0.8, 0.8, 0.0, 0.0, 0.0, *[0.0] * 30, 10.0, 0.01, 0.002, *tip]
    return ContactModel.from_fields(fields, 'world')


def tap(stiffness: float, *, local: bool, servo_rate: float = 4000.0,
        round_trip: int = 1, contact_damping_ratio: float = 1.0) -> TapResult:
    """Run one tap; ``round_trip`` in ticks. The law runs in the wand's Python loop, observed."""
    law = _law(contact_damping_ratio if local else 0.0)
    recording = _Recording(law)
    costs = _press(recording, law, stiffness, local, servo_rate, round_trip)
    rows = np.array(recording.rows)
    times, z, force = rows[:, 0], rows[:, 1], rows[:, 2]
    inside = int(np.argmax(z < 0.0))  # between this period's start and the one before
    crossing = times[inside - 1] + (times[inside] - times[inside - 1]) * z[inside - 1] / (
        z[inside - 1] - z[inside])
    first_force = times[np.argmax(force != 0.0)]
    return TapResult(contacts=len(contacts(z)), work=float(np.sum(force[:-1] * np.diff(z))),
                     depth=float(-z.min()), peak_force=float(force.max()),
                     felt_latency=float(first_force - crossing), substep_cost=costs)


def servo_cost(stiffness: float, *, servo_rate: float = 4000.0) -> np.ndarray:
    """Return each tick's wall time per servo period of a local tap, the law compiled.

    The law is given to the wand unobserved, as the driver gives it (``servo_loop``).
    """
    law = _law(1.0)
    return _press(law, law, stiffness, True, servo_rate, 1)


def _law(contact_damping_ratio: float) -> LocalRenderer:
    return LocalRenderer(force_limit=10.0, torque_limit=0.5,
                         passivity=PortPassivity(max_damping=50.0), mass=(MASS,) * 3,
                         contact_damping_ratio=contact_damping_ratio)


def _press(device_law, law: LocalRenderer, stiffness: float, local: bool, servo_rate: float,
           round_trip: int) -> np.ndarray:
    """Tap with ``device_law`` in the wand's servo loop and ``law`` taking what the loop sends.

    Returns each tick's wall time of ``read``, per servo period.
    """
    config = SimulatedWandConfig(step=1.0 / servo_rate,
                                 initial_position=np.array([0.0, 0.0, 0.005]))
    wand = SimulatedWand(config, operator=OperatorHand(WaypointScript.from_rows(SCRIPT)))
    wand.render_locally(device_law)
    in_flight, costs = deque(), []
    for tick in range(round(DURATION / TICK)):
        start = time.perf_counter()
        state = wand.read(tick * TICK)
        costs.append((time.perf_counter() - start) / (servo_rate * TICK))
        model = _wall_model(stiffness, tuple(state.position))
        answer = model if local else model.wrench(state.position, state.linear_velocity, 0.0,
                                                  0.0, (0.0, 0.0, 0.0))[0]
        in_flight.append(answer)
        if len(in_flight) > round_trip:
            arrived = in_flight.popleft()
            if local:
                law.take(arrived, deadline=math.inf)
            else:
                law.take_wrench(arrived, (0.0, 0.0, 0.0), deadline=math.inf)
    return np.array(costs)
