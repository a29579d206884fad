"""The newest message of a stream, taken when its reader asks, never delivered one by one.

Why: the probe's imager wants the TCP pose 30 times a second, from a 1 kHz stream. Delivered
by the executor, each pose costs the reader's process a dispatch and a decode in Python, 970 of
them a second for nothing. Here the middleware keeps the newest sample (a history of one) in
its own threads, and the reader takes it when it needs it, as ``rclpy.wait_for_message`` does:
from a subscription of a node that no executor spins, so no callback ever runs for it.
"""
from typing import Optional, Sequence

from rclpy.node import Node

from haptic_util.cdr import MalformedMessage, MessageCodec
from haptic_util.qos import NEWEST_STREAM_QOS
from haptic_util.tally import Tally

__all__ = ['NewestMessage']


class NewestMessage:
    """Takes the newest message of ``topic`` as ``codec``'s leaf values, when asked.

    Its subscription is on a node of its own (``<node>_newest``, in ``node``'s namespace and
    context), which it destroys with ``destroy``. Bytes that are no message of the type are
    counted in ``refused``, with the reason, and skipped.
    """

    def __init__(self, node: Node, codec: MessageCodec, topic: str, *, refused: Tally) -> None:
        self._codec, self._refused = codec, refused
        self._kind = f'malformed {topic}'
        # No log or parameters of its own (as ``PolledReader``'s intake): two readers of one
        # node would register its name's log publisher twice.
        self._reader = Node(f'{node.get_name()}_newest', namespace=node.get_namespace(),
                            context=node.context, start_parameter_services=False,
                            enable_rosout=False)
        self._subscription = self._reader.create_subscription(
            codec.message_class, topic, lambda data: None, NEWEST_STREAM_QOS, raw=True)

    def take(self) -> Optional[Sequence]:
        """Return the newest message not taken yet, None if there is none."""
        with self._subscription.handle:
            taken = self._subscription.handle.take_message(self._subscription.msg_type, True)
        if taken is None:
            return None
        try:
            return self._codec.decode(taken[0])
        except MalformedMessage as error:
            self._refused.add(self._kind, str(error))
            return None

    def destroy(self) -> None:
        self._reader.destroy_node()
