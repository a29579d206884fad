"""The recorder inside a site's own process: nothing its nodes publish is lost, under any load.

A recorder in another process takes the 1 kHz streams over DDS, best effort: a loaded machine
that leaves it unscheduled for a moment loses messages (issue 24: 1,020 recorded of 1,105
published at a load average of 3-10). Here each stream is taken by the process's handover
(``haptic_util.intra_process``): inside the publisher's ``publish``, its values go into the
bag's bounded queue, and the bag's own thread encodes and writes them
(``haptic_bringup.queued_bag``). The loop never waits for the disk, and if the writer ever falls
a whole queue behind, what is dropped is counted in the recorder's report rather than lost
unseen. A stream that reaches the process over DDS (what crossed the link, at a telerobotic
site) is taken by the one reader that feeds the node using it: the bag holds exactly what that
node received, read as the node reads it (the robot's commands: ``link_subscription``). The
process's reports, the last ones included, are handed over as published. (In a process whose
streams go through DDS, ``--no-intra-process``, a benchmark's baseline, it takes them over DDS
as its nodes do.)

The process builds this node last (``haptic_bringup.composed``), so it is destroyed last, after
every other node has said its last words. Each telerobotic site runs one and writes its own bag
(``operator``, ``remote``: see ``haptic_bringup.session``).
"""
from haptic_bringup.recorder import message_class, Recorder
from haptic_contract.graph import absolute, STREAMS, TELEOP_COMMAND, TOPIC_TYPES
from haptic_util.cdr import MessageCodec
from haptic_util.intra_process import link_subscription, stream_subscription

__all__ = ['ProcessRecorder']


class ProcessRecorder(Recorder):
    """Records its process's streams as they are handed over, the rest as ``Recorder`` does.

    ``name`` is the node's, which its parameters are given under (one per site).
    """

    def __init__(self, name: str, **kwargs):
        self._streams = []  # its stream subscriptions, made as the base class records
        super().__init__(name, **kwargs)

    def record(self, topic: str, name: str) -> None:
        if topic not in STREAMS:
            super().record(topic, name)
            return
        codec = MessageCodec(message_class(TOPIC_TYPES[topic]))
        self.bag.add_topic(name, TOPIC_TYPES[topic], encode=codec.encode)
        subscribe = link_subscription if topic == absolute(TELEOP_COMMAND) else \
            stream_subscription
        self._streams.append(subscribe(self, codec, topic, lambda values: self.put(name, values),
                                       refused=self.refused))

    def destroy_node(self) -> bool:
        """Close the bag, then stop taking the streams (a polled reader's node goes with them)."""
        destroyed = super().destroy_node()
        for subscription in self._streams:
            subscription.destroy()
        return destroyed
