"""The emulated link as a stage of a node: what a site sends, held for its delay, jitter and loss.

Why: experiments set the link's delay over the real transport (the kernel here has no netem),
so the site gateway holds each message it sends for the emulated link (``link_emulator.link``)
before handing it to Zenoh. The release timer (steady clock) is re-armed for the link's next
arrival rather than polling at 1 kHz: a release is then late by the executor's wake-up alone.
"""
import math
import time
from typing import Callable

from rclpy.clock import Clock, ClockType
from rclpy.node import Node

from haptic_util.executor import StartupError
from link_emulator.link import DelayTrace, EmulatedLink, LinkConfig
from link_emulator.params import LinkStageParams
from link_emulator.relay import Relay

__all__ = ['ReleaseTimer', 'emulated_link']

_STEADY = Clock(clock_type=ClockType.STEADY_TIME)  # the clock time.monotonic() reads


def emulated_link(params: LinkStageParams, direction: str, node_name: str) -> EmulatedLink:
    """Return one direction's emulated link (``to_operator`` draws with ``seed + 1``).

    A bad value or an unreadable trace raises ``StartupError`` naming the node.
    """
    seed = params.seed + (1 if direction == 'to_operator' else 0)
    try:
        config = LinkConfig(params.delay, params.jitter, params.loss, params.reorder, seed)
    except ValueError as error:
        raise StartupError(f'{node_name}: {error}') from None
    try:
        trace = DelayTrace.from_csv(params.delay_trace) if params.delay_trace else None
    except (ValueError, OSError) as error:
        raise StartupError(f'{node_name}: parameter delay_trace: {error}') from None
    return EmulatedLink(config, trace=trace)


class ReleaseTimer:
    """One direction's emulated link in a node: messages in, each out when its time comes.

    The timer (steady clock) is armed for the link's next arrival, rather than polling at
    1 kHz; a message whose time has come on arrival (no delay) goes out at once, through
    ``emit(route, data)``: a DDS publisher here, a Zenoh one in the site gateway.
    """

    def __init__(self, relay: Relay, node: Node, emit: Callable[[int, bytes], None]) -> None:
        self.relay = relay
        self._emit = emit
        self._timer = node.create_timer(1.0, self.on_timer, clock=_STEADY, autostart=False)
        self._armed = None  # [s] the arrival the timer is armed for

    def on_message(self, route: int, data: bytes) -> None:
        self.relay.send(time.monotonic(), route, data)
        self.release()

    def on_timer(self) -> None:
        self._armed = None  # it fired: arm it again, even for the same arrival
        self.release()

    def release(self) -> None:
        now = time.monotonic()
        for route, data in self.relay.release(now):
            self._emit(route, data)
        due = self.relay.next_arrival
        if due == self._armed:
            return
        self._armed = due
        if due is None:
            self._timer.cancel()
            return
        self._timer.timer_period_ns = max(1, math.ceil((due - now) * 1e9))
        self._timer.reset()
