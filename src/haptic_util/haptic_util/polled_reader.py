"""A topic that any peer on the network can flood, read at a bounded rate.

Why: an executor calls a subscription's callback once per message, and rclpy's EventsExecutor
queues one event per arrival, first in first out with the timers'. A stranger's 20 kHz flood of
commands on the robot's site then cost its one process a Python callback per message: it fell
behind, and the robot's own 1 kHz timers waited behind the backlog (its site published 1 message
in the flood's second, and none for 1.3 s after it ended). Read instead by a timer, at most
``max_rate`` messages a second, a flood is shed by DDS itself: the reader's keep-last history
holds the newest messages and drops the older ones, costing no Python. The followed session's
messages are among those taken at their share of what arrives, so a site under a flood still
hears its operator, and the rest of the process keeps its rate.

rclpy executors register every subscription of the nodes they spin, so the subscription lives on
a node of its own that no executor spins (hidden: its name starts with an underscore); the
timer that takes from it is on the owning node. A node that ticks at 1 kHz anyway (the
follower) takes in its own tick instead (``timed=False``): a 1 kHz timer is a wake of rclpy's
timer thread and of the executor each millisecond, 3-4 % of a core here whatever it does.
"""
import math
from typing import Callable

from rclpy.node import Node
from rclpy.qos import QoSProfile

__all__ = ['PolledReader', 'TICK']

TICK = 0.001  # [s] how often the reader takes what arrived: the haptic streams' period


class PolledReader:
    """Takes ``topic``'s serialized messages to ``deliver``, at most ``max_rate`` a second.

    Parameters
    ----------
    node : Node
        The node whose executor runs the taking timer.
    msg_type
        The topic's message class.
    deliver : callable
        Called with each message's CDR bytes, in arrival order.
    qos : QoSProfile
        Its history's depth is the most that waits between two ticks; the rest is shed.
    max_rate : float, Hz
        At most ``max_rate * TICK`` (rounded up) are taken each tick.
    timed : bool
        Take by a timer of the owner's, every ``TICK``; else the owner calls ``take`` in its
        own tick.
    """

    def __init__(self, node: Node, msg_type, topic: str, deliver: Callable[[bytes], None],
                 qos: QoSProfile, max_rate: float, *, timed: bool = True) -> None:
        if not max_rate > 0.0:
            raise ValueError(f'{topic}: max_rate must be positive, not {max_rate}')
        self._per_tick = math.ceil(max_rate * TICK)
        self._msg_type = msg_type
        self._deliver = deliver
        self._owner = node
        # Not the process's arguments: a ``__node`` remap would give it the owner's name. The
        # topic is resolved by the owner, with its remaps.
        self._intake = Node(f'_{node.get_name()}_intake', namespace=node.get_namespace(),
                            context=node.context, use_global_arguments=False,
                            start_parameter_services=False, enable_rosout=False)
        self._subscription = self._intake.create_subscription(
            msg_type, node.resolve_topic_name(topic), lambda _: None, qos, raw=True)
        self.timed = timed
        self._timer = node.create_timer(TICK, self.take) if timed else None

    def take(self) -> int:
        """Deliver what arrived, up to one tick's share of ``max_rate``; return how many."""
        taken = 0
        while taken < self._per_tick:
            message = self._subscription.handle.take_message(self._msg_type, True)
            if message is None:
                break
            taken += 1
            self._deliver(message[0])
        return taken

    def get_publisher_count(self) -> int:
        return self._subscription.get_publisher_count()

    def destroy(self) -> None:
        if self._timer is not None:
            self._owner.destroy_timer(self._timer)
        self._intake.destroy_node()
