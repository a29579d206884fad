"""Closed-loop simulation of a haptic device pressed by a hand against a virtual wall.

The device is a mass with viscous damping, free to move along 1 to 3 orthonormal axes; the
operator's hand is a spring-damper pulling it towards a scripted target. A renderer (normally
`ForcePipeline.step`) is sampled at the servo instants and its force is held (zero-order hold)
until the next one, optionally with period jitter, dropped messages and delay. Between events the
linear device-plus-hand dynamics are integrated exactly (matrix exponential) and the state is
recorded on a fine grid, so the port energy −∫F·v dt is exact, not a quadrature.

Times are counted in whole `substep`s internally, so events never drift. Everything is
deterministic given `seed`. Sign convention of `port_energy`: as in `force_renderer.passivity`
(energy absorbed by the rendering; positive means passive).

It lives in `ground_truth`, not in the `force_renderer` package: it is a test harness, and
nothing that runs the loop uses it. Its users are the stability tests of the pipeline, the
passivity controller and the proxy, and `bench/stiffness_sweep.py`.
"""

from collections import deque
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.linalg import expm

from force_renderer.contact import Contact
from force_renderer.errors import ForceRendererError, non_negative, positive, vector3

__all__ = ['Device', 'HalfSpace', 'OperatorHand', 'ServoTiming', 'WallRun', 'simulate']

Renderer = Callable[[Contact, np.ndarray | None, float], np.ndarray]
SignedDistance = Callable[[np.ndarray], tuple[float, np.ndarray]]


@dataclass(frozen=True)
class HalfSpace:
    """A solid filling the half-space behind a plane: signed distance and normal, exact.

    Attributes
    ----------
    origin : (3,) float, m
        A point on the plane.
    normal : (3,) float
        Outward normal (normalised on construction).
    """

    origin: np.ndarray = field(default_factory=lambda: np.zeros(3))
    normal: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))

    def __post_init__(self) -> None:
        normal = vector3(self.normal, 'HalfSpace.normal')
        length = float(np.linalg.norm(normal))
        if not (np.isfinite(length) and length > 0.0):
            raise ForceRendererError(f'HalfSpace.normal must be finite and non-zero, got {normal}')
        object.__setattr__(self, 'origin', vector3(self.origin, 'HalfSpace.origin'))
        object.__setattr__(self, 'normal', normal / length)

    def __call__(self, point: np.ndarray) -> tuple[float, np.ndarray]:
        """Signed distance (m, negative inside) and outward unit normal at `point` (3,)."""
        return float((np.asarray(point) - self.origin) @ self.normal), self.normal

    def signed_distances(self, points: np.ndarray) -> np.ndarray:
        """Signed distances (n,) of `points` (n, 3), m."""
        return (np.asarray(points) - self.origin) @ self.normal


@dataclass(frozen=True)
class Device:
    """A haptic device as a point mass with viscous damping on its actuated axes.

    Attributes
    ----------
    mass : float, kg
    damping : float, N·s/m
        Physical damping b of the mechanism (the b of the passivity bound).
    axes : (d, 3) float
        Orthonormal rows: the directions it can move and be pushed along (d = 1, 2 or 3).
    """

    mass: float = 0.15
    damping: float = 1.0
    axes: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self) -> None:
        positive(self.mass, 'Device.mass')
        non_negative(self.damping, 'Device.damping')
        axes = np.atleast_2d(np.asarray(self.axes, dtype=np.float64))
        if axes.ndim != 2 or axes.shape[1] != 3 or not 1 <= axes.shape[0] <= 3 \
                or not np.allclose(axes @ axes.T, np.eye(axes.shape[0]), atol=1e-9):
            raise ForceRendererError(
                f'Device.axes must be 1 to 3 orthonormal rows of 3, got {axes.tolist()}')
        object.__setattr__(self, 'axes', axes)


