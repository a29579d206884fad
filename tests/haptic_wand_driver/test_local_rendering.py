"""The device-side law: what it renders and when it renders nothing, and a stiff tap through it.

The tap (``taps.py``) is the simulated wand pushed by a hand into a wall z < 0 and pulled back out,
the wall at K = 1e5 N/m: rendered by the device at its 4 kHz servo rate from a plane model, against
the same wall as a held wrench computed from the pose one 1 ms tick old (remote rendering in
miniature). Contacts are counted as the report counts them (a lift under 0.1 mm is no rebound).
"""
import math

from contact_model_fields import fields, plane
import pytest
from taps import tap

from haptic_wand_driver.contact_model import ContactModel, Kind
from haptic_wand_driver.local_rendering import LocalRenderer, MAX_DAMPING_PER_MASS
from haptic_wand_driver.port_passivity import PortPassivity

STILL = [0.0, 0.0, 0.0, 0.0, 0.0]
MASS = 0.15  # [kg] the simulated wand's default


def renderer(**options) -> LocalRenderer:
    return LocalRenderer(force_limit=10.0, torque_limit=0.5,
                         passivity=PortPassivity(max_damping=0.0), **options)


def wall(stiffness=1000.0, **options) -> ContactModel:
    return ContactModel.from_fields(fields([plane(stiffness=stiffness)], **options), 'world')


def at(z, vz=0.0):
    return [0.0, 0.0, z, 0.0, 0.0], [0.0, 0.0, vz, 0.0, 0.0]


def test_a_held_model_is_rendered_until_its_deadline_and_within_its_radius():
    law = renderer()
    law.take(wall(), deadline=2.0)
    assert law.wrench(1.0, *at(-0.002), 2.5e-4)[0] == pytest.approx((0.0, 0.0, 2.0))
    assert law.wrench(2.0, *at(-0.002), 2.5e-4)[0] == (0.0, 0.0, 0.0)  # expired
    far = [0.0, 0.0025, -0.002, 0.0, 0.0]  # 2.5 mm from the model's tip, radius 2 mm
    assert law.wrench(1.0, far, STILL, 2.5e-4)[0] == (0.0, 0.0, 0.0)


def test_nothing_is_rendered_without_a_model_or_from_a_free_one():
    law = renderer()
    assert law.wrench(0.0, *at(-0.002), 2.5e-4)[0] == (0.0, 0.0, 0.0)
    law.take(wall(kind=Kind.FREE), deadline=math.inf)
    assert law.wrench(0.0, *at(-0.002), 2.5e-4)[0] == (0.0, 0.0, 0.0)
    law.take(wall(), deadline=math.inf)
    law.clear()
    assert law.wrench(0.0, *at(-0.002), 2.5e-4)[0] == (0.0, 0.0, 0.0)


def test_the_force_is_saturated_to_the_lower_of_the_two_limits():
    law = renderer()
    law.take(wall(stiffness=1e5, limit=4.0), deadline=math.inf)
    assert law.wrench(0.0, *at(-0.001), 2.5e-4)[0] == pytest.approx((0.0, 0.0, 4.0))


def test_a_wrench_can_be_rendered_in_place_of_a_model():
    law = renderer()
    law.take_wrench((1.0, 0.0, 0.0), (0.0, 0.0, 0.1), deadline=1.0)
    assert law.wrench(0.5, *at(0.01), 2.5e-4) == ((1.0, 0.0, 0.0), (0.0, 0.0, 0.1))
    assert law.wrench(1.0, *at(0.01), 2.5e-4) == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


@pytest.mark.parametrize('speed', [-0.05, 0.05, 0.2])
def test_contact_damping_is_critical_on_the_device_mass_and_never_pulls(speed):
    law = renderer(mass=(MASS,) * 3, contact_damping_ratio=1.0)
    law.take(wall(stiffness=1e4), deadline=math.inf)
    force = law.wrench(0.0, *at(-0.0005, speed), 2.5e-4)[0]
    damping = 2.0 * math.sqrt(1e4 * MASS)  # 77 N*s/m, below the cap 0.5 m/T = 300
    assert damping < MAX_DAMPING_PER_MASS * MASS / 2.5e-4
    assert force[2] == pytest.approx(max(0.0, 5.0 - damping * speed))


def test_contact_damping_still_acts_on_a_wall_pressed_past_its_force_limit():
    law = renderer(mass=(MASS,) * 3, contact_damping_ratio=1.0)
    law.take(wall(stiffness=1e5), deadline=math.inf)  # at 0.3 mm the spring alone is 30 N
    damping = 2.0 * math.sqrt(1e5 * MASS)  # 245 N*s/m
    going_in = law.wrench(0.0, *at(-0.0003, -0.02), 2.5e-4)[0]
    coming_out = law.wrench(0.0, *at(-0.0003, 0.02), 2.5e-4)[0]
    assert going_in[2] == pytest.approx(10.0)
    assert coming_out[2] == pytest.approx(10.0 - damping * 0.02)  # less out than in: dissipative


def test_a_stiff_tap_rendered_on_the_device_stays_one_contact_and_gives_no_energy():
    local, remote = tap(1e5, local=True), tap(1e5, local=False)
    assert local.contacts == 1 and local.work <= 0.0, local
    assert remote.contacts > 1, remote  # the baseline rebounds: the comparison can fail


def test_the_force_is_felt_one_servo_period_after_the_tip_enters_at_most():
    assert 0.0 < tap(5e3, local=True).felt_latency <= 2.5e-4
    assert tap(5e3, local=False).felt_latency > 1e-3  # a tick and a round trip
