"""The virtual coupling between TDPA's port and the wand: it passes a steady force, and gives the
hand no energy of its own.

What "no energy" can mean for a force held over a step: the coupling sees the wand's position and
velocity at the step's start, and its force is held until the next. With any gains its config
admits, it gives the wand no energy when the wand keeps that velocity over the step, whatever the
velocities from step to step. A velocity that changes within the step is beyond any held force,
fixed before the motion that decides the sign of its work, and no bound on the hand's motion
removes that, it only shrinks it: a hand turning round as the coupling engages gets +4.9e-8 J
at 1 g, +4.9e-12 J on a 5 Hz, 0.3 m/s motion. That energy of the hold is the device's to
dissipate, by its own damping and its port's passivity controller (``haptic_wand_driver.
port_passivity``; the sampled spring's K·T/2 in ``force_renderer.passivity`` is the same effect).
"""
from hypothesis import example, given, strategies as st, target
import numpy as np
import pytest
from scipy.linalg import toeplitz

from teleop_leader.virtual_coupling import CouplingConfig, VirtualCoupling

DT = 1e-3  # [s] the leader's tick


def test_a_steady_port_force_reaches_a_held_wand_whole():
    coupling = VirtualCoupling(CouplingConfig(), np.zeros(3))
    port = np.array([0.5, -1.0, 2.5])
    for _ in range(3000):
        felt = coupling.step(port, np.zeros(3), np.zeros(3), DT)
    np.testing.assert_allclose(felt, port, atol=1e-9)


def test_the_mass_starts_at_rest_where_the_wand_is():
    """No force at first, and no energy of its own to give."""
    coupling = VirtualCoupling(CouplingConfig(), [0.1, 0.0, 0.0])
    first = coupling.step(np.zeros(3), [0.1, 0.0, 0.0], np.zeros(3), DT)
    np.testing.assert_array_equal(first, np.zeros(3))


# The velocities of a path (40 Hz, 0.37 m/s) whose held forces did +2.5e-8 J on the path itself.
@example([0.0, 0.012526407337705511, -0.3650611155989467, 0.3512516071267422],
         [35.37721479949942, 0.6546816775871278, 39.21894570499731, 0.5], DT)
@given(st.lists(st.floats(-0.5, 0.5), min_size=4, max_size=4),
       st.lists(st.floats(0.5, 500.0), min_size=4, max_size=4),
       st.floats(1e-4, CouplingConfig().max_step))
def test_it_gives_the_hand_no_energy_it_did_not_take_from_it(amplitudes, frequencies, dt):
    """No port force, the wand at the velocities of a sum of sines up to 500 Hz (the 1 ms tick's
    Nyquist frequency), each kept over its step: the held forces' work never rises above zero."""
    coupling = VirtualCoupling(CouplingConfig(), np.zeros(3))
    times = np.arange(3000) * dt
    velocities = sum(a * np.cos(2 * np.pi * f * times) for a, f in zip(amplitudes, frequencies))
    wand, work, most = 0.0, 0.0, -np.inf
    for velocity in velocities:
        force = coupling.step(np.zeros(3), [wand, 0.0, 0.0], [velocity, 0.0, 0.0], dt)
        work += force[0] * velocity * dt
        wand += velocity * dt
        most = max(most, work)
    target(most)
    assert most <= 0.0


def _largest_work_per_square_velocity(config: CouplingConfig, step: float,
                                      ticks: int = 1000) -> float:
    """Return max over every sequence u of ``ticks`` velocities of work / (|u|^2 step), N·s/m.

    With no port force the coupling at rest is linear and time-invariant in the wand's velocity,
    so each step's force is the convolution of the velocities with one impulse response and the
    work a quadratic form in them, whose largest eigenvalue bounds the work of every sequence.
    """
    coupling = VirtualCoupling(config, np.zeros(3))
    impulse = [coupling.step(np.zeros(3), np.zeros(3), [1.0, 0.0, 0.0], step)[0]]
    impulse += [coupling.step(np.zeros(3), [step, 0.0, 0.0], np.zeros(3), step)[0]
                for _ in range(ticks - 1)]
    forces = toeplitz(impulse, np.zeros(ticks))  # row k: the force of step k per velocity
    return float(np.linalg.eigvalsh((forces + forces.T) / 2.0)[-1])


EDGES = [{}, {'stiffness': 17_900.0}, {'damping': 99.4}, {'ground_damping': 0.0}]


@pytest.mark.parametrize('gains', EDGES)
def test_no_sequence_of_velocities_draws_energy_from_it(gains):
    """The leader's gains and gains just inside each bound: jumps included, over 1000 steps."""
    config = CouplingConfig(**gains)
    assert _largest_work_per_square_velocity(config, config.max_step) <= 0.0


@pytest.mark.parametrize('gains', EDGES)
def test_stepped_past_its_bounds_the_same_coupling_gives_energy(gains):
    """5 % past the longest step its gains are passive for, each gives energy: the bounds are
    where the coupling's own numbers put them, and the check can fail."""
    config = CouplingConfig(**gains)
    longest = min(2.0 * config.damping / config.stiffness,
                  config.mass / (config.damping + config.ground_damping / 2.0))
    assert _largest_work_per_square_velocity(config, 1.05 * longest) > 0.0


@st.composite
def admitted_gains(draw) -> CouplingConfig:
    """Gains the config admits for a 1 ms step, short of its bounds by 0.1 % at least."""
    mass = draw(st.floats(0.01, 10.0))
    fraction = st.floats(0.0, 0.999)
    ground = draw(fraction) * 2.0 * mass / DT
    damping = draw(fraction) * (mass / DT - ground / 2.0)
    return CouplingConfig(mass, draw(fraction) * 2.0 * damping / DT, damping, ground, DT)


@given(admitted_gains())
def test_no_admitted_gains_draw_energy(config):
    assert _largest_work_per_square_velocity(config, DT, ticks=300) <= 0.0


@pytest.mark.parametrize('field, value', [('mass', 0.0), ('stiffness', -1.0),
                                          ('damping', float('nan')), ('stiffness', 18_100.0),
                                          ('damping', 99.6)])
def test_a_coupling_that_is_not_physical_or_not_passive_sampled_is_refused(field, value):
    with pytest.raises(ValueError, match=field):
        CouplingConfig(**{field: value})
