"""A bag written by a thread of its own, fed by a bounded queue that never blocks who feeds it.

Why: a recorder that writes in the thread that takes the messages is as fast as its slowest
write, and a 1 kHz loop that feeds it must never wait for a disk. ``put`` only appends to a
queue (a ``deque``: appending and popping from two threads needs no lock in CPython); the writer
thread encodes each message, writes it, and flushes a chunk at least every ``FLUSH_PERIOD``, idle
or not (``haptic_bringup.bag``). A full queue drops the message and counts it per topic
(``dropped``): the loop goes on, and the loss is said, never hidden. ``close`` writes everything
still queued before it closes the bag.

Every operation on the bag itself (declaring a topic, writing, flushing, closing) runs in the
writer thread, in the order it was asked for.
"""
import collections
import threading
import time
from typing import Callable, Optional

from haptic_bringup.bag import BagWriter

__all__ = ['QueuedBag', 'CAPACITY']

CAPACITY = 20_000  # messages: about 3 s of the loop's six 1 kHz streams
IDLE_WAIT = 0.005  # [s] the writer's sleep when the queue is empty
_DECLARE, _WRITTEN = object(), object()  # mark a topic's declaration, and a drain's end


class QueuedBag:
    """Write messages to a new bag at ``path`` from a thread of its own.

    Attributes
    ----------
    counts : topic -> messages written so far (the writer thread's)
    dropped : topic -> messages lost: refused because the queue was full, or not encodable
    error : the last message that could not be encoded, and why ('' when none)
    """

    def __init__(self, path, typestore, capacity: int = CAPACITY) -> None:
        self._bag = BagWriter(path, typestore)  # raises here if the bag cannot be made
        self.path = self._bag.path
        self.counts = self._bag.counts
        self.dropped: collections.Counter = collections.Counter()
        self.error = ''
        self._capacity = capacity
        self._queue: collections.deque = collections.deque()
        self._encoders: dict = {}
        self._closing = False
        self._thread = threading.Thread(target=self._write, name='bag writer', daemon=True)
        self._thread.start()

    def add_topic(self, topic: str, msgtype: str,
                  encode: Optional[Callable[[object], bytes]] = None) -> None:
        """Declare ``topic`` (``pkg/msg/Name``); ``encode`` turns what is put into CDR bytes."""
        self._encoders[topic] = encode
        self._queue.append((_DECLARE, topic, msgtype))  # never dropped

    def put(self, topic: str, time_ns: int, message) -> bool:
        """Queue one message received at ``time_ns``; False (and counted) if the queue is full."""
        if len(self._queue) >= self._capacity:
            self.dropped[topic] += 1
            return False
        self._queue.append((topic, time_ns, message))
        return True

    def drain(self) -> None:
        """Wait until everything queued so far is written."""
        written = threading.Event()
        self._queue.append((_WRITTEN, written, None))
        written.wait()

    def close(self) -> None:
        """Write everything queued, then the bag's summary: the bag is then complete."""
        self._closing = True
        self._thread.join()
        self._bag.close()

    def _write(self) -> None:
        queue, bag, encoders = self._queue, self._bag, self._encoders
        while True:
            try:
                first, second, third = queue.popleft()
            except IndexError:
                if self._closing and not queue:
                    return
                bag.flush_if_due()
                time.sleep(IDLE_WAIT)
                continue
            if first is _DECLARE:
                bag.add_topic(second, third)
                continue
            if first is _WRITTEN:
                second.set()
                continue
            encode = encoders[first]
            try:
                bag.write(first, second, encode(third) if encode is not None else third)
            except Exception as error:  # a message it cannot encode: said, and the rest goes on
                self.dropped[first] += 1
                self.error = f'{first}: {type(error).__name__}: {error}'
