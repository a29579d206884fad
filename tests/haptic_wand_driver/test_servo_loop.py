"""The compiled servo loop against its reference: the wand's Python substeps with the same law.

Two simulated wands, the same hand, the same models at the same instants. One is given its
``LocalRenderer`` as the driver gives it (compiled, ``servo_loop``); the other the same law behind
a wrapper, which the wand runs in its Python loop through ``LocalRenderer.wrench``. Random
models: up to three planes, tilted, with tool points off the tip (torque), stiff enough to
saturate and to wake the port's passivity, met with the tip inside (the port's bound moves them
out), valid for less than a tick or until the radius is left; held wrenches; a model dropped.
Every state, force, energy and shift must be the same float.
"""
import math

from contact_model_fields import fields
import numpy as np
import pytest

from haptic_contract.contact_model import ContactModel, Kind
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.port_passivity import PortPassivity
from haptic_wand_driver.simulated import SimulatedWand, SimulatedWandConfig
from simulated_operator.hand import OperatorHand

TICK = 0.001  # [s]
TICKS = 400


class _Sweep:
    """A hand's target moving on every joint: down through z = 0, rolling and yawing."""

    def target_components(self, t):
        w = 2.0 * math.pi
        return ((0.01 * math.sin(w * t), 0.005 * math.cos(w * t), 0.004 - 0.03 * t,
                 0.4 * math.sin(w * t), 0.3 * math.cos(w * t)),
                (0.01 * w * math.cos(w * t), -0.005 * w * math.sin(w * t), -0.03,
                 0.4 * w * math.cos(w * t), -0.3 * w * math.sin(w * t)))


class _Python:
    """The same law, hidden from the wand's compiled path."""

    def __init__(self, law: LocalRenderer) -> None:
        self.law = law

    def wrench(self, *args):
        return self.law.wrench(*args)


def _renderer(ratio: float, rate: float = 0.0) -> LocalRenderer:
    return LocalRenderer(force_limit=8.0, torque_limit=0.3,
                         passivity=PortPassivity(max_damping=50.0), mass=(0.15, 0.12, 0.18),
                         contact_damping_ratio=ratio, model_step_rate=rate)


def _random_plane(rng, tip):
    normal = rng.normal(size=3) + (0.0, 0.0, 2.0)
    normal /= np.linalg.norm(normal)
    point = np.asarray(tip) + rng.uniform(-0.003, 0.003, size=3)
    stiffness = 10.0 ** rng.uniform(2.0, 5.5, size=3)
    damping = rng.uniform(0.0, 5.0, size=3)
    tool_point = rng.uniform(-0.02, 0.02, size=3) * (rng.random() < 0.7)
    return tuple(map(tuple, (point, normal, stiffness, damping, tool_point)))


def _give(law: LocalRenderer, rng, tip, now: float, since: float = -math.inf) -> None:
    """Hand the law what the loop might, from ``since``: a model, a held wrench, or nothing."""
    choice = rng.random()
    deadline = now + rng.choice([0.0004, 0.0011, 0.003, math.inf])
    if choice < 0.1:
        law.clear(since)
    elif choice < 0.25:
        law.take_wrench(rng.uniform(-12.0, 12.0, size=3), rng.uniform(-0.5, 0.5, size=3),
                        deadline, since)
    else:
        count = int(rng.integers(0, 4))
        kind = Kind.PLANES if count else Kind.FREE
        planes = [_random_plane(rng, tip) for _ in range(count)]
        model = ContactModel.from_fields(
            fields(planes, kind=kind, limit=float(rng.uniform(3.0, 12.0)),
                   radius=float(rng.choice([0.0005, 0.002, 0.05])), tip=tuple(tip)), 'world')
        law.take(model, deadline, since)


def _give_estimate(law: LocalRenderer, rng, tip, now: float, since: float = -math.inf) -> None:
    """Hand the law a remote site's estimate: one plane, its normal within a degree of up."""
    normal = rng.normal(size=3) * 0.01 + (0.0, 0.0, 1.0)
    plane = (tuple(np.asarray(tip) + (0.0, 0.0, rng.uniform(-0.002, 0.004))),
             tuple(normal / np.linalg.norm(normal)), (rng.uniform(100.0, 3000.0),) * 3,
             (rng.uniform(0.0, 5.0),) * 3, (0.0, 0.0, 0.0))
    law.take(ContactModel.from_fields(fields([plane], radius=0.05, tip=tuple(tip)), 'world'),
             now + 0.003, since)


def _wand(law, hand: bool = True) -> SimulatedWand:
    config = SimulatedWandConfig(initial_position=np.array([0.0, 0.0, 0.004]), initial_roll=0.1)
    wand = SimulatedWand(config, operator=OperatorHand(_Sweep()) if hand else None)
    wand.render_locally(law)
    return wand


def _row(wand: SimulatedWand, state, law: LocalRenderer) -> tuple:
    force, torque = wand.applied()
    return (*state.position, state.roll, state.yaw, *state.linear_velocity, state.roll_rate,
            state.yaw_rate, *force, *torque, law.passivity.energy, law.passivity.net_work,
            *law.bound[[0, 2, 3, 4, 5, 6]], *law.bound[7:])


