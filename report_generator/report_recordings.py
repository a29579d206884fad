"""What the demo recorded: each experiment's bag and loop statistics, read as arrays.

The demo writes one folder per run under its ``--out`` (``<run>/bag``, an mcap rosbag2, and
``<run>/loop_stats.npz``, the driver's round-trip record); ``haptic_bringup.session`` turns a
bag into arrays in the order the collision states were published.
"""

from dataclasses import dataclass
import math
from pathlib import Path

import numpy as np
from report_generator.report_experiments import Experiment
from report_generator.report_format import format_utc

from haptic_bringup.contacts import contact_intervals
from haptic_bringup.session import published_counts, PUBLISHERS, read_session, topic_counts

__all__ = ['CONTACT_SAMPLES', 'NO_FORCE_RUN', 'Recording', 'control_contacts', 'read_recording',
           'typestore']

CONTACT_SAMPLES = 3  # shorter runs inside are grazes, as for contacts.contact_intervals
NO_FORCE_RUN = 'cuboid-no-force'  # the demo's control run, the cuboid taps without force


@dataclass(frozen=True, eq=False)
class Recording:
    """What one experiment's bag and loop statistics hold (see ``haptic_bringup.session``).

    ``velocity`` (n, 3) m/s is the wand's twist stamped as each answered pose (NaN if none).
    """

    experiment: Experiment
    session: object
    velocity: np.ndarray
    contacts: list
    loop: dict
    counts: dict
    recorded_at: str
    scene_matches: bool


def typestore():
    """Return the rosbags type store that knows this repository's messages."""
    from haptic_bringup.bag import typestore_with
    from haptic_bringup.launcher import add_venv_prefix
    from haptic_bringup.recorder import custom_definitions

    add_venv_prefix()
    return typestore_with(custom_definitions())


def _velocities(bag: Path, type_store) -> np.ndarray:
    """(n, 3) m/s: the twist stamped as each collision state's pose, in ``read_session`` order."""
    from rosbags.highlevel import AnyReader

    twists, states = {}, set()
    with AnyReader([bag], default_typestore=type_store) as reader:
        wanted = [c for c in reader.connections
                  if c.topic in ('/wand/twist', '/collision/state')]
        for connection, _, raw in reader.messages(connections=wanted):
            message = reader.deserialize(raw, connection.msgtype)
            stamp = message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec
            if connection.topic == '/wand/twist':
                linear = message.twist.linear
                twists[stamp] = (linear.x, linear.y, linear.z)
            else:
                states.add(stamp)
    missing = (math.nan,) * 3
    return np.array([twists.get(stamp, missing) for stamp in sorted(states)])


def read_recording(experiment: Experiment, demo_dir: Path, type_store) -> Recording:
    """Read one experiment's bag and loop statistics."""
    run = demo_dir / experiment.name
    bag = run / 'bag'
    if not bag.is_dir():
        raise FileNotFoundError(f'{bag}: no bag; run `demo --experiments {experiment.name}`')
    session = read_session(bag, type_store)
    recorded = topic_counts(bag)
    published = published_counts(bag, type_store)
    counts = {topic: (published.get(topic), recorded.get(topic, 0))
              for topic in sorted(published.keys() | (recorded.keys() & PUBLISHERS.keys()))}
    stats = run / 'loop_stats.npz'
    loop = {key: value for key, value in np.load(stats).items()} if stats.exists() else {}
    stamp = max(path.stat().st_mtime for path in bag.iterdir())
    scene_text = experiment.scene_file.read_text()
    contacts = contact_intervals(session, min_samples=CONTACT_SAMPLES)
    return Recording(experiment, session, _velocities(bag, type_store), contacts, loop, counts,
                     format_utc(stamp), session.scene == scene_text)


def control_contacts(demo_dir: Path, type_store) -> list | None:
    """Read the contacts of the demo's control run (no force), or None if it was not run."""
    control = demo_dir / NO_FORCE_RUN / 'bag'
    if not control.exists():
        return None
    return contact_intervals(read_session(control, type_store))
