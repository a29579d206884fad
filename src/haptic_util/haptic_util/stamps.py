"""Time as integer nanoseconds: stamps (builtin_interfaces/Time) and clock reads, in one place."""
from builtin_interfaces.msg import Time
from rclpy.clock import Clock

__all__ = ['clock_ns', 'to_stamp', 'to_nanoseconds']


def clock_ns(clock: Clock) -> int:
    """Return the clock's time (ROS or simulated time alike) as integer nanoseconds.

    Why: ``Clock.now()`` builds a checked ``Time`` only to be asked for its integer; the 1 kHz
    paths read the clock several times a tick, and this same read of the same clock costs less
    than half as much (1.6 µs against 3.7 µs on the machine of ``docs/cpu_budget.md``).
    """
    handle = clock.handle
    with handle:  # as Clock.now: the clock must not be destroyed during the read
        return handle.get_now().nanoseconds


def to_nanoseconds(stamp: Time) -> int:
    """Return a stamp as integer nanoseconds, exactly."""
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def to_stamp(nanoseconds: int) -> Time:
    """Build a stamp from integer nanoseconds."""
    sec, nanosec = divmod(int(nanoseconds), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)
