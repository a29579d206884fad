"""The driver node's wiring, in-process: what its clocks do, without a launched loop."""
import itertools

from contact_model_fields import fields
import pytest
import rclpy
from rclpy.context import Context

from haptic_wand_driver.contact_model import Kind
from haptic_wand_driver.node import WandDriverNode


class JumpingClock:
    """ROS time that goes 1 ms forward per reading, then 10 s back once, as NTP may step it."""

    def __init__(self) -> None:
        self._readings = itertools.count()

    def now(self):
        k = next(self._readings)
        return type('Time', (), {'nanoseconds': 1_800_000_000_000_000_000 + k * 1_000_000
                                 - (10_000_000_000 if k > 50 else 0)})()


@pytest.fixture
def driver():
    context = Context()
    rclpy.init(context=context, domain_id=98)
    node = WandDriverNode(context=context, parameter_overrides=[
        rclpy.parameter.Parameter('experiment', value='hold'),
        rclpy.parameter.Parameter('wait_for_wrench', value=False),
        rclpy.parameter.Parameter('min_subscribers', value=0)])
    yield node
    node.destroy_node()
    rclpy.try_shutdown(context=context)


def test_a_backward_step_of_the_system_clock_does_not_stop_the_wand(driver, monkeypatch):
    clock = JumpingClock()
    monkeypatch.setattr(driver, 'get_clock', lambda: clock)
    for _ in range(100):  # through the step back at the 51st reading
        driver.tick()
    assert driver.stats.poses > 90


def test_rendering_locally_it_takes_the_model_alone_and_holds_the_wrench_of_a_law_without_one(
        driver):
    assert {s.topic_name for s in driver.subscriptions} == {'/wand/contact_model'}
    driver.tick()  # open loop: the session runs from the first tick
    pose = driver._last_probe_ns  # the stamp of the pose just published, which it answers
    model = fields(kind=Kind.UNAVAILABLE, stamp=divmod(pose, 1_000_000_000),
                   wrench=(1.0, 0.0, -0.5, 0.0, 0.0, 0.0))
    driver.on_model(model)
    state = driver.device.read(driver._device_time())
    force, torque = driver.renderer.wrench(driver._device_time(), [*state.position, 0.0, 0.0],
                                           [0.0] * 5, 2.5e-4)
    assert force == pytest.approx((1.0, 0.0, -0.5)) and torque == (0.0, 0.0, 0.0)
    assert driver.stats.answers == 1
