"""Conversions between builtin_interfaces/Time and float seconds, in one place."""
from builtin_interfaces.msg import Time

__all__ = ['to_seconds', 'to_stamp', 'to_nanoseconds']


def to_seconds(stamp: Time) -> float:
    """Return a stamp as float seconds (ns resolution is kept to ~0.2 µs for current epochs)."""
    return stamp.sec + stamp.nanosec * 1e-9


def to_nanoseconds(stamp: Time) -> int:
    """Return a stamp as integer nanoseconds, exactly."""
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def to_stamp(nanoseconds: int) -> Time:
    """Build a stamp from integer nanoseconds."""
    sec, nanosec = divmod(int(nanoseconds), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)
