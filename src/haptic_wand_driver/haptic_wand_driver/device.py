"""The haptic device contract: one small abstract class that every backend implements.

A backend is anything that reports where the wand tip is and accepts a wrench to render: the
shipped :class:`~haptic_wand_driver.simulated.SimulatedWand` and
:class:`~haptic_wand_driver.replay.ReplayDevice`, or a hardware backend (a Quanser HIL wand, a
Force Dimension or Geomagic device, a remote robot) installed separately and registered with
:func:`register_device`.

Contract for :class:`HapticDevice`
----------------------------------
Threading
    A device is not thread-safe. Call ``read``, ``apply`` and ``close`` from one thread (the node's
    executor thread); a backend that needs its own I/O thread hides it behind these calls.
Time
    ``now`` is seconds on the caller's clock, which must not decrease: the node uses a monotonic
    clock, so that a step of the system clock cannot move or stall the wand (stamps stay on ROS
    time; the node converts deadlines). The first ``read`` starts the device's clock.
    ``WandState.time`` is the instant the returned state is valid for, at most ``now``.
Frame and units
    Everything is in the workspace frame (REP-103: x forward, y left, z up; ``world`` by default)
    and in SI: m, s, rad, N, N·m. The position is the tip; the torque is about the tip.
Wrench
    ``apply`` holds the wrench (zero-order hold) until the next ``apply``, or until its
    ``until`` deadline passes, whichever comes first (a device-level watchdog). A backend
    renders only what it can actuate (forces x, y, z; torques about its roll and yaw axes) and
    saturates to its declared ``limits``; non-finite or mis-shaped input raises ``ValueError``.
Local rendering
    A backend with a servo loop of its own may take a law to run there every servo period
    (``render_locally``: a ``LocalRenderer``, which renders the latest contact model against the
    device's current state); from then on it renders that law instead of the held wrench. One
    that cannot raises ``LocalRenderingUnsupported``, and the driver applies the wrench.
Applied wrench
    ``applied`` reports what the device actually rendered since the previous call (its mean over
    the servo periods, after saturation and watchdog), so that what the hand felt is observable.
Lifetime
    ``close`` is idempotent and leaves the device commanding no force; afterwards ``read`` and
    ``apply`` raise :class:`DeviceClosedError`. Devices are context managers.
"""

import abc
from dataclasses import dataclass, field
import importlib
import math
from typing import Callable, Sequence

import numpy as np

from haptic_contract.checks import (finite_components, finite_number, finite_vector,
                                    read_only_vector, within_box)
from haptic_contract.wand import quaternion_from_roll_yaw, roll_axis

__all__ = [
    'DeviceClosedError',
    'DeviceLimits',
    'DeviceUnavailableError',
    'HapticDevice',
    'LocalRenderingUnsupported',
    'WandState',
    'Workspace',
    'available_devices',
    'make_device',
    'register_device',
]

_THIRTY_DEGREES = np.pi / 6.0


class DeviceUnavailableError(ValueError):
    """The requested device kind is not installed or not registered."""


class DeviceClosedError(RuntimeError):
    """The device was used after ``close()``."""


class LocalRenderingUnsupported(ValueError):
    """The backend cannot run a law in a servo loop of its own."""


