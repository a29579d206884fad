"""Fast DDS transports of our own for two kinds of process, on loopback only.

A relay between sites talks to its site over UDP on 127.0.0.1, never Fast DDS's shared memory.

Why: a relay (the site gateway) stands for the network between the sites, and
it may stop: SIGSTOP in a test, a link down, a process descheduled. Over shared memory, a site
stalled while its relay was stopped: a sender that finds a peer's port unanswered checks its
health, sleeping 333 ms at a time for up to 1 s (``healthy_check_timeout_ms``), and it does so
holding its participant's one send mutex, so every other write of that process waits too, its
1 kHz streams included (Fast DDS 2.14, ``RTPSParticipantImpl::sendSync``). The site's ticks were
lost for that long (a 1.003 s hole in a CI run; 0.47 s in a run here). Over UDP, a write to a
stopped peer is a datagram dropped.

With ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, rmw_fastrtps adds a shared-memory transport of
its own, whatever ``FASTDDS_BUILTIN_TRANSPORTS`` says; so the relay leaves the range to Fast DDS
and gives its own profile (``config/loopback_udp.xml``): UDP on 127.0.0.1 only, discovery by
unicast to 127.0.0.1. No packet leaves loopback, as with the LOCALHOST range.

A recorder of its own process (``--separate``) takes the 1 kHz streams over shared memory, with
a port queue 16 times the default: 8192 messages, 1.4 s of the loop's six streams. Fast DDS
queues every message for a participant in one port (512 by default, under 0.1 s of those
streams) until its receiving thread takes it into a reader's history, and drops what a full
port cannot hold. On a loaded machine that thread was descheduled longer, and the recorder lost
the same 175 to 240 messages of each stream (a CI run; here with the machine's cores hogged).
Its process stopped for 0.15 s, it lost 59 to 66 of each with the default port, none with this
(``tests/integration/test_recording.py``). Until the recorder takes a message, it also holds the
writer's buffer, about 1 kB a message, in the writer's segment: Fast DDS's default 512 kB held
0.17 s of the wand driver's three streams (the recorder stopped 0.25 s lost 80 of each; 0.4 s,
188). So the processes that a recorder process records get the same profile, whose segments of
8 MB hold longer than its port: stopped 0.4, 0.8 or 1.2 s, it lost nothing (1.2 s: in 4 runs
of 5; in the other, no message either, but the bag held 559 more of the driver's poses than its
last report in it said); 1.6 s, 1546 to 1552 of each stream, its port full.
"""
import os
import pathlib

from ament_index_python.packages import get_package_share_directory

__all__ = ['deep_shared_memory', 'deep_shared_memory_environment', 'loopback_udp']


def loopback_udp() -> None:
    """Make the DDS participants this process makes next UDP peers on 127.0.0.1 only."""
    os.environ.update(_profile_environment('loopback_udp.xml'))


def deep_shared_memory() -> None:
    """Give the DDS participants this process makes next deep shared memory (see above)."""
    os.environ.update(deep_shared_memory_environment())


def deep_shared_memory_environment() -> dict:
    """Return the variables that give a process's DDS participants deep shared memory."""
    return _profile_environment('deep_shared_memory.xml')


def _profile_environment(name: str) -> dict:
    """Leave the discovery range to Fast DDS, which then takes our profile (``config/name``)."""
    profile = pathlib.Path(get_package_share_directory('haptic_util')) / 'config' / name
    return {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'SYSTEM_DEFAULT',
            'FASTRTPS_DEFAULT_PROFILES_FILE': str(profile)}
