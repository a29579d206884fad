"""A simulated robot arm holding the ultrasound probe, under Cartesian impedance control.

Why: the remote site needs a robot that behaves as a real impedance-controlled arm (a Franka's or
a UR's cartesian_controllers) does: its tool centre point (TCP) does not jump to a commanded pose
but is pulled there by a spring-damper, so pressing on a patient gives a force that depends on
how far the target lies inside, and a sudden command moves the probe no faster than the arm can.

The TCP is a point mass m pulled toward the target by K (x_t − x) − D ẋ, plus the external force
of whatever it touches (the ``environment``: the patient's tissue). Its speed is limited to
``max_speed`` (norm) and its position to the workspace box, whose walls stop it inelastically.
The orientation is held at its initial value for now; the pose API carries a quaternion (x, y,
z, w, as geometry_msgs) so that orientation control can come later without a new interface.

``read(now)`` advances in fixed substeps of ``step`` seconds with semi-implicit Euler (velocity
first, the damping implicit), as ``haptic_wand_driver.simulated`` does: the trajectory depends
only on the commands given before each substep, never on when ``read`` is called. A new target
applies from the next substep on. The substeps run twice a 1 kHz tick in the remote site's loop,
so the state is plain floats: numpy's cost per call on a 3-vector is larger than the arithmetic.
"""

from dataclasses import dataclass, field
import math
from typing import Callable

import numpy as np

from remote_probe._checks import finite_number, finite_vector, unit_vector

__all__ = ['Environment', 'ImpedanceRobot', 'ImpedanceRobotConfig', 'RobotState']

