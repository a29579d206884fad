"""Conversions between builtin_interfaces/Time and integer nanoseconds, in one place."""
from builtin_interfaces.msg import Time

__all__ = ['to_stamp', 'to_nanoseconds']


def to_nanoseconds(stamp: Time) -> int:
    """Return a stamp as integer nanoseconds, exactly."""
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def to_stamp(nanoseconds: int) -> Time:
    """Build a stamp from integer nanoseconds."""
    sec, nanosec = divmod(int(nanoseconds), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)
