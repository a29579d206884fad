"""The virtual coupling between TDPA's port and the wand: it passes a steady force, and gives the
hand no energy of its own.

What "no energy" can mean for a force held over a step: the coupling sees the wand's position and
velocity at the step's start, and its force is held until the next. With the leader's gains it
gives the wand no energy when the wand keeps that velocity over the step, whatever the velocities
from step to step. A velocity that changes within the step is beyond any held force, fixed before
the motion that decides the sign of its work, and no bound on the hand's motion removes that, it
only shrinks it: a hand turning round as the coupling engages gets +4.9e-8 J at 1 g, +4.9e-12 J on
a 5 Hz, 0.3 m/s motion. That energy of the hold is the device's to dissipate, by its own damping
and its port's passivity controller (``haptic_wand_driver.port_passivity``; the sampled spring's
K·T/2 in ``force_renderer.passivity`` is the same effect).
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


def _largest_work_per_square_velocity(config: CouplingConfig, ticks: int = 1000) -> float:
    """Return max over every sequence u of ``ticks`` velocities of work / (|u|^2 DT), N·s/m.

    With no port force the coupling at rest is linear and time-invariant in the wand's velocity,
    so each step's force is the convolution of the velocities with one impulse response and the
    work a quadratic form in them, whose largest eigenvalue bounds the work of every sequence.
    """
    coupling = VirtualCoupling(config, np.zeros(3))
    impulse = [coupling.step(np.zeros(3), np.zeros(3), [1.0, 0.0, 0.0], DT)[0]]
    impulse += [coupling.step(np.zeros(3), [DT, 0.0, 0.0], np.zeros(3), DT)[0]
                for _ in range(ticks - 1)]
    forces = toeplitz(impulse, np.zeros(ticks))  # row k: the force of step k per velocity
    return float(np.linalg.eigvalsh((forces + forces.T) / 2.0)[-1])


def test_no_sequence_of_velocities_draws_energy_from_it():
    """Jumps included, over a second of ticks."""
    assert _largest_work_per_square_velocity(CouplingConfig()) < 0.0


def test_the_check_sees_a_coupling_that_gives_energy():
    """A spring without its damper, held over each step, gives energy (Colgate's K·T/2): the check
    says so."""
    assert _largest_work_per_square_velocity(CouplingConfig(damping=0.0)) > 0.0


@pytest.mark.parametrize('field, value', [('mass', 0.0), ('stiffness', -1.0),
                                          ('damping', float('nan'))])
def test_a_coupling_that_is_not_physical_is_refused(field, value):
    with pytest.raises(ValueError, match=field):
        CouplingConfig(**{field: value})
