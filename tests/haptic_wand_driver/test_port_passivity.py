"""The device-port passivity observer and controller: its books, and what it may and may not do."""
import math

import numpy as np
import pytest

from haptic_wand_driver.port_passivity import BOOKS_CLOSE_AFTER, bounded_shift, PortPassivity


def test_observing_the_same_position_twice_books_nothing_more():
    port = PortPassivity(max_damping=0.0)
    port.control((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    port.observe((-0.002, 0.0, 0.0))
    port.control((1.0, 0.0, 0.0), (-0.002, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    assert port.energy == pytest.approx(0.002)


def test_the_observer_books_minus_the_work_of_the_held_force():
    port = PortPassivity(max_damping=0.0)
    port.control((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    port.control((2.0, 0.0, 0.0), (0.001, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)  # 1 N over +1 mm
    port.control((2.0, 0.0, 0.0), (0.0005, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)  # 2 N over -0.5 mm
    assert port.energy == pytest.approx(-1.0 * 0.001 + 2.0 * 0.0005)
    assert port.net_work == pytest.approx(1.0 * 0.001 - 2.0 * 0.0005)


def test_a_deficit_is_dissipated_along_the_force_only():
    """A tip leaving a wall and sliding: the push drops, and no sideways force appears."""
    port = PortPassivity(max_damping=1000.0)
    port.control((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    velocity = (0.05, 0.0, -0.1)  # out along the push (+x), and sliding along -z
    force = port.control((1.0, 0.0, 0.0), (0.002, 0.0, 0.0), velocity, 0.001)
    deficit = 1.0 * 0.002 + 1.0 * 0.05 * 0.001  # 2 mJ done, and the coming period's work
    alpha = deficit / (0.001 * 0.05 ** 2)
    assert force == pytest.approx((max(0.0, 1.0 - alpha * 0.05), 0.0, 0.0))
    assert force[1] == force[2] == 0.0


def test_a_residue_the_tip_moves_against_is_never_amplified():
    port = PortPassivity(max_damping=1000.0)
    port.control((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    port.control((0.0, 0.0, 1.0), (0.0, 0.0, 0.003), (0.0, 0.0, 0.063), 0.001)  # a deficit
    residue = (-0.005, 0.0, 0.0002)  # the damper's sideways leftover as the contact ends
    force = port.control(residue, (0.0, 0.0, 0.003), (0.03, 0.0, 0.063), 0.001)
    assert force == residue  # the tip moves against it: it takes energy in, nothing is added


def test_damping_is_capped_and_never_turns_the_force_round():
    port = PortPassivity(max_damping=1e6)
    port.control((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    force = port.control((0.0, 0.0, 1.0), (0.0, 0.0, 0.01), (0.0, 0.0, 0.5), 0.001)
    assert force[2] == pytest.approx(0.0, abs=1e-12)  # cancelled, not reversed
    capped = PortPassivity(max_damping=2.0)
    capped.control((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    force = capped.control((0.0, 0.0, 1.0), (0.0, 0.0, 0.01), (0.0, 0.0, 0.1), 0.001)
    assert force[2] == pytest.approx(1.0 - 2.0 * 0.1)


def test_the_books_close_after_a_break_in_contact_not_at_a_bounce():
    port = PortPassivity(max_damping=100.0)
    port.control((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    port.control((0.0, 0.0, 0.0), (0.003, 0.0, 0.0), (0.1, 0.0, 0.0), 0.001)
    assert port.energy == pytest.approx(-0.003)  # a bounce: the deficit stays
    for _ in range(round(BOOKS_CLOSE_AFTER / 0.001)):
        port.control((0.0, 0.0, 0.0), (0.003, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    assert port.energy == 0.0  # a break: the next touch is another contact
    # A push against a tip coming in takes energy in: it passes untouched.
    assert port.control((1.0, 0.0, 0.0), (0.003, 0.0, 0.0), (-0.1, 0.0, 0.0), 0.001) == \
        (1.0, 0.0, 0.0)


def test_a_push_that_would_give_energy_it_never_took_is_damped():
    fast = PortPassivity(max_damping=100.0)
    fast.control((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    assert fast.control((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.1, 0.0, 0.0), 0.001)[0] == \
        pytest.approx(0.0, abs=1e-12)
    # A slow tip is only slowed, at most max_damping: a wall still pushes out a tip inside it.
    slow = PortPassivity(max_damping=50.0)
    slow.control((1.6, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    assert slow.control((1.6, 0.0, 0.0), (0.0, 0.0, 0.0), (0.01, 0.0, 0.0), 0.001)[0] == \
        pytest.approx(1.6 - 50.0 * 0.01)


def bounce(k: float, delay_steps: int, port) -> float:
    """A 0.15 kg tip dropped at 0.2 m/s on a wall at z = 0, the wall force one step late; return
    the work the applied force did on the tip (J) over 1 s."""
    mass, period, substeps = 0.15, 0.001, 20
    z, v, work = 0.005, -0.2, 0.0
    pending = [0.0] * (delay_steps + 1)
    for _ in range(1000):
        pending.append(k * max(-z, 0.0))
        force = pending.pop(0)
        if port is not None:
            force = port.control((0.0, 0.0, force), (0.0, 0.0, z), (0.0, 0.0, v), period)[2]
        for _ in range(substeps):
            dt = period / substeps
            v += dt * (force - 0.5) / mass  # a hand pressing down with 0.5 N
            z += dt * v
            work += force * v * dt
    return work


def test_with_a_late_stiff_wall_it_removes_the_energy_the_delay_creates():
    free = bounce(5000.0, 1, None)
    controlled = bounce(5000.0, 1, PortPassivity(max_damping=100.0))
    assert free > 1e-4  # the delayed wall pushes back harder than it was pushed: active
    assert controlled < 0.02 * free
    assert math.isfinite(controlled)


def stored(springs, shift: float) -> float:
    """Energy (J) in springs (depth m, stiffness N/m) moved out by ``shift``, summed plainly."""
    return sum(0.5 * k * max(d - shift, 0.0) ** 2 for d, k in springs if k > 0.0)


def least_shift(springs, energy: float) -> float:
    """The least shift storing at most ``energy``, by bisection on ``stored`` (ground truth)."""
    low, high = 0.0, max([d for d, _ in springs] + [0.0])
    if stored(springs, low) <= energy:
        return 0.0
    for _ in range(200):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if stored(springs, middle) > energy else (low, middle)
    return high


def test_one_plane_moves_out_to_the_depth_its_energy_allows():
    allowed = math.sqrt(2 * 0.005 / 400)  # the depth at which 400 N/m stores 5 mJ
    assert bounded_shift([(0.01, 400.0)], 0.005) == pytest.approx(0.01 - allowed)
    assert bounded_shift([(0.01, 400.0)], 0.0) == pytest.approx(0.01)
    assert bounded_shift([(0.01, 400.0)], 0.02) == 0.0  # 0.02 J covers the 0.02 J it stores
    assert bounded_shift([(0.01, 400.0)], -0.001) == pytest.approx(0.01)  # a deficit: none


@pytest.mark.parametrize('seed', range(20))
def test_several_planes_move_out_together_as_far_as_the_energy_requires(seed):
    rng = np.random.default_rng(seed)
    springs = [(float(rng.uniform(-0.005, 0.02)), float(10.0 ** rng.uniform(1.0, 5.0)))
               for _ in range(int(rng.integers(1, 4)))]
    energy = float(rng.uniform(0.0, 1.2) * stored(springs, 0.0))
    shift = bounded_shift(springs, energy)
    assert shift == pytest.approx(least_shift(springs, energy), abs=1e-9)
    assert stored(springs, shift) <= energy * (1.0 + 1e-9) + 1e-15


def test_planes_in_front_or_without_stiffness_store_nothing_and_move_nothing():
    assert bounded_shift([(-0.01, 400.0), (0.01, 0.0)], 0.0) == 0.0
    assert bounded_shift([], 0.0) == 0.0


def test_a_lapse_of_the_watchdog_keeps_the_contact_s_books():
    """Zero force because no law was alive is no break in contact: the books stay open."""
    port = PortPassivity(max_damping=0.0)
    port.control((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.001)
    port.control((0.0, 0.0, 1.0), (0.0, 0.0, -0.002), (0.0, 0.0, 0.0), 0.001)  # 2 mJ taken in
    for _ in range(2 * round(BOOKS_CLOSE_AFTER / 0.001)):
        port.control((0.0, 0.0, 0.0), (0.0, 0.0, -0.002), (0.0, 0.0, 0.0), 0.001, lapsed=True)
    assert port.energy == pytest.approx(0.002)
