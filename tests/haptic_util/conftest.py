"""Fixtures of the haptic_util tests that make ROS entities."""
from domains import session_domain_id
import pytest
import rclpy
from rclpy.context import Context


@pytest.fixture
def context():
    """Yield an rclpy context of its own, on the session's domain; shut it down after."""
    context = Context()
    rclpy.init(context=context, domain_id=session_domain_id())
    yield context
    rclpy.try_shutdown(context=context)
