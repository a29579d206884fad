"""The driver node's wiring, in-process: what its clocks do, without a launched loop."""
import itertools

import pytest
import rclpy
from rclpy.context import Context

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
