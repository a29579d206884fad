"""Integer nanoseconds: stamps both ways, and a clock's read as Clock.now would give it."""
from rclpy.clock import Clock, ClockType, ROSClock
from rclpy.time import Time

from haptic_util.stamps import clock_ns, to_nanoseconds, to_stamp


def test_a_stamp_goes_to_nanoseconds_and_back_exactly():
    nanoseconds = 1_764_012_345_678_901_234
    assert to_nanoseconds(to_stamp(nanoseconds)) == nanoseconds


def test_the_clock_read_falls_between_two_reads_of_clock_now():
    for clock in (Clock(clock_type=ClockType.SYSTEM_TIME),
                  Clock(clock_type=ClockType.STEADY_TIME), ROSClock()):
        before = clock.now().nanoseconds
        read = clock_ns(clock)
        assert before <= read <= clock.now().nanoseconds


def test_with_simulated_time_the_clock_read_is_the_simulated_time():
    clock = ROSClock()
    clock._set_ros_time_is_active(True)
    clock.set_ros_time_override(Time(seconds=42, nanoseconds=7))
    assert clock_ns(clock) == clock.now().nanoseconds == 42_000_000_007