@dataclass(frozen=True, eq=False)
class Workspace:
    """The reachable set of the wand: a box for the tip and symmetric roll and yaw ranges.

    Parameters
    ----------
    lower, upper : (3,) float, m, workspace frame
        Corners of the box; ``lower <= upper`` on every axis.
    roll_limit, yaw_limit : float, rad
        |roll| <= roll_limit and |yaw| <= yaw_limit (the Quanser wand: about 30 degrees).

    The default box holds the paper's objects, centred 0.075 m below the start at the origin,
    with room to approach them from the sides and above; it is an assumption, not a datasheet.
    """

    lower: np.ndarray = field(default_factory=lambda: np.array([-0.15, -0.15, -0.15]))
    upper: np.ndarray = field(default_factory=lambda: np.array([0.15, 0.15, 0.10]))
    roll_limit: float = _THIRTY_DEGREES
    yaw_limit: float = _THIRTY_DEGREES

    def __post_init__(self):
        object.__setattr__(self, 'lower', finite_vector(self.lower, 3, 'Workspace.lower'))
        object.__setattr__(self, 'upper', finite_vector(self.upper, 3, 'Workspace.upper'))
        if np.any(self.lower > self.upper):
            raise ValueError(f'Workspace.lower {self.lower.tolist()} exceeds Workspace.upper '
                             f'{self.upper.tolist()}')
        for name in ('roll_limit', 'yaw_limit'):
            limit = finite_number(getattr(self, name), f'Workspace.{name}', minimum=0.0)
            if limit > np.pi:
                raise ValueError(f'Workspace.{name} must be at most pi rad, got {limit!r}')
            object.__setattr__(self, name, limit)

    @property
    def coordinate_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Bounds on the joint coordinates (x, y, z, roll, yaw): two (5,) arrays, m and rad."""
        angles = np.array([self.roll_limit, self.yaw_limit])
        return (np.concatenate([self.lower, -angles]), np.concatenate([self.upper, angles]))

    def contains(self, coordinates: np.ndarray) -> bool:
        """Whether joint coordinates (5,) (x, y, z [m], roll, yaw [rad]) lie inside."""
        return within_box(coordinates, *self.coordinate_bounds)


@dataclass(frozen=True, eq=False)
class DeviceLimits:
    """What a device declares it can render and reach.

    Parameters
    ----------
    force_limit : float, N
        Largest force norm it renders; larger commands are scaled down keeping direction.
    torque_limit : float, N·m
        Largest norm of the actuated (roll, yaw) torque.
    workspace : Workspace
    """

    force_limit: float
    torque_limit: float
    workspace: Workspace = field(default_factory=Workspace)

    def __post_init__(self):
        for name in ('force_limit', 'torque_limit'):
            object.__setattr__(self, name, finite_number(
                getattr(self, name), f'DeviceLimits.{name}', minimum=0.0))


@dataclass(frozen=True, eq=False)
class WandState:
    """The wand tip at one instant, in the workspace frame.

    Parameters
    ----------
    time : float, s
        The instant this state is valid for, on the caller's clock.
    position : (3,) float, m
        Tip position.
    roll, yaw : float, rad
        Orientation R = Rz(yaw) · Rx(roll); pitch is always zero.
    linear_velocity : (3,) float, m/s
        Tip velocity.
    roll_rate, yaw_rate : float, rad/s
        Joint rates; :attr:`angular_velocity` is their world-frame sum.
    """

    time: float
    position: np.ndarray
    roll: float
    yaw: float
    linear_velocity: np.ndarray
    roll_rate: float
    yaw_rate: float

    def __post_init__(self):
        for name in ('time', 'roll', 'yaw', 'roll_rate', 'yaw_rate'):
            object.__setattr__(self, name,
                               finite_number(getattr(self, name), f'WandState.{name}'))
        for name in ('position', 'linear_velocity'):
            object.__setattr__(self, name,
                               finite_vector(getattr(self, name), 3, f'WandState.{name}'))

    @classmethod
    def from_coordinates(cls, time: float, coordinates: np.ndarray,
                         rates: np.ndarray) -> 'WandState':
        """Build from joint coordinates and rates, both (5,): (x, y, z, roll, yaw) and d/dt."""
        return cls._from_checked(finite_number(time, 'WandState.time'),
                                 finite_components(coordinates, 5, 'WandState coordinates'),
                                 finite_components(rates, 5, 'WandState rates'))

    @classmethod
    def _from_checked(cls, time: float, coordinates: Sequence[float],
                      rates: Sequence[float]) -> 'WandState':
        """Build from floats the caller vouches are finite: a device's per-tick constructor.

        It skips the dataclass checks, which cost more than a simulated substep.
        """
        vectors = read_only_vector((*coordinates[:3], *rates[:3]))
        state = object.__new__(cls)
        state.__dict__.update({'time': time, 'position': vectors[:3], 'roll': coordinates[3],
                               'yaw': coordinates[4], 'linear_velocity': vectors[3:],
                               'roll_rate': rates[3], 'yaw_rate': rates[4]})
        return state

    @property
    def coordinates(self) -> np.ndarray:
        """(5,) float: x, y, z [m], roll, yaw [rad]."""
        return np.array([*self.position.tolist(), self.roll, self.yaw])

    @property
    def rates(self) -> np.ndarray:
        """(5,) float: linear velocity [m/s], roll rate, yaw rate [rad/s]."""
        return np.array([*self.linear_velocity.tolist(), self.roll_rate, self.yaw_rate])

    @property
    def orientation(self) -> np.ndarray:
        """(4,) float: unit quaternion (x, y, z, w) of Rz(yaw) · Rx(roll)."""
        return quaternion_from_roll_yaw(self.roll, self.yaw)

    @property
    def angular_velocity(self) -> np.ndarray:
        """(3,) float, rad/s, world frame: roll_rate about the roll axis plus yaw_rate about z."""
        x, y, z = roll_axis(self.yaw)
        return np.array([self.roll_rate * x, self.roll_rate * y,
                         self.roll_rate * z + self.yaw_rate])


class HapticDevice(abc.ABC):
    """A haptic wand backend; see the module docstring for the full contract."""

    _closed: bool = False

    @property
    @abc.abstractmethod
    def limits(self) -> DeviceLimits:
        """What the device can render and reach."""

    @abc.abstractmethod
    def read(self, now: float) -> WandState:
        """Return the tip state at (or just before) ``now``, seconds on the caller's clock."""

    @abc.abstractmethod
    def apply(self, force: np.ndarray, torque: np.ndarray, *, until: float = math.inf) -> None:
        """Hold a wrench until the next call: force (3,) N and torque (3,) N·m, workspace frame.

        ``until`` (s, the device's clock) is a watchdog deadline: past it the device renders zero
        even if no further call comes, so a dead loop cannot leave a force on the user's hand.
        A backend with a hardware watchdog arms it with this deadline.
        """

    @abc.abstractmethod
    def applied(self) -> tuple[np.ndarray, np.ndarray]:
        """Return the force (3,) N and torque (3,) N·m rendered since the last call, their means.

        Workspace frame, after the device's saturation and watchdog; zero before anything was
        rendered.
        """

    def render_locally(self, law) -> None:
        """Run ``law`` in the device's servo loop from now on, instead of the held wrench.

        ``law.wrench(time, coordinates, rates, period) -> (force, torque)`` is called every servo
        period with the device's clock, its joints (x, y, z, roll, yaw) and their rates.
        Backends without a servo loop of their own keep this default.
        """
        raise LocalRenderingUnsupported(f'{type(self).__name__} has no servo loop of its own to '
                                        'render a contact model in')

    def close(self) -> None:
        """Stop rendering and release the device; idempotent.

        Backends holding resources override this and call ``super().close()``.
        """
        self._closed = True

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` has been called."""
        return self._closed

    def _raise_if_closed(self) -> None:
        if self._closed:
            raise DeviceClosedError(f'{type(self).__name__} is closed')

    def __enter__(self) -> 'HapticDevice':
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


DeviceFactory = Callable[..., HapticDevice]

_SHIPPED = {
    'simulated': ('haptic_wand_driver.simulated', 'SimulatedWand'),
    'replay': ('haptic_wand_driver.replay', 'ReplayDevice'),
}
_registered: dict[str, DeviceFactory] = {}


def register_device(kind: str, factory: DeviceFactory) -> None:
    """Make ``make_device(kind, **options)`` call ``factory(**options)``.

    This is how a hardware backend, installed as its own package, plugs in.
    """
    if not isinstance(kind, str) or not kind:
        raise ValueError(f'device kind must be a non-empty string, got {kind!r}')
    if kind in _SHIPPED or kind in _registered:
        raise ValueError(f'device kind {kind!r} is already registered')
    if not callable(factory):
        raise ValueError(f'factory for device kind {kind!r} is not callable: {factory!r}')
    _registered[kind] = factory


def available_devices() -> list[str]:
    """Sorted device kinds that :func:`make_device` can build."""
    return sorted([*_SHIPPED, *_registered])


def make_device(kind: str, **options) -> HapticDevice:
    """Build the device ``kind`` with keyword ``options`` passed to its constructor.

    The constructor validates every option before the device starts, so a failure leaves nothing
    half-configured.

    Raises
    ------
    DeviceUnavailableError
        If no backend of that kind is shipped or registered.
    """
    if kind in _SHIPPED:
        module_name, class_name = _SHIPPED[kind]
        factory = getattr(importlib.import_module(module_name), class_name)
    elif kind in _registered:
        factory = _registered[kind]
    else:
        raise DeviceUnavailableError(
            f'haptic device {kind!r} is not available; available: '
            f'{", ".join(available_devices())}. A hardware backend is installed separately and '
            f'registered with haptic_wand_driver.register_device({kind!r}, factory).')
    return factory(**options)
