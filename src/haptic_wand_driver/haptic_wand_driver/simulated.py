"""A simulated 5-DOF wand: the device to use when there is no hardware, closing the loop.

The wand is five decoupled joints q = (x, y, z, roll, yaw), each a mass (or inertia) with viscous
damping, moved by the operator's hand and by the applied wrench. The workspace ends are perfectly
inelastic stops: a joint reaching one is put back on it and loses its outward velocity, so the
stops only ever remove energy.

The substep is the device's servo period (4 kHz by default). In each, the wand renders either the
held wrench, or, once given a law to run locally (``render_locally``: a ``LocalRenderer`` with
the latest contact model), that law against its state at the substep, as a real device's servo
loop would. ``applied`` reports the mean of what it rendered since the last call, and
``force_edges`` every instant the force it rendered switched on or off (the substep's start).

``read(now)`` advances in fixed substeps of ``step`` seconds with semi-implicit Euler (velocity
first, the device's own damping implicit), so the trajectory depends only on the wrench applied
before each substep, never on when ``read`` was called: a jittery timer that reads the same
instants gets the same states, bit for bit. The held wrench applies from the next substep on,
and substep k pulls toward the hand's target at k · step seconds of the wand's clock.

The substeps run in the haptic loop's thread, once or twice per 1 kHz tick, so the joints are
plain floats: numpy's per-call cost on 5-vectors is larger than the arithmetic. With the
device's own law (a ``LocalRenderer``, as the driver gives it) they run compiled
(``servo_loop``): the same arithmetic in the same order, of which this module's Python loop,
run for any other law, is the reference. Everything that enters (the configuration, the applied
wrench, the hand's targets) is finite where it enters and the stops bound the coordinates, so
the states it returns need no second check.
"""

from dataclasses import dataclass, field
import math

import numpy as np

from haptic_contract.checks import finite_components, finite_number, finite_vector
from haptic_contract.plane_law import saturate_components
from haptic_contract.shared_defaults import DEVICE_DAMPING, FORCE_LIMIT
from haptic_contract.wand import roll_axis
from haptic_util.substeps import substeps_due
from haptic_wand_driver.device import DeviceLimits, HapticDevice, WandState
from haptic_wand_driver.hand_coupling import Hand, impedance
from haptic_wand_driver.local_rendering import LocalRenderer

__all__ = ['DEVICE_MASS', 'SERVO_RATE', 'SimulatedWand', 'SimulatedWandConfig', 'TORQUE_LIMIT']

DEVICE_MASS = 0.15  # [kg] apparent mass per axis
TORQUE_LIMIT = 0.5  # [N*m]
SERVO_RATE = 4000.0  # [Hz] the substep's rate

_STABLE_STEP = 0.2
"""Largest step · sqrt(k / m) and step · c / m accepted for the hand's explicit spring-damper."""


