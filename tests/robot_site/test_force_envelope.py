"""The clinical force envelope against an operator who jabs, measured at the patient.

Every figure is the force the tissue put on the probe (the simulated patient's, not the
safety's books): its rate of rise, its ramp after the first touch, and the hard stop.
"""
import math

import numpy as np
import pytest
from test_safety import RemoteSite, TICK

from robot_site.force_envelope import EnvelopeConfig, ForceEnvelope
from robot_site.impedance_robot import ImpedanceRobot, ImpedanceRobotConfig
from robot_site.tissue import HuntCrossley, Tissue

OFF = EnvelopeConfig(hard_stop=math.inf, rise_rate=math.inf, contact_ramp=0.0)
ON = EnvelopeConfig()
SKIN_PRESS = -0.004  # [m] a press of a few newtons on the abdomen


def jab(t: float) -> list:
    """The operator presses lightly, then jabs 3 cm in for half a second, every second."""
    deep = t > 1.5 and (t % 1.0) < 0.5
    return [0.0, 0.0, -0.03 if deep else SKIN_PRESS]


def rise_rate(forces: np.ndarray, window: float = 0.005) -> float:
    """Return the peak rate of rise (N/s) of ``forces`` over ``window`` s (the sensor's noise)."""
    steps = round(window / TICK)
    return float(np.max(forces[steps:] - forces[:-steps]) / window)


def test_a_jab_reaches_the_patient_at_the_envelopes_rate_not_at_once():
    forces = {name: RemoteSite([0.0, 0.0, 0.01], envelope=config).run(4.0, jab)
              for name, config in (('off', OFF), ('on', ON))}
    assert rise_rate(forces['off']) > 2.0 * ON.rise_rate  # the jab, as the robot takes it
    # The spring rises at the rate; the tissue's own damping adds a little (6 % here).
    assert rise_rate(forces['on']) <= 1.1 * ON.rise_rate
    assert rise_rate(forces['on'], TICK) <= 1.1 * ON.rise_rate
    assert forces['on'][1500:].max() > 10.0  # and the jabs do press


def test_the_first_touch_ramps_the_force_in():
    """A target 5 cm inside from 1 cm above: the force at the patient stays under the ramp.

    Above it by the approach's momentum at the touch at most (0.66 N here).
    """
    site = RemoteSite([0.0, 0.0, 0.01], envelope=ON)
    forces = site.run(3.0, lambda t: [0.0, 0.0, -0.05])
    free = RemoteSite([0.0, 0.0, 0.01], envelope=OFF).run(3.0, lambda t: [0.0, 0.0, -0.05])
    touched = int(np.argmax(forces > ON.contact_force))
    after = (np.arange(len(forces)) - touched) * TICK
    limit = 19.0  # the working limit: 20 N less the margin
    ramp = ON.contact_force + (limit - ON.contact_force) * after / ON.contact_ramp
    assert np.all(forces[touched:] <= ramp[touched:] + 1.0)
    assert forces[-1] == pytest.approx(limit, rel=0.01)
    reached = int(np.argmax(forces > 0.9 * limit)) - touched
    reached_free = int(np.argmax(free > 0.9 * limit)) - int(np.argmax(free > ON.contact_force))
    assert reached * TICK >= 0.7 * ON.contact_ramp > 2 * reached_free * TICK


class StiffSpot(RemoteSite):
    """The same site on a stiff spot (a rib under thin tissue): an impact past the hard stop."""

    def __init__(self, start, **safety):
        super().__init__(start, **safety)
        config = ImpedanceRobotConfig(initial_position=start)
        self.robot = ImpedanceRobot(config, environment=Tissue(
            HuntCrossley(stiffness=2e5, exponent=1.0, damping=0.0)))
        self.state = self.robot.read(0.0)


def test_a_jab_into_a_stiff_spot_stops_the_robot_until_it_is_re_engaged():
    site = StiffSpot([0.0, 0.0, 0.02], envelope=ON)
    struck = site.run(1.5, lambda t: [0.0, 0.0, -0.03])  # down at full speed: the impact
    assert struck.max() >= ON.hard_stop
    assert site.safety.envelope.stopped and site.safety.holding
    stopped = site.run(2.0, jab)  # the operator jabs on: nothing reaches the patient
    assert stopped[500:].max() <= site.safety.config.release_force
    assert site.state.external_force[2] <= site.safety.config.release_force  # let go
    site.safety.re_engage()
    assert not site.safety.envelope.stopped
    pressed = site.run(3.0, lambda t: [0.0, 0.0, -0.0067])  # then a press: the spring's 10 N
    assert pressed[-1] == pytest.approx(10.0, rel=0.05)
    assert pressed.max() < ON.hard_stop


def test_re_engaging_is_refused_while_the_probe_still_presses():
    envelope = ForceEnvelope(ON, 19.0)
    assert envelope.trip(31.0)
    assert not envelope.re_engage(5.0)
    assert envelope.trip(0.5)  # still latched
    assert envelope.stopped
    assert envelope.re_engage(0.5)


@pytest.mark.parametrize('field, value', [('hard_stop', 0.0), ('rise_rate', -1.0),
                                          ('rise_rate', math.nan), ('contact_ramp', -0.1)])
def test_a_bad_envelope_is_refused(field, value):
    with pytest.raises(ValueError, match=field):
        EnvelopeConfig(**{field: value})


def test_a_hard_stop_under_the_working_limit_is_refused():
    with pytest.raises(ValueError, match='hard_stop'):
        ForceEnvelope(EnvelopeConfig(hard_stop=15.0), 19.0)
