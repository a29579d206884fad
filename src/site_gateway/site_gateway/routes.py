"""Which topics cross between the two sites, which way, how, and under which Zenoh key.

Why one table: both gateways must agree on it, and the access control is written from it. A key
names the role whose site publishes it (``haptic/operator/teleop/command``), and a site's access
control lets each certificate put under its own role's keys only. So the role in a key that
arrives is authenticated: a command under ``haptic/remote/...`` was put by a holder of the
remote site's certificate, and the gateway refuses it by name, where a key alone would say
nothing of who sent it.

Topics are written ``'topic:pkg/msg/Type'`` (``link_emulator.relay``).
A topic crosses as a 1 kHz stream (the newest message matters, a late one is worthless: drop
rather than block) unless it is listed as reliable (it must arrive, as the clutch must) or as a
frame (an image: tens of kilobytes at tens of hertz, for a person to look at; the newest
matters, and it must never hold a stream back: it goes after the streams, dropped when the link
is congested).
"""
from dataclasses import dataclass
from typing import Iterable

from link_emulator.relay import check_no_loop, parse_routes, Route

__all__ = ['Crossing', 'FRAME', 'RELIABLE', 'ROLES', 'STREAM', 'SiteRoutes', 'bye_key',
           'other_role', 'role_in_key', 'site_routes']

ROLES = ('operator', 'remote')
STREAM, RELIABLE, FRAME = 'stream', 'reliable', 'frame'
_PUBLISHER = {'to_remote': 'operator', 'to_operator': 'remote'}
_BYE = '_gateway/bye'  # under a role's keys: that site's gateway is stopping


def other_role(role: str) -> str:
    """Return the role of the other site."""
    if role not in ROLES:
        raise ValueError(f'role {role!r} is not one of {list(ROLES)}')
    return ROLES[1 - ROLES.index(role)]


def _check_prefix(prefix: str) -> str:
    chunks = prefix.split('/')
    if not prefix or any(not chunk or set(chunk) & set('*$?#@') for chunk in chunks):
        raise ValueError(f'key prefix {prefix!r} must be chunks of plain characters joined by '
                         f"'/' (no '*', '$', '?', '#', '@' nor empty chunk)")
    return prefix


@dataclass(frozen=True)
class Crossing:
    """One topic that crosses: its route, the role whose site publishes it, and its kind."""

    route: Route
    publisher: str
    kind: str

    @property
    def topic(self) -> str:
        """The topic without its leading slash: a gateway's node lives in the root namespace."""
        return self.route.topic.lstrip('/')

    def key(self, prefix: str, role: str | None = None) -> str:
        """Return this topic's Zenoh key under ``role``'s keys (default: its publisher's)."""
        return f'{_check_prefix(prefix)}/{role or self.publisher}/{self.topic}'

    def any_role_key(self, prefix: str) -> str:
        """Return the key expression of this topic under every role's keys."""
        return self.key(prefix, '*')


def bye_key(prefix: str, role: str) -> str:
    """Return the key on which ``role``'s gateway says that its site is stopping."""
    return f'{_check_prefix(prefix)}/{role}/{_BYE}'


def role_in_key(key: str, prefix: str) -> str | None:
    """Return the role named in ``key`` under ``prefix``, or None if it names none."""
    head = f'{prefix}/'
    if not key.startswith(head):
        return None
    role = key[len(head):].split('/', 1)[0]
    return role if role in ROLES else None


@dataclass(frozen=True)
class SiteRoutes:
    """What one site's gateway sends and receives, each in the order of its parameter."""

    role: str
    outgoing: tuple  # Crossing, published by this site
    incoming: tuple  # Crossing, published by the other site


def _topics(listed: Iterable[str]) -> set:
    """Return the topics listed (as in the routes), blank entries skipped."""
    return {topic.strip().lstrip('/') for topic in listed if topic.strip()}


def site_routes(role: str, to_remote: Iterable[str], to_operator: Iterable[str],
                reliable: Iterable[str] = (), frames: Iterable[str] = ()) -> SiteRoutes:
    """Return ``role``'s side of the table; raise ValueError naming what is wrong.

    ``reliable`` lists topics (as in the routes) that must arrive, ``frames`` those that cross
    as frames; blank entries are skipped, as in the routes. A topic may cross one way only, as
    one kind, and none may be named like the gateways' own key.
    """
    other_role(role)
    routes = {'to_remote': parse_routes(to_remote, 'to_remote'),
              'to_operator': parse_routes(to_operator, 'to_operator')}
    check_no_loop(routes['to_remote'], routes['to_operator'])
    kinds = {RELIABLE: _topics(reliable), FRAME: _topics(frames)}
    both = kinds[RELIABLE] & kinds[FRAME]
    if both:
        raise ValueError(f'{sorted(both)} listed both as reliable and as frames; choose one')
    kind_of = {topic: kind for kind, topics in kinds.items() for topic in topics}
    crossings = [Crossing(route, _PUBLISHER[direction],
                          kind_of.get(route.topic.lstrip('/'), STREAM))
                 for direction, entries in routes.items() for route in entries]
    topics = {crossing.topic for crossing in crossings}
    for kind, listed in (('reliable', kinds[RELIABLE]), ('frames', kinds[FRAME])):
        unknown = listed - topics
        if unknown:
            raise ValueError(f'{kind}: {sorted(unknown)} cross neither way; list each in '
                             f'to_remote or to_operator')
    if _BYE in topics:
        raise ValueError(f'topic {_BYE!r} is the gateways\' own; it cannot cross')
    return SiteRoutes(role, tuple(c for c in crossings if c.publisher == role),
                      tuple(c for c in crossings if c.publisher != role))
