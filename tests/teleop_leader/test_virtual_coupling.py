"""The virtual coupling between TDPA's port and the wand: it passes a steady force, and gives the
hand no energy of its own."""
from hypothesis import given, strategies as st
import numpy as np
import pytest

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


@given(st.lists(st.floats(-0.5, 0.5), min_size=4, max_size=4),
       st.lists(st.floats(0.5, 40.0), min_size=4, max_size=4))
def test_it_gives_the_hand_no_energy_it_did_not_take_from_it(amplitudes, frequencies):
    """No port force, the wand moving at will (a sum of sines, up to 40 Hz and 1.6 m/s): the
    work of the coupling on the wand, each force held over its tick, never rises above zero."""
    coupling = VirtualCoupling(CouplingConfig(), np.zeros(3))
    times = np.arange(3000) * DT
    path = sum(a / (2 * np.pi * f) * np.sin(2 * np.pi * f * times)
               for a, f in zip(amplitudes, frequencies))
    speed = sum(a * np.cos(2 * np.pi * f * times) for a, f in zip(amplitudes, frequencies))
    work = 0.0
    for k in range(len(times) - 1):
        wand = np.array([path[k], 0.0, 0.0])
        force = coupling.step(np.zeros(3), wand, [speed[k], 0.0, 0.0], DT)
        work += force[0] * (path[k + 1] - path[k])
        assert work <= 1e-12


@pytest.mark.parametrize('field, value', [('mass', 0.0), ('stiffness', -1.0),
                                          ('damping', float('nan'))])
def test_a_coupling_that_is_not_physical_is_refused(field, value):
    with pytest.raises(ValueError, match=field):
        CouplingConfig(**{field: value})
