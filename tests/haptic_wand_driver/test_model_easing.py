"""A new contact model eased into the hand: no step, and no energy the hand did not put in.

Measured from outside the law: the force it returned each servo period, and the work that force
did on the tip.
"""
import math

from contact_model_fields import fields, plane
import numpy as np
import pytest

from haptic_contract.contact_model import ContactModel
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.port_passivity import PortPassivity
from haptic_wand_driver.simulated import SimulatedWand, SimulatedWandConfig
from simulated_operator.hand import OperatorHand
from simulated_operator.scripts import WaypointScript

PERIOD = 2.5e-4  # [s]
RATE = 5.0  # [N/s]
MASS = 0.15  # [kg]


def wall(stiffness: float, height: float = 0.0, damping: float = 0.0) -> ContactModel:
    return ContactModel.from_fields(fields([plane(point=(0.0, 0.0, height), stiffness=stiffness,
                                                  damping=damping)], radius=1.0), 'world')


def law(rate: float) -> LocalRenderer:
    return LocalRenderer(force_limit=10.0, torque_limit=0.5,
                         passivity=PortPassivity(max_damping=0.0), model_step_rate=rate)


def at(z):
    return [0.0, 0.0, z, 0.0, 0.0], [0.0] * 5


def pressed(rate: float) -> LocalRenderer:
    """The tip pressed 2 mm into a 1000 N/m wall, from outside, 0.1 mm a period: 2 N."""
    renderer = law(rate)
    renderer.take(wall(1000.0), math.inf)
    for z in np.linspace(0.0005, -0.002, 26):
        renderer.wrench(0.0, *at(z), PERIOD)
    return renderer


@pytest.mark.parametrize('stiffness, height', [(500.0, 0.0005), (4000.0, -0.0005),
                                               (1000.0, -0.001)])
def test_a_new_model_goes_on_from_the_force_felt_and_eases_to_its_own(stiffness, height):
    """Softer and further out, stiffer and further in, moved in: each steps at once unless eased.

    Held still, the eased force changes by at most the rate (N/s) per period for the shift and as
    much for the stiffness, and reaches the model's own force as far as the energy allows: at
    least what the port absorbed, at most that or what the planes before stored (2 mJ).
    """
    stepped, eased = pressed(0.0), pressed(RATE)
    for renderer in (stepped, eased):
        renderer.take(wall(stiffness, height), math.inf)
    own = stiffness * (height + 0.002)
    assert stepped.wrench(0.0, *at(-0.002), PERIOD)[0][2] != pytest.approx(2.0, abs=0.1)
    forces = [eased.wrench(k * PERIOD, *at(-0.002), PERIOD)[0][2] for k in range(8000)]
    assert forces[0] == pytest.approx(2.0, abs=1e-9)
    assert np.abs(np.diff(forces)).max() <= 2.0 * RATE * PERIOD * (1.0 + 1e-9)
    absorbed, before = eased.passivity.energy, 0.5 * 1000.0 * 0.002 ** 2
    if 0.5 * own * own / stiffness <= absorbed:
        assert forces[-1] == pytest.approx(own, rel=1e-6)
    else:
        assert (math.sqrt(2.0 * stiffness * absorbed) * (1.0 - 1e-6) <= forces[-1]
                <= math.sqrt(2.0 * stiffness * max(absorbed, before)) * (1.0 + 1e-6))


def test_a_model_met_after_nothing_was_felt_ramps_in_from_zero():
    renderer = law(RATE)
    renderer.take(wall(1000.0), math.inf)
    forces = [renderer.wrench(k * PERIOD, *at(-0.002), PERIOD)[0][2] for k in range(4000)]
    assert forces[0] == 0.0
    assert np.diff(forces).max() <= RATE * PERIOD * (1.0 + 1e-9)
    assert forces[-1] == 0.0  # nothing was put in: nothing to push back with


def lapsed(depth: float, model: ContactModel) -> list:
    """Press 2 mm in (2 N), let the law lapse while the hand goes to ``depth``, take ``model``.

    Returns the force of each period after, the tip held at ``depth``.
    """
    renderer = law(RATE)
    renderer.take(wall(1000.0), deadline=0.0)
    for z in np.linspace(0.0005, -0.002, 26):
        renderer.wrench(-1.0, *at(z), PERIOD)
    for k, z in enumerate(np.linspace(-0.002, depth, 120)):  # 30 ms of nothing rendered
        assert renderer.wrench(k * PERIOD, *at(z), PERIOD)[0] == (0.0, 0.0, 0.0)
    renderer.take(model, math.inf)
    return [renderer.wrench(0.03 + k * PERIOD, *at(depth), PERIOD)[0][2] for k in range(400)]


def test_a_model_after_a_lapse_goes_on_from_the_force_felt_before_it():
    """The hand sank 12 mm while it felt nothing: it finds the 2 N it left, not a ramp from 0.

    A remote end that never saw the lapse keeps the patient pressed as before; the hand, ramped
    from zero, sank further and the robot followed it in (ci13). What the planes store is what
    they stored before the lapse, which the port had absorbed.
    """
    forces = lapsed(-0.014, wall(1000.0))
    assert forces[0] == pytest.approx(2.0, abs=1e-9)
    assert np.abs(np.diff(forces)).max() <= RATE * PERIOD * (1.0 + 1e-9)


def test_a_model_after_a_lapse_pushes_no_more_than_it_does_where_the_hand_now_is():
    """The hand left the wall during the lapse: no wall follows it out, it ramps in from zero.

    And one it is still 1 mm into, of the same stiffness, starts from its own 1 N.
    """
    left, into = lapsed(0.001, wall(1000.0)), lapsed(-0.001, wall(1000.0))
    assert left[0] == 0.0
    assert into[0] == pytest.approx(1.0, abs=1e-9)


