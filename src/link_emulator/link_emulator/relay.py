"""What a site gateway relays, and one direction of it: routes, the emulated link, the counts.

Why a pure part: the gateway process only moves serialized messages between its DDS domain and
Zenoh; what it must get right is which topics cross, in which order and when they come out, and
what it says about that. All of that is here, without rclpy, so it is tested with plain times
and bytes.

A route is one topic that crosses, written ``'topic:pkg/msg/Type'``. The gateway never
deserializes a message (it forwards the CDR bytes), but DDS needs the type to match publishers
and subscribers, so the type is resolved at start-up and a typo stops the gateway there.

All the routes of one direction share one ``EmulatedLink``: one path, so without ``reorder`` a
message never overtakes an earlier one, whatever its topic, as on a real connection.
"""
from collections import deque
from dataclasses import dataclass
import importlib
import re
from typing import Iterable, NamedTuple

import numpy as np

from link_emulator.link import EmulatedLink

__all__ = ['LATENESS_WINDOW', 'Relay', 'Release', 'Route', 'check_no_loop', 'message_class',
           'parse_routes']

LATENESS_WINDOW = 1000  # releases whose lateness is summarized (1 s of a 1 kHz stream)
_TYPE_NAME = re.compile(r'([A-Za-z_][A-Za-z0-9_]*)/msg/([A-Za-z][A-Za-z0-9]*)')


@dataclass(frozen=True)
class Route:
    """One topic that crosses the link, and its message type ``'pkg/msg/Type'``."""

    topic: str
    type_name: str


def message_class(type_name: str) -> type:
    """Return the message class of ``'pkg/msg/Type'``; raise ValueError naming what is wrong."""
    match = _TYPE_NAME.fullmatch(type_name)
    if match is None:
        raise ValueError(f'message type {type_name!r} is not of the form pkg/msg/Type')
    package, name = match.groups()
    try:
        module = importlib.import_module(f'{package}.msg')
    except ImportError:
        raise ValueError(f'message type {type_name!r}: no message package {package!r} is '
                         f'installed') from None
    cls = getattr(module, name, None)
    if not isinstance(cls, type) or not hasattr(cls, 'get_fields_and_field_types'):
        raise ValueError(f'message type {type_name!r}: {package} has no message {name!r}')
    return cls


def parse_routes(entries: Iterable[str], direction: str) -> tuple:
    """Return the ``Route`` of each ``'topic:pkg/msg/Type'`` entry of one direction.

    Blank entries are skipped: ``['']`` says that nothing crosses this way, since a ROS
    parameter cannot be declared as an empty list of strings. Raises ValueError naming the
    direction and the entry: a missing type, an unknown type, or a topic listed twice.
    """
    routes, topics = [], set()
    for entry in entries:
        if not entry.strip():
            continue
        topic, separator, type_name = entry.rpartition(':')
        topic, type_name = topic.strip(), type_name.strip()
        if not separator or not topic or not type_name:
            raise ValueError(f'{direction}: entry {entry!r} is not of the form '
                             f"'topic:pkg/msg/Type'")
        try:
            message_class(type_name)
        except ValueError as error:
            raise ValueError(f'{direction}: entry {entry!r}: {error}') from None
        if topic in topics:
            raise ValueError(f'{direction}: topic {topic!r} is listed twice')
        topics.add(topic)
        routes.append(Route(topic, type_name))
    return tuple(routes)


def check_no_loop(to_remote: tuple, to_operator: tuple) -> None:
    """Raise ValueError if a topic crosses both ways: the gateways would echo it back forever.

    The gateway's node lives in the root namespace, so ``a`` and ``/a`` are one topic.
    """
    both = ({route.topic.lstrip('/') for route in to_remote}
            & {route.topic.lstrip('/') for route in to_operator})
    if both:
        raise ValueError(f'topics {sorted(both)} are listed in both to_remote and to_operator; '
                         f'a topic may cross one way only')


class Release(NamedTuple):
    """A message out of the link: which route it belongs to and its bytes."""

    route: int
    data: bytes


class Relay:
    """One direction of a gateway: messages in, messages due out, and what happened to them.

    Parameters
    ----------
    link : EmulatedLink
        Shared by every route of this direction.
    reliable : collection of int
        The routes whose messages the transport must deliver: never lost on the link.
    """

    def __init__(self, link: EmulatedLink, reliable=frozenset()) -> None:
        self.link = link
        self._reliable = frozenset(reliable)
        self.relayed = 0
        self._lateness = deque(maxlen=LATENESS_WINDOW)  # [s] release time minus arrival

    def send(self, now: float, route: int, data: bytes) -> bool:
        """Put the bytes of ``route`` on the link at ``now`` (s); return False if lost."""
        return self.link.send(now, Release(route, data), reliable=route in self._reliable)

    def release(self, now: float) -> list:
        """Return the ``Release`` of each message due by ``now`` (s), in order of arrival."""
        due = self.link.deliver(now)
        for delivery in due:
            self._lateness.append(now - delivery.arrived)
        self.relayed += len(due)
        return [delivery.payload for delivery in due]

    @property
    def next_arrival(self) -> float | None:
        """When (s) the next message is due, or None when none is in flight."""
        return self.link.next_arrival

    @property
    def in_flight(self) -> int:
        """Messages on the link, neither lost nor released yet."""
        return self.link.sent - self.link.lost - self.relayed

    def lateness(self) -> tuple:
        """Return the p50 and p99 (s) of how late the latest releases came, or (None, None).

        Lateness is what the process adds to the emulated delay: the time from a message's
        arrival on the link to its release.
        """
        if not self._lateness:
            return None, None
        p50, p99 = np.percentile(np.fromiter(self._lateness, float), [50.0, 99.0])
        return float(p50), float(p99)

    def counts(self) -> dict:
        """Return what a diagnostics report says of this direction."""
        p50, p99 = self.lateness()
        return {'received': self.link.sent, 'relayed': self.relayed, 'lost': self.link.lost,
                'retransmitted': self.link.retransmitted,
                'in_flight': self.in_flight,
                'lateness_p50_ms': '-' if p50 is None else f'{p50 * 1e3:.3f}',
                'lateness_p99_ms': '-' if p99 is None else f'{p99 * 1e3:.3f}'}
