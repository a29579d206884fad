"""A process's timers start at one instant, so that those of one period fire in one wake."""
import time

import rclpy
from rclpy.context import Context
from rclpy.node import Node

from haptic_util.executor import align_timers


def test_timers_made_apart_are_due_together_and_one_made_not_to_start_stays_so():
    context = Context()
    rclpy.init(context=context, domain_id=98)
    try:
        robot, follower = Node('robot', context=context), Node('follower', context=context)
        ticks = [robot.create_timer(0.001, lambda: None)]
        time.sleep(0.0004)
        ticks.append(follower.create_timer(0.001, lambda: None))
        feedback = follower.create_timer(0.01, lambda: None)
        later = follower.create_timer(0.001, lambda: None, autostart=False)
        apart = abs(ticks[0].time_until_next_call() - ticks[1].time_until_next_call())
        align_timers([robot, follower])
        due = [timer.time_until_next_call() for timer in (*ticks, feedback)]
        assert apart > 300_000  # [ns]
        assert abs(due[0] - due[1]) < 100_000
        assert abs(due[2] - due[0] - 9_000_000) < 100_000  # its period later, in phase
        assert later.is_canceled()
    finally:
        rclpy.try_shutdown(context=context)
