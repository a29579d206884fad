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
from math import isfinite
from typing import Callable

import numpy as np

from haptic_contract.checks import (finite_components, finite_number, finite_vector,
                                    nonzero_components, unit_vector, within_box)
from haptic_util.substeps import substeps_due

__all__ = ['Environment', 'ImpedanceRobot', 'ImpedanceRobotConfig', 'RobotState']

Environment = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""The force (3,) N on the TCP from what it touches, given its position (m) and velocity (m/s).

An environment may also offer ``force_floats(position, velocity)``: the same force from and as
three floats (``tissue.Tissue`` does). The substeps then call that, with no arrays.
"""

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
        return within_box(position, self.workspace_lower, self.workspace_upper)


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
        self._force_floats = _float_environment(environment)
        self._decay = 1.0 + config.step * config.damping / config.mass  # the implicit damping
        self._position = tuple(config.initial_position.tolist())
        self._velocity = (0.0, 0.0, 0.0)
        self._external_force = self._force_floats(self._position, self._velocity)
        self._target = self._position
        self._start: float | None = None
        self._steps_done = 0
        self._limits = tuple(zip(config.workspace_lower.tolist(), config.workspace_upper.tolist()))

    @property
    def config(self) -> ImpedanceRobotConfig:
        """The configuration it was built with."""
        return self._config

    @property
    def position(self) -> tuple:
        """Where the TCP is (m) at the last substep, as floats: no arrays, for every tick."""
        return self._position

    @property
    def target(self) -> np.ndarray:
        """The commanded TCP position (3,) m, as given (the workspace stops the TCP, not it)."""
        return np.array(self._target)

    def command(self, position, orientation=_IDENTITY) -> None:
        """Pull the TCP toward ``position`` (3,) m from the next substep on.

        ``orientation`` (4,) x, y, z, w must be a non-zero quaternion; it is not tracked yet
        (the orientation stays at ``config.initial_orientation``).
        """
        target = finite_components(position, 3, 'ImpedanceRobot.command position')
        nonzero_components(orientation, 4, 'ImpedanceRobot.command orientation')
        self._target = target

    def read(self, now: float) -> RobotState:
        """Advance to the last substep at or before ``now`` (s) and return the state there.

        The first call starts the clock at ``now``; the clock must not go back.
        """
        self.advance(now)
        return self.state()

    def advance(self, now: float) -> None:
        """Advance to the last substep at or before ``now`` (s) as ``read`` does; return nothing.

        For a caller about to give a new command, which needs the old target applied up to now
        but not the state, whose arrays cost more than a tick's two substeps.
        """
        now = finite_number(now, 'ImpedanceRobot now')
        self._start, target_steps = substeps_due(now, self._start, self._steps_done,
                                                 self._config.step, 'ImpedanceRobot')
        if target_steps > self._steps_done:
            self._run_substeps(target_steps - self._steps_done)
            self._steps_done = target_steps

    def state(self) -> RobotState:
        """Return the state at the last substep, without advancing."""
        return RobotState(self._time(), np.array(self._position), np.array(self._velocity),
                          self._config.initial_orientation, np.array(self._external_force))

    def _time(self) -> float:
        return (self._start or 0.0) + self._steps_done * self._config.step

    def _run_substeps(self, steps: int) -> None:
        """Run ``steps`` semi-implicit Euler steps: speed limited, then the walls stop the TCP.

        The state stays in local floats from one substep to the next: attribute lookups and
        3-vector arrays would cost more than the arithmetic.
        """
        config = self._config
        step, mass, stiffness = config.step, config.mass, config.stiffness
        max_speed, decay, force_floats = config.max_speed, self._decay, self._force_floats
        (x_lower, x_upper), (y_lower, y_upper), (z_lower, z_upper) = self._limits
        target_x, target_y, target_z = self._target
        x, y, z = self._position
        vx, vy, vz = self._velocity
        fx, fy, fz = self._external_force
        for _ in range(steps):
            vx = (vx + step * (stiffness * (target_x - x) + fx) / mass) / decay
            vy = (vy + step * (stiffness * (target_y - y) + fy) / mass) / decay
            vz = (vz + step * (stiffness * (target_z - z) + fz) / mass) / decay
            speed = math.sqrt(vx ** 2 + vy ** 2 + vz ** 2)
            if speed > max_speed:
                scale = max_speed / speed
                vx, vy, vz = vx * scale, vy * scale, vz * scale
            x, y, z = x + step * vx, y + step * vy, z + step * vz
            if not (x_lower < x < x_upper and y_lower < y < y_upper and z_lower < z < z_upper):
                x, vx = _stop_at_walls(x, vx, x_lower, x_upper)
                y, vy = _stop_at_walls(y, vy, y_lower, y_upper)
                z, vz = _stop_at_walls(z, vz, z_lower, z_upper)
            fx, fy, fz = force_floats((x, y, z), (vx, vy, vz))
        self._position, self._velocity = (x, y, z), (vx, vy, vz)
        self._external_force = (fx, fy, fz)


def _stop_at_walls(position: float, velocity: float, lower: float, upper: float) -> tuple:
    """Return ``position`` clamped to [lower, upper] and ``velocity`` along it, zeroed outward."""
    if position <= lower and velocity < 0.0 or position >= upper and velocity > 0.0:
        velocity = 0.0
    return min(max(position, lower), upper), velocity


def _no_force(position: tuple, velocity: tuple) -> tuple:
    """Return free space's force: none."""
    return (0.0, 0.0, 0.0)


def _float_environment(environment: Environment | None) -> Callable[[tuple, tuple], tuple]:
    """Return ``environment`` as a function of float tuples giving a checked float tuple.

    The substeps call it: an environment with ``force_floats`` (as ``tissue.Tissue``) is called
    on floats, any other with (3,) arrays, as the ``Environment`` type says.
    """
    if environment is None:
        return _no_force
    force_floats = getattr(environment, 'force_floats', None)
    if force_floats is None:
        def array_force_floats(position: tuple, velocity: tuple) -> tuple:
            """Call the environment on arrays; check its force and return it as floats."""
            force = environment(np.array(position), np.array(velocity))
            return tuple(finite_vector(force, 3, 'environment force').tolist())
        return array_force_floats

    def checked_force_floats(position: tuple, velocity: tuple) -> tuple:
        """Call the environment on floats; check its force, as an array environment's."""
        force = force_floats(position, velocity)
        fx, fy, fz = force
        if isfinite(fx) and isfinite(fy) and isfinite(fz):
            return force
        raise ValueError(f'environment force must be 3 finite numbers, got {force!r}')
    return checked_force_floats