@dataclass(frozen=True)
class OperatorHand:
    """The operator's hand: F = k (target(t) − x) − b v on the device.

    Attributes
    ----------
    stiffness : float, N/m
    damping : float, N·s/m
    target : callable t (s) -> (3,) float, m
        Where the hand wants the tip; held over each simulation piece (it moves slowly).
    """

    stiffness: float
    damping: float
    target: Callable[[float], np.ndarray]

    def __post_init__(self) -> None:
        non_negative(self.stiffness, 'OperatorHand.stiffness')
        non_negative(self.damping, 'OperatorHand.damping')


@dataclass(frozen=True)
class ServoTiming:
    """How the force loop samples and delivers.

    Attributes
    ----------
    period : float, s
        Nominal servo period.
    jitter : float, s
        Each period is `period` plus a uniform draw from [0, jitter].
    drop_probability : float
        Chance that a sample's message is lost: the renderer then gets the last delivered input.
    delay : float, s
        Time from a sample to when its force reaches the device.
    substep : float, s
        Grid of the simulation; every other time is rounded to it.
    """

    period: float = 0.001
    jitter: float = 0.0
    drop_probability: float = 0.0
    delay: float = 0.0
    substep: float = 1e-5

    def __post_init__(self) -> None:
        positive(self.period, 'ServoTiming.period')
        non_negative(self.jitter, 'ServoTiming.jitter')
        non_negative(self.delay, 'ServoTiming.delay')
        positive(self.substep, 'ServoTiming.substep')
        if not 0.0 <= self.drop_probability < 1.0:
            raise ForceRendererError(
                f'ServoTiming.drop_probability must be in [0, 1), got {self.drop_probability}')
        if self.period < self.substep:
            raise ForceRendererError('ServoTiming.period must be at least one substep')


@dataclass(frozen=True)
class WallRun:
    """Time series of one simulation, on the fine grid (n points).

    Attributes
    ----------
    time : (n,) float, s
    position : (n, 3) float, m
    velocity : (n, 3) float, m/s
    force : (n, 3) float, N
        Rendered force held on the device (before projection onto its axes).
    port_energy : (n,) float, J
        Energy absorbed by the rendering so far, −∫F·v dt (negative: it generated energy).
    sample_time : (m,) float, s
        The servo instants.
    """

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    force: np.ndarray
    port_energy: np.ndarray
    sample_time: np.ndarray


def simulate(render: Renderer, wall: SignedDistance, device: Device, hand: OperatorHand, *,
             duration: float, start: np.ndarray, start_velocity=(0.0, 0.0, 0.0),
             timing: ServoTiming = ServoTiming(), give_velocity: bool = True,
             seed: int = 0) -> WallRun:
    """Run the closed loop for `duration` seconds.

    Parameters
    ----------
    render : callable (Contact, velocity or None, now) -> (3,) float, N
        The force renderer; `ForcePipeline.step` fits.
    wall : callable point (3,) -> (signed distance m, outward unit normal (3,))
        The virtual object's signed-distance field, e.g. `HalfSpace`.
    device, hand : Device, OperatorHand
    duration : float, s
    start, start_velocity : (3,) float, m and m/s
        Initial tip state; only its components along `device.axes` move.
    timing : ServoTiming
    give_velocity : bool
        Pass the true velocity (a driver's twist) to `render`; False passes None.
    seed : int
        Seed of the jitter and drop draws.

    Returns
    -------
    WallRun
        The series on the `timing.substep` grid, and the servo instants.
    """
    grid = _Grid(device, hand, timing, positive(duration, 'duration'))
    start = vector3(start, 'start')
    state = np.stack([np.zeros(len(device.axes)),
                      device.axes @ vector3(start_velocity, 'start_velocity')])
    rng = np.random.default_rng(seed)
    delay = round(timing.delay / timing.substep)
    pending: deque[tuple[int, np.ndarray]] = deque()
    applied, energy, tick, next_sample = np.zeros(3), 0.0, 0, 0
    delivered = None
    samples = []
    while tick < grid.steps:
        if tick == next_sample:
            now = tick * timing.substep
            if delivered is None or rng.random() >= timing.drop_probability:
                delivered = _measure(wall, device, start, state, now, give_velocity)
            pending.append((tick + delay, np.asarray(render(*delivered, now), dtype=np.float64)))
            samples.append(now)
            next_sample += grid.period_steps(rng)
        while pending and pending[0][0] <= tick:
            applied = pending.popleft()[1]
        end = min(next_sample, grid.steps, pending[0][0] if pending else grid.steps)
        state, energy = grid.advance(tick, end, state, applied, energy, start)
        tick = end
    return grid.result(start, np.array(samples))