def _run(seed: int, ratio: float, hand: bool, rate: float = 0.0, give=_give):
    laws = [_renderer(ratio, rate), _renderer(ratio, rate)]
    wands = [_wand(laws[0], hand), _wand(_Python(laws[1]), hand)]
    assert wands[0]._compiled is not None and wands[1]._compiled is None  # the two paths
    rng = np.random.default_rng(seed)
    rows = [[], []]
    for tick in range(TICKS):
        now = tick * TICK + rng.uniform(0.0, 0.0006)  # reads at jittered instants
        states = [wand.read(now) for wand in wands]
        tip = states[0].position.tolist()
        # From the next period, or from one up to 0.3 ms later (before the next read).
        since = -math.inf if rng.random() < 0.5 else now + rng.uniform(0.0, 0.0003)
        draw = rng.bit_generator.state
        for law, row, wand, state in zip(laws, rows, wands, states):
            rng.bit_generator.state = draw  # the same model for both
            give(law, rng, tip, now, since)
            row.append(_row(wand, state, law))
    return np.array(rows), [wand.force_edges for wand in wands]


@pytest.mark.parametrize('seed', range(6))
@pytest.mark.parametrize('ratio, rate', [(0.0, 0.0), (1.0, 0.0), (1.0, 5.0), (0.0, 50.0)])
def test_the_compiled_loop_gives_its_reference_trajectory_float_for_float(seed, ratio, rate):
    """With the models switched at once, and eased in (``model_easing``)."""
    (compiled, reference), (edges, reference_edges) = _run(seed, ratio, hand=seed % 3 != 2,
                                                           rate=rate)
    assert np.array_equal(compiled, reference)
    assert edges == reference_edges


def test_the_runs_compared_press_rotate_saturate_and_wake_the_passivity():
    """What the comparison covers: contact on and off, torque, saturation, energy taken out."""
    (compiled, _), (edges, _) = _run(0, 1.0, hand=True)
    force, torque = compiled[:, 10:13], compiled[:, 13:16]
    assert len(edges) >= 6
    assert np.abs(compiled[:, 3:5]).max() > 0.1  # rolled and yawed
    assert np.linalg.norm(torque, axis=1).max() > 0.0
    assert np.linalg.norm(force, axis=1).max() > 7.9  # at the renderer's limits
    assert np.abs(compiled[:, 16]).max() > 0.0  # the passivity's books moved
    assert compiled[:, 18].max() > 0.0  # models met inside were moved out by the port's bound


def test_the_eased_runs_compared_match_pushes_scale_stiffnesses_and_shift_both_ways():
    (compiled, _), _ = _run(0, 1.0, hand=True, rate=5.0)
    shift, push, scale = compiled[:, 18], compiled[:, 19], compiled[:, 20]
    assert shift.min() < 0.0 < shift.max()
    assert push.max() > 0.0
    assert scale.min() < 1.0 < scale.max()


@pytest.mark.parametrize('seed', range(2))
def test_estimates_eased_in_turn_their_normals_in_both_loops_float_for_float(seed):
    """A new estimate every tick, its normal a fraction of a degree from the last one's."""
    (compiled, reference), _ = _run(seed, 1.0, hand=True, rate=5.0, give=_give_estimate)
    assert np.array_equal(compiled, reference)
    pressing = (compiled[:-1, 24] == 1.0) & (compiled[1:, 24] == 1.0) & (compiled[1:, 19] > 0.0)
    turns = np.arccos(np.clip(np.einsum('ij,ij->i', compiled[:-1, 25:28], compiled[1:, 25:28]),
                              -1.0, 1.0))[pressing]
    assert np.count_nonzero((turns > 0.0) & (turns < 2e-3)) > 10, turns  # turned, not taken


@pytest.mark.parametrize('seed', range(3))
def test_a_law_taken_at_an_instant_switches_where_advancing_the_wand_to_it_first_would(seed):
    """What the driver does instead of reading the wand at every answer: the same floats.

    A third wand takes each law at once, with no instant and no read: it renders it from its
    last read on, too early, and must differ.
    """
    laws = [_renderer(1.0) for _ in range(3)]
    wands = [_wand(law) for law in laws]
    rng = np.random.default_rng(seed)
    rows = [[], [], []]
    for tick in range(TICKS):
        now = tick * TICK
        states = [wand.read(now) for wand in wands]
        for row, wand, state, law in zip(rows, wands, states, laws):
            row.append(_row(wand, state, law))
        arrival = now + rng.uniform(0.0, 0.00095)
        wands[0].read(arrival)  # up to the arrival with the law it held
        draw = rng.bit_generator.state
        for law, since in zip(laws, (-math.inf, arrival, -math.inf)):
            rng.bit_generator.state = draw  # the same law for all three
            _give(law, rng, states[0].position.tolist(), arrival, since)
    advanced, taken_at, early = map(np.array, rows)
    assert np.array_equal(taken_at, advanced)
    assert wands[1].force_edges == wands[0].force_edges
    assert not np.array_equal(early, advanced)