Environment = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""The force (3,) N on the TCP from what it touches, given its position (m) and velocity (m/s)."""

_IDENTITY = (0.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True, eq=False)
class ImpedanceRobotConfig:
    """Parameters of the simulated arm, all in the robot's base frame.

    The defaults are plausible for a 7-DOF arm in Cartesian impedance control (translational
    stiffness of the order of 10³ N/m), chosen for a well-behaved scan, not from a datasheet.

    Parameters
    ----------
    mass : float, kg
        Apparent Cartesian mass at the TCP, probe included.
    stiffness : float, N/m
        Translational stiffness of the impedance spring.
    damping : float or None, N·s/m
        Translational damping; None gives critical damping, 2·sqrt(stiffness · mass).
    max_speed : float, m/s
        Largest TCP speed.
    workspace_lower, workspace_upper : (3,) float, m
        Corners of the box the TCP stays in.
    step : float, s
        Simulation substep.
    initial_position : (3,) float, m
    initial_orientation : (4,) float
        Unit quaternion x, y, z, w; held.
    """

    mass: float = 2.0
    stiffness: float = 1500.0
    damping: float | None = None
    max_speed: float = 0.25
    workspace_lower: np.ndarray = field(default_factory=lambda: np.full(3, -0.4))
    workspace_upper: np.ndarray = field(default_factory=lambda: np.full(3, 0.4))
    step: float = 5e-4
    initial_position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    initial_orientation: np.ndarray = field(default_factory=lambda: np.array(_IDENTITY))

    def __post_init__(self):
        for name in ('mass', 'stiffness', 'max_speed', 'step'):
            finite_number(getattr(self, name), f'ImpedanceRobotConfig.{name}',
                          minimum=0.0, strict=True)
        if self.damping is None:
            object.__setattr__(self, 'damping', 2.0 * math.sqrt(self.stiffness * self.mass))
        finite_number(self.damping, 'ImpedanceRobotConfig.damping', minimum=0.0)
        for name in ('workspace_lower', 'workspace_upper', 'initial_position'):
            object.__setattr__(self, name, finite_vector(getattr(self, name), 3,
                                                         f'ImpedanceRobotConfig.{name}'))
        object.__setattr__(self, 'initial_orientation', unit_vector(
            self.initial_orientation, 4, 'ImpedanceRobotConfig.initial_orientation'))
        if np.any(self.workspace_lower >= self.workspace_upper):
            raise ValueError(f'ImpedanceRobotConfig workspace_lower {self.workspace_lower} must '
                             f'lie below workspace_upper {self.workspace_upper} on every axis')
        if not self.contains(self.initial_position):
            raise ValueError(f'ImpedanceRobotConfig.initial_position {self.initial_position} '
                             f'lies outside the workspace')

    def contains(self, position: np.ndarray) -> bool:
        """Whether ``position`` (3,) m lies in the workspace box, walls included."""
        return bool(np.all(position >= self.workspace_lower)
                    and np.all(position <= self.workspace_upper))


@dataclass(frozen=True, eq=False)
class RobotState:
    """The TCP at one substep.

    Attributes
    ----------
    time : float, s
    position : (3,) float, m
    velocity : (3,) float, m/s
    orientation : (4,) float
        Unit quaternion x, y, z, w.
    external_force : (3,) float, N
        The environment's force on the TCP at this position and velocity: what a force sensor
        at the probe mount measures (the probe taken as weightless).
    """

    time: float
    position: np.ndarray
    velocity: np.ndarray
    orientation: np.ndarray
    external_force: np.ndarray


class ImpedanceRobot:
    """A TCP pulled toward a commanded target by a spring-damper, against an environment.

    Parameters
    ----------
    config : ImpedanceRobotConfig
    environment : Environment or None
        The force of what the probe touches, evaluated at every substep; None: free space.
    """

    def __init__(self, config: ImpedanceRobotConfig = ImpedanceRobotConfig(), *,
                 environment: Environment | None = None):
        self._config = config
        self._environment = environment
        self._position = tuple(config.initial_position.tolist())
        self._velocity = (0.0, 0.0, 0.0)
        self._external_force = self._environment_force()
        self._target = self._position
        self._start: float | None = None
        self._steps_done = 0
        self._limits = tuple(zip(config.workspace_lower.tolist(), config.workspace_upper.tolist()))

    @property
    def config(self) -> ImpedanceRobotConfig:
        """The configuration it was built with."""
        return self._config

    @property
    def target(self) -> np.ndarray:
        """The commanded TCP position (3,) m, as given (the workspace stops the TCP, not it)."""
        return np.array(self._target)

    def command(self, position, orientation=_IDENTITY) -> None:
        """Pull the TCP toward ``position`` (3,) m from the next substep on.

        ``orientation`` (4,) x, y, z, w must be a non-zero quaternion; it is not tracked yet
        (the orientation stays at ``config.initial_orientation``).
        """
        position = finite_vector(position, 3, 'ImpedanceRobot.command position')
        unit_vector(orientation, 4, 'ImpedanceRobot.command orientation')
        self._target = tuple(position.tolist())

    def read(self, now: float) -> RobotState:
        """Advance to the last substep at or before ``now`` (s) and return the state there.

        The first call starts the clock at ``now``; the clock must not go back.
        """
        now = finite_number(now, 'ImpedanceRobot.read now')
        if self._start is None:
            self._start = now
        elif now < self._time():
            raise ValueError(f'ImpedanceRobot.read: now {now!r} s is before the last state '
                             f'({self._time()!r} s); the clock must not go back')
        target_steps = math.floor((now - self._start) / self._config.step + 1e-9)
        for _ in range(self._steps_done, target_steps):
            self._substep()
        self._steps_done = max(self._steps_done, target_steps)
        return self.state()

    def state(self) -> RobotState:
        """Return the state at the last substep, without advancing."""
        return RobotState(self._time(), np.array(self._position), np.array(self._velocity),
                          self._config.initial_orientation, np.array(self._external_force))

    def _time(self) -> float:
        return (self._start or 0.0) + self._steps_done * self._config.step

    def _substep(self) -> None:
        """One semi-implicit Euler step: speed limited, then the workspace walls stop the TCP."""
        config = self._config
        step, mass, stiffness = config.step, config.mass, config.stiffness
        decay = 1.0 + step * config.damping / mass
        velocity = [(v + step * (stiffness * (t - p) + f) / mass) / decay for p, v, t, f in zip(
            self._position, self._velocity, self._target, self._external_force)]
        speed = math.sqrt(velocity[0] ** 2 + velocity[1] ** 2 + velocity[2] ** 2)
        if speed > config.max_speed:
            scale = config.max_speed / speed
            velocity = [v * scale for v in velocity]
        position = []
        for k, (p, (lower, upper)) in enumerate(zip(self._position, self._limits)):
            p += step * velocity[k]
            if p <= lower and velocity[k] < 0.0 or p >= upper and velocity[k] > 0.0:
                velocity[k] = 0.0
            position.append(min(max(p, lower), upper))
        self._position, self._velocity = tuple(position), tuple(velocity)
        self._external_force = self._environment_force()

    def _environment_force(self) -> tuple:
        """Return the environment's force at the current state (and for the next substep)."""
        if self._environment is None:
            return (0.0, 0.0, 0.0)
        force = self._environment(np.array(self._position), np.array(self._velocity))
        return tuple(finite_vector(force, 3, 'environment force').tolist())