@dataclass(frozen=True, eq=False)
class SimulatedWandConfig:
    """Parameters of the simulated wand.

    The defaults describe a desk-top pantograph wand as a point: they are plausible values chosen
    for a well-behaved loop, not a datasheet.

    Parameters
    ----------
    mass : (3,) float, kg
        Apparent mass on x, y, z.
    damping : (3,) float, N·s/m
        Viscous damping on x, y, z.
    roll_inertia, yaw_inertia : float, kg·m²
    roll_damping, yaw_damping : float, N·m·s/rad
    limits : DeviceLimits
        Force and torque saturation and the workspace, whose ends are the stops.
    step : float, s
        Simulation substep.
    initial_position : (3,) float, m
    initial_roll, initial_yaw : float, rad
    """

    mass: np.ndarray = field(default_factory=lambda: np.full(3, DEVICE_MASS))
    damping: np.ndarray = field(default_factory=lambda: np.full(3, DEVICE_DAMPING))
    roll_inertia: float = 5e-4
    yaw_inertia: float = 5e-4
    roll_damping: float = 2e-3
    yaw_damping: float = 2e-3
    limits: DeviceLimits = field(
        default_factory=lambda: DeviceLimits(force_limit=FORCE_LIMIT, torque_limit=TORQUE_LIMIT))
    step: float = 1.0 / SERVO_RATE
    initial_position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    initial_roll: float = 0.0
    initial_yaw: float = 0.0

    def __post_init__(self):
        for name in ('mass', 'damping', 'initial_position'):
            object.__setattr__(self, name, finite_vector(getattr(self, name), 3,
                                                         f'SimulatedWandConfig.{name}'))
        for name, value in (('mass', self.mass.min()), ('roll_inertia', self.roll_inertia),
                            ('yaw_inertia', self.yaw_inertia), ('step', self.step)):
            finite_number(value, f'SimulatedWandConfig.{name}', minimum=0.0, strict=True)
        for name, value in (('damping', self.damping.min()), ('roll_damping', self.roll_damping),
                            ('yaw_damping', self.yaw_damping)):
            finite_number(value, f'SimulatedWandConfig.{name}', minimum=0.0)
        if not self.limits.workspace.contains(self.initial_coordinates):
            raise ValueError(f'SimulatedWandConfig initial pose {self.initial_coordinates} lies '
                             f'outside the workspace {self.limits.workspace}')

    @property
    def inertia(self) -> np.ndarray:
        """(5,) float: mass [kg] on x, y, z, inertia [kg·m²] on roll, yaw."""
        return np.concatenate([self.mass, [self.roll_inertia, self.yaw_inertia]])

    @property
    def joint_damping(self) -> np.ndarray:
        """(5,) float: N·s/m on x, y, z, N·m·s/rad on roll, yaw."""
        return np.concatenate([self.damping, [self.roll_damping, self.yaw_damping]])

    @property
    def initial_coordinates(self) -> np.ndarray:
        """(5,) float: x, y, z [m], roll, yaw [rad]."""
        return np.concatenate([self.initial_position, [self.initial_roll, self.initial_yaw]])


_ZERO = (0.0, 0.0, 0.0)
_NO_TARGET = ((0.0,) * 5, (0.0,) * 5)  # for no hand, whose gains are 0