def test_a_model_without_damping_goes_on_from_the_damping_felt_and_eases_it_out():
    """An estimate's damping clamped to zero, met by a hand pressing in at 1 cm/s.

    The damping felt (5 N·s/m: 0.05 N) drops at once unless eased. Eased, the force holds in the
    period of the switch (the planes matched to the push before), then each period's change is
    the spring's own (k·v·T) within the rate, and the damping is gone once eased out.
    """
    speed, spring_step = -0.01, 1000.0 * 0.01 * PERIOD  # m/s; N a period

    def pressing(rate: float) -> list:
        renderer = law(rate)
        renderer.take(wall(1000.0, damping=5.0), math.inf)
        heights = iter(np.arange(0.0005, -0.008, speed * PERIOD))
        forces = [renderer.wrench(0.0, [0.0, 0.0, next(heights), 0.0, 0.0],
                                  [0.0, 0.0, speed, 0.0, 0.0], PERIOD)[0][2] for _ in range(800)]
        renderer.take(wall(1000.0), math.inf)
        return forces + [renderer.wrench(0.0, [0.0, 0.0, z, 0.0, 0.0], [0.0, 0.0, speed, 0.0, 0.0],
                                         PERIOD)[0][2] for z in heights]

    stepped, eased = np.diff(pressing(0.0)), np.diff(pressing(RATE))
    assert stepped[799] - spring_step < -0.045  # the damping's 0.05 N, gone in one period
    assert eased[799] == pytest.approx(0.0, abs=1e-12)
    assert np.abs(eased[800:] - spring_step).max() <= RATE * PERIOD * (1.0 + 1e-9)
    assert eased[-1] == pytest.approx(spring_step, rel=1e-9)  # the model's own spring alone


class _Recording:
    """The law seen from the wand's servo loop: each period's height and force."""

    def __init__(self, renderer: LocalRenderer) -> None:
        self.law, self.rows = renderer, []

    def wrench(self, time_, coordinates, rates, period):
        force, torque = self.law.wrench(time_, coordinates, rates, period)
        self.rows.append((coordinates[2], force[2]))
        return force, torque


def press_through_new_estimates(rate: float, seed: int) -> np.ndarray:
    """A hand presses a wall for 2 s and lifts; every tick brings a new estimate of it.

    Each estimate moves the wall by up to ±1 mm and sets its stiffness between 300 and 3000 N/m,
    as a model-mediated link's estimates scatter. Returns each servo period's height and force.
    """
    renderer = LocalRenderer(force_limit=10.0, torque_limit=0.5,
                             passivity=PortPassivity(max_damping=50.0), mass=(MASS,) * 3,
                             contact_damping_ratio=1.0, model_step_rate=rate)
    recording = _Recording(renderer)
    script = WaypointScript.from_rows([(0.0, 0.0, 0.0, 0.005), (0.5, 0.0, 0.0, -0.02),
                                       (2.5, 0.0, 0.0, -0.02), (3.0, 0.0, 0.0, 0.005)])
    wand = SimulatedWand(SimulatedWandConfig(initial_position=np.array([0.0, 0.0, 0.005])),
                         operator=OperatorHand(script))
    wand.render_locally(recording)
    rng = np.random.default_rng(seed)
    for tick in range(3500):
        state = wand.read(tick * 0.001)
        renderer.take(wall(10.0 ** rng.uniform(2.5, 3.5), rng.uniform(-0.001, 0.001)),
                      tick * 0.001 + 0.010, state.time)
    return np.array(recording.rows)


@pytest.mark.parametrize('seed', range(2))
def test_scattered_estimates_eased_in_give_the_hand_no_energy_and_no_jolt(seed):
    """Judged while the hand holds (1 to 2.5 s): the tip's entry is a collision either way."""
    stepped = press_through_new_estimates(0.0, seed)
    eased = press_through_new_estimates(RATE, seed)
    for rows in (stepped, eased):
        assert np.sum(rows[:-1, 1] * np.diff(rows[:, 0])) <= 0.0  # work on the tip
    holding = slice(round(1.0 / PERIOD), round(2.5 / PERIOD))
    assert eased[holding, 1].min() > 0.5  # N: in contact throughout
    jolt = np.abs(np.diff(stepped[holding, 1])).max()
    step = np.abs(np.diff(eased[holding, 1])).max()
    assert jolt > 0.5  # N in one period
    assert step < jolt / 20.0


def test_the_shift_said_over_a_lapse_is_the_one_the_next_model_starts_from():
    """Pressed 2 mm (2 N), the law lapses and the hand sinks 12 mm: the planes are said to sit
    12 mm out, over the lapse (the robot holds where the hand felt the wall) and after it."""
    renderer = law(RATE)
    renderer.take(wall(1000.0), deadline=0.0)
    for z in np.linspace(0.0005, -0.002, 26):
        renderer.wrench(-1.0, *at(z), PERIOD)
    assert renderer.planes_shift(at(-0.002)[0]) == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
    for k, z in enumerate(np.linspace(-0.002, -0.014, 120)):
        renderer.wrench(k * PERIOD, *at(z), PERIOD)
    lapsed = renderer.planes_shift(at(-0.014)[0])
    renderer.take(wall(1000.0), math.inf)
    renderer.wrench(0.03, *at(-0.014), PERIOD)
    assert lapsed == pytest.approx((0.0, 0.0, 0.012))
    assert renderer.planes_shift(at(-0.014)[0]) == pytest.approx(lapsed)
