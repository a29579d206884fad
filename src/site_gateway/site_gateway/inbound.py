"""What comes from the other site, judged before it enters this site's DDS domain.

Why here, before DDS: the nodes behind the gateway check every field (``haptic_contract.teleop``),
but each message the gateway lets through costs the site a DDS publication and its nodes a
callback. So the gateway hands on a message only if:
- it arrived under the key of the role that may publish it (the access control guarantees that
  the role in a key is the sender's certificate); anything else is a try by that role, refused
  and counted under its name;
- it is a well-formed message of the crossing's type (``haptic_util.cdr`` reads it, bounded,
  without converting it); the bytes handed on are the bytes that came;
- its crossing is within ``max_rate`` (a token bucket with ``BURST`` s of tokens): an
  authenticated peer's flood is shed here, not queued into the site.
"""
from typing import NamedTuple, Sequence

from haptic_util.cdr import MalformedMessage, MessageCodec
from haptic_util.tally import Tally
from link_emulator.relay import message_class
from site_gateway.routes import role_in_key

__all__ = ['BURST', 'Inbound', 'Verdict']

BURST = 0.05  # [s] of messages at max_rate that may come at once (a jittery link's bunch)


class Verdict(NamedTuple):
    """Whether to hand a message on, and its leaf values; else the refusal and who sent it."""

    deliver: bool
    refusal: str = ''
    sender: str = ''
    values: Sequence = ()


class _Bucket:
    """A token bucket: ``rate`` per second, at most ``rate * BURST`` (and one) saved up."""

    def __init__(self, rate: float) -> None:
        self.rate = rate
        self.capacity = max(1.0, rate * BURST)
        self.tokens = self.capacity
        self.filled = None  # [s]

    def take(self, now: float) -> bool:
        if self.rate <= 0.0:
            return True
        if self.filled is not None:
            self.tokens = min(self.capacity, self.tokens + (now - self.filled) * self.rate)
        self.filled = now
        if self.tokens < 1.0:
            return False
        self.tokens -= 1.0
        return True


class Inbound:
    """The other site's crossings into this one, and the counts of what became of them.

    Parameters
    ----------
    crossings : tuple of Crossing
        What the other site publishes (``SiteRoutes.incoming``).
    prefix : str
        The keys' prefix.
    max_rate : float, Hz
        Per crossing; 0 for no limit.
    """

    def __init__(self, crossings: tuple, prefix: str, max_rate: float) -> None:
        if max_rate < 0.0:
            raise ValueError(f'max_rate must be >= 0 Hz, got {max_rate!r}')
        self.crossings = crossings
        self._prefix = prefix
        self._codecs = [MessageCodec(message_class(c.route.type_name)) for c in crossings]
        self._buckets = [_Bucket(max_rate) for _ in crossings]
        self.received = [0] * len(crossings)
        self.delivered = [0] * len(crossings)
        self.refused = Tally()

    def judge(self, now: float, index: int, key: str, data: bytes) -> Verdict:
        """Judge one message of crossing ``index`` that arrived under ``key`` at ``now`` (s)."""
        crossing = self.crossings[index]
        self.received[index] += 1
        sender = role_in_key(key, self._prefix) or 'unknown'
        if sender != crossing.publisher:
            return self._refuse(f'{crossing.topic} from the {sender} role', sender,
                                f'only the {crossing.publisher} site may publish it')
        if not self._buckets[index].take(now):
            return self._refuse(f'{crossing.topic} over max_rate', sender)
        try:
            values = self._codecs[index].decode(data)
        except MalformedMessage as error:
            return self._refuse(f'malformed {crossing.topic}', sender, str(error))
        self.delivered[index] += 1
        return Verdict(True, sender=sender, values=values)

    def _refuse(self, kind: str, sender: str, detail: str = '') -> Verdict:
        self.refused.add(kind, detail)
        return Verdict(False, kind, sender)

    def counts(self) -> dict:
        """Return what a diagnostics report says of the incoming crossings."""
        values = {}
        for crossing, received, delivered in zip(self.crossings, self.received, self.delivered):
            values[f'in {crossing.topic} received'] = received
            values[f'in {crossing.topic} delivered'] = delivered
        values.update({f'refused: {kind}': count for kind, count in self.refused.counts.items()})
        return values
