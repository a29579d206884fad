"""A virtual coupling between the link's port and the wand, where TDPA's controller acts.

Why: in contact, TDPA's operator-side controller is a relay. With the energy the robot sent
spent, a motion out of the patient must get no force and a motion in gets all of it; acting on
the wand's own velocity, that switch chattered at 20–30 Hz, 14–30 % of the felt force, over ROS
and in lockstep alike. A small virtual mass on a spring and a damper between the port and the
wand (Colgate's virtual coupling) takes the switching instead: the controller acts on the mass's
velocity, and the hand feels the spring, which averages it. Mass, spring and dampers are passive,
so the chain stays as passive as the link; the mass starts at rest, with no energy of its own.

Integrated with the position first: over a step the port force does exactly ``force · velocity ·
dt`` of work on the mass, the energy the controller books. Steps are at most ``max_step``: the
leader's tick is the wand's pose period, which a busy machine stretches.

Sampled, the elements stay passive for some gains only. The force on the wand is held over each
step, and gives a wand that keeps the step's velocity no energy while ``stiffness · step / 2 <=
damping`` (Colgate's bound for a sampled spring, with the coupling's damper for the device's) and
``(damping + ground_damping / 2) · step < mass``: the impedance at the step's Nyquist frequency
changes sign at each, and within both it is positive real (checked on the impedance for 200,000
random gains, and on the coupling itself in tests/teleop_leader/test_virtual_coupling.py). Other
gains are refused. A velocity that changes within a step is beyond any held force: that energy is
the device's to absorb.
"""
from dataclasses import dataclass
import math

import numpy as np

from haptic_contract.checks import finite_number

__all__ = ['CouplingConfig', 'VirtualCoupling']


@dataclass(frozen=True)
class CouplingConfig:
    """The coupling's elements, as the hand feels them (wand frame, felt units).

    Parameters
    ----------
    mass : float, kg
    stiffness : float, N/m
        The spring between the mass and the wand.
    damping : float, N·s/m
        The damper beside that spring.
    ground_damping : float, N·s/m
        A damper from the mass to the world: in free space the hand feels it, through the spring.
    max_step : float, s
        The longest integration step.
    """

    mass: float = 0.1
    stiffness: float = 400.0
    damping: float = 9.0
    ground_damping: float = 1.0
    max_step: float = 1e-3

    def __post_init__(self):
        finite_number(self.mass, 'coupling mass', minimum=0.0, strict=True)
        finite_number(self.max_step, 'coupling max_step', minimum=0.0, strict=True)
        for name in ('stiffness', 'damping', 'ground_damping'):
            finite_number(getattr(self, name), f'coupling {name}', minimum=0.0)
        if self.stiffness * self.max_step / 2.0 > self.damping:
            raise ValueError(f'coupling stiffness {self.stiffness:g} N/m gives energy sampled '
                             f'every {self.max_step:g} s with damping {self.damping:g} N*s/m: '
                             'needs stiffness * max_step / 2 <= damping')
        if (self.damping + self.ground_damping / 2.0) * self.max_step >= self.mass:
            raise ValueError(f'coupling damping {self.damping:g} N*s/m (ground '
                             f'{self.ground_damping:g}) gives energy sampled every '
                             f'{self.max_step:g} s on mass {self.mass:g} kg: needs (damping + '
                             'ground_damping / 2) * max_step < mass')


class VirtualCoupling:
    """A mass, coupled to the wand by a spring and a damper, driven by the link's port force.

    Parameters
    ----------
    config : CouplingConfig
    wand : (3,) float, m
        Where the wand is: the mass starts there, at rest.
    """

    def __init__(self, config: CouplingConfig, wand) -> None:
        self.config = config
        self.position = np.array(wand, dtype=np.float64)
        self.velocity = np.zeros(3)

    def steps(self, dt: float) -> tuple[int, float]:
        """Return how many steps of what length (s) make ``dt`` s."""
        count = max(1, math.ceil(dt / self.config.max_step - 1e-9))
        return count, dt / count

    def step(self, port_force, wand, wand_velocity, dt: float) -> np.ndarray:
        """Advance ``dt`` s under ``port_force`` (3,) N; return the force (3,) N on the wand."""
        config = self.config
        self.position = self.position + self.velocity * dt
        on_mass = (np.asarray(port_force) - self._coupling_force(wand, wand_velocity)
                   - config.ground_damping * self.velocity)
        self.velocity = self.velocity + on_mass * (dt / config.mass)
        return self._coupling_force(wand, wand_velocity)

    def _coupling_force(self, wand, wand_velocity) -> np.ndarray:
        """Return what the spring and damper push the wand with (the mass feels its opposite)."""
        return (self.config.stiffness * (self.position - np.asarray(wand))
                + self.config.damping * (self.velocity - np.asarray(wand_velocity)))