class _Grid:
    """Exact piecewise integration of the device and hand, recorded on the substep grid."""

    def __init__(self, device: Device, hand: OperatorHand, timing: ServoTiming,
                 duration: float) -> None:
        self.device, self.hand, self.timing = device, hand, timing
        self.steps = round(duration / timing.substep)
        self._period = round(timing.period / timing.substep)
        self._jitter = round(timing.jitter / timing.substep)
        longest = max(self._period + self._jitter, round(timing.delay / timing.substep)) + 1
        self._transition, self._input = _transitions(device, hand, timing.substep, longest)
        axes = len(device.axes)
        self._states = np.zeros((self.steps + 1, 2, axes))
        self._force = np.zeros((self.steps + 1, 3))
        self._energy = np.zeros(self.steps + 1)

    def period_steps(self, rng: np.random.Generator) -> int:
        """Length of the next servo period, in substeps."""
        return self._period + (int(rng.integers(0, self._jitter + 1)) if self._jitter else 0)

    def advance(self, tick: int, end: int, state: np.ndarray, force: np.ndarray, energy: float,
                start: np.ndarray) -> tuple[np.ndarray, float]:
        """Integrate from `tick` to `end` under a constant force; record; return the end state."""
        count = end - tick
        axes = self.device.axes
        target = axes @ (self.hand.target(tick * self.timing.substep) - start)
        drive = axes @ force + self.hand.stiffness * target
        states = np.einsum('jab,bd->jad', self._transition[:count], state) \
            + self._input[:count, :, None] * drive
        generalised = axes @ force
        energies = energy - (states[:, 0] - state[0]) @ generalised
        self._states[tick + 1:end + 1] = states
        self._force[tick:end] = force
        self._energy[tick + 1:end + 1] = energies
        return states[-1], float(energies[-1])

    def result(self, start: np.ndarray, samples: np.ndarray) -> WallRun:
        """Return the recorded series as a `WallRun`."""
        axes = self.device.axes
        self._force[-1] = self._force[-2]
        return WallRun(
            time=np.arange(self.steps + 1) * self.timing.substep,
            position=start + self._states[:, 0] @ axes,
            velocity=self._states[:, 1] @ axes,
            force=self._force,
            port_energy=self._energy,
            sample_time=samples)


def _transitions(device: Device, hand: OperatorHand, substep: float,
                 count: int) -> tuple[np.ndarray, np.ndarray]:
    """Exact transition matrices Φ(j·h) (count, 2, 2) and input vectors Γ(j·h) (count, 2).

    Per axis, m q̈ = u − (b + b_h) q̇ − k_h q with the input u held constant over the piece.
    """
    system = np.zeros((3, 3))
    system[0, 1] = 1.0
    system[1, 0] = -hand.stiffness / device.mass
    system[1, 1] = -(device.damping + hand.damping) / device.mass
    system[1, 2] = 1.0 / device.mass
    one = expm(system * substep)
    transition = np.empty((count, 2, 2))
    inputs = np.empty((count, 2))
    transition[0], inputs[0] = one[:2, :2], one[:2, 2]
    for j in range(1, count):
        transition[j] = one[:2, :2] @ transition[j - 1]
        inputs[j] = one[:2, :2] @ inputs[j - 1] + inputs[0]
    return transition, inputs


def _measure(wall: SignedDistance, device: Device, start: np.ndarray, state: np.ndarray,
             now: float, give_velocity: bool) -> tuple[Contact, np.ndarray | None]:
    """Return what the renderer receives at a servo instant: collision state and twist."""
    tip = start + state[0] @ device.axes
    distance, normal = wall(tip)
    normal = np.asarray(normal, dtype=np.float64)
    contact = Contact(distance, tip - distance * normal, normal, tip, 'wall', now)
    return contact, (state[1] @ device.axes if give_velocity else None)