class SimulatedWand(HapticDevice):
    """A 5-DOF wand simulated in real time, moved by an operator's hand and the applied wrench.

    Parameters
    ----------
    config : SimulatedWandConfig
    operator : Hand or None
        The hand holding it (``simulated_operator.OperatorHand``, a scripted one); None leaves the
        wand free (only the applied wrench moves it).
    """

    def __init__(self, config: SimulatedWandConfig = SimulatedWandConfig(), *,
                 operator: Hand | None = None):
        self._config = config
        inverse_inertia = 1.0 / config.inertia
        if operator is not None:
            _check_step_resolves(config.step, operator, inverse_inertia)
        self._operator = operator
        self._step = config.step
        damping_decay = 1.0 / (1.0 + config.step * config.joint_damping * inverse_inertia)
        lower, upper = config.limits.workspace.coordinate_bounds
        hand_gains = (np.zeros((2, 5)) if operator is None
                      else np.array([operator.stiffness, operator.damping]))
        self._joints = list(zip(*hand_gains.tolist(), inverse_inertia.tolist(),
                                damping_decay.tolist(), lower.tolist(), upper.tolist()))
        self._joint_table = np.array(self._joints)  # (5, 6), for servo_loop
        self._coordinates = config.initial_coordinates.tolist()
        self._rates = [0.0] * 5
        self._force = self._torque = _ZERO
        self._until = math.inf
        self._start: float | None = None
        self._steps_done = 0
        self._law = self._compiled = None
        self._rendered = [0.0] * 6  # sum of force and torque over the substeps since applied()
        self._rendered_steps = 0
        self._mean = np.zeros(6)  # what applied() returned last
        self._pushing = False
        self.force_edges: list = []  # (time s, pushing after it): the force switching on or off

    @property
    def limits(self) -> DeviceLimits:
        """Force, torque and workspace limits from the configuration."""
        return self._config.limits

    @property
    def config(self) -> SimulatedWandConfig:
        """The configuration it was built with."""
        return self._config

    def read(self, now: float) -> WandState:
        """Advance to the last substep at or before ``now`` (s) and return the state there.

        The first call starts the clock (and the operator's script) at ``now``.
        """
        self._raise_if_closed()
        now = finite_number(now, 'SimulatedWand.read now')
        self._start, target_steps = substeps_due(now, self._start, self._steps_done, self._step,
                                                 'SimulatedWand.read')
        if target_steps > self._steps_done:
            self._advance(target_steps)
        return WandState._from_checked(self._time(), self._coordinates, self._rates)

    def apply(self, force: np.ndarray, torque: np.ndarray, *, until: float = math.inf) -> None:
        """Hold this wrench (N, N·m, workspace frame), saturated, until the next or ``until``.

        A substep that would end after ``until`` (s, the wand's clock) renders zero: nothing is
        rendered past the deadline, as in ``LocalRenderer``.
        """
        self._raise_if_closed()
        force = finite_components(force, 3, 'SimulatedWand.apply force')
        torque = finite_components(torque, 3, 'SimulatedWand.apply torque')
        if math.isnan(until):
            raise ValueError('SimulatedWand.apply until must not be NaN')
        limits = self._config.limits
        self._force = saturate_components(force, limits.force_limit)
        self._torque = saturate_components(torque, limits.torque_limit)
        self._until = until

    def render_locally(self, law) -> None:
        """Run ``law`` at every substep instead of the held wrench (see ``HapticDevice``).

        The device's own law (a ``LocalRenderer``) is compiled here, before the loop starts.
        """
        self._raise_if_closed()
        self._law, self._compiled = law, None
        if isinstance(law, LocalRenderer):
            from haptic_wand_driver import servo_loop  # numba: only for a wand that needs it
            servo_loop.compile_now()
            self._compiled = servo_loop.advance

    def applied(self) -> tuple[np.ndarray, np.ndarray]:
        """Return the mean force and torque rendered over the substeps since the last call.

        With no substep since (two ticks inside one servo period), the last mean: the hand still
        feels it. Zero there read as a drop of the whole force for a tick (58 in a scan at 100 ms
        on a loaded machine, every jump over 1 N of its felt force).
        """
        if self._rendered_steps:
            self._mean = np.array(self._rendered) / self._rendered_steps
        self._rendered, self._rendered_steps = [0.0] * 6, 0
        return self._mean[:3].copy(), self._mean[3:].copy()

    def close(self) -> None:
        """Drop the held wrench and the local law, and stop."""
        self._force = self._torque = _ZERO
        self._law = self._compiled = None
        super().close()

    def _time(self) -> float:
        return self._start + self._steps_done * self._step

    def _expiry_step(self) -> float:
        """Return the first substep that would end after the hold deadline (inf when none)."""
        if self._until == math.inf or self._start is None:
            return math.inf
        if self._until == -math.inf:
            return self._steps_done
        return max(math.floor((self._until - self._start) / self._step + 1e-9), self._steps_done)

    def _advance(self, target_steps: int) -> None:
        """Substep semi-implicit Euler on every joint up to ``target_steps``; stops hold."""
        if self._compiled is not None:
            self._advance_compiled(target_steps, self._law)
            return
        step = self._step
        force_x, force_y, force_z = self._force
        torque_x, torque_y, torque_z = self._torque
        hand = None if self._operator is None else self._operator.target_components
        joints = self._joints
        coordinates, rates = self._coordinates, self._rates
        expires = self._expiry_step()
        law, limits = self._law, self._config.limits
        rendered = self._rendered
        for done in range(self._steps_done, target_steps):
            if law is not None:
                (force_x, force_y, force_z), (torque_x, torque_y, torque_z) = law.wrench(
                    self._start + done * step, coordinates, rates, step)
                force_x, force_y, force_z = saturate_components(
                    (force_x, force_y, force_z), limits.force_limit)
                torque_x, torque_y, torque_z = saturate_components(
                    (torque_x, torque_y, torque_z), limits.torque_limit)
            elif done == expires:  # the watchdog deadline: the held wrench drops to zero
                force_x = force_y = force_z = torque_x = torque_y = torque_z = 0.0
                self._force = self._torque = _ZERO
            for k, value in enumerate((force_x, force_y, force_z, torque_x, torque_y, torque_z)):
                rendered[k] += value
            pushing = force_x != 0.0 or force_y != 0.0 or force_z != 0.0
            if pushing != self._pushing:
                self._pushing = pushing
                self.force_edges.append((self._start + done * step, pushing))
            roll_x, roll_y, roll_z = roll_axis(coordinates[4])
            efforts = (force_x, force_y, force_z,  # then roll_yaw_jacobian(yaw).T @ torque
                       roll_x * torque_x + roll_y * torque_y + roll_z * torque_z, torque_z)
            targets, target_rates = _NO_TARGET if hand is None else hand(done * step)
            moved, kept = [], []
            for (coordinate, rate, effort, target, target_rate,
                 (stiffness, damping, inverse_inertia, decay, lower, upper)) in zip(
                    coordinates, rates, efforts, targets, target_rates, joints):
                effort += impedance(stiffness, damping, target, target_rate, coordinate, rate)
                rate = (rate + step * effort * inverse_inertia) * decay
                coordinate += step * rate
                if coordinate < lower:
                    coordinate, rate = lower, max(rate, 0.0)
                elif coordinate > upper:
                    coordinate, rate = upper, min(rate, 0.0)
                moved.append(coordinate)
                kept.append(rate)
            coordinates, rates = moved, kept
        self._coordinates, self._rates = coordinates, rates
        self._rendered_steps += target_steps - self._steps_done
        self._steps_done = target_steps

    def _advance_compiled(self, target_steps: int, law: LocalRenderer) -> None:
        """``_advance`` with the device's own law, in ``servo_loop``."""
        first, step = self._steps_done, self._step
        if self._operator is None:
            targets = np.zeros((target_steps - first, 2, 5))
        else:
            hand = self._operator.target_components
            targets = np.array([hand(done * step) for done in range(first, target_steps)])
        coordinates, rates = np.array(self._coordinates), np.array(self._rates)
        rendered = np.array(self._rendered)
        edges = np.empty(target_steps - first, dtype=np.int64)
        books, limits = law.passivity.books(), self._config.limits
        pushing, written = self._compiled(
            coordinates, rates, self._joint_table, targets, law.packed, books, law.bound,
            limits.force_limit, limits.torque_limit, self._start, first, step, rendered, edges,
            self._pushing)
        law.passivity.restore(books)
        for done in edges[:written].tolist():
            self._pushing = not self._pushing
            self.force_edges.append((self._start + done * step, self._pushing))
        self._rendered = rendered.tolist()
        self._coordinates, self._rates = coordinates.tolist(), rates.tolist()
        self._rendered_steps += target_steps - first
        self._steps_done = target_steps


def _check_step_resolves(step: float, operator: Hand,
                         inverse_inertia: np.ndarray) -> None:
    """Refuse a step too long for the hand's explicit spring-damper on this inertia."""
    stiffness_ratio = step * np.sqrt(operator.stiffness * inverse_inertia).max()
    damping_ratio = step * (operator.damping * inverse_inertia).max()
    if max(stiffness_ratio, damping_ratio) > _STABLE_STEP:
        raise ValueError(
            f'SimulatedWandConfig.step {step} s is too long for the operator hand on this '
            f'mass: step·sqrt(k/m) = {stiffness_ratio:.3g} and step·c/m = '
            f'{damping_ratio:.3g} must stay <= {_STABLE_STEP}')
