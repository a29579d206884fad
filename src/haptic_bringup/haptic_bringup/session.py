"""A recorded haptic session as arrays: what the wand did, what the engine said, what was felt.

Read from a rosbag2 bag with rosbags (no ROS needed), and joined on the pose stamp that every
state and wrench carries, so each row is one pose with its answer.

A session is one bag, or a folder of bags read as one (rosbags' ``AnyReader`` merges them in
time): a telerobotic session records each site in its own process, so its folder holds the bags
``operator`` and ``remote``. Both sites run on one machine for now, so the receive times of both
bags are on one clock; aligning the bags of two machines is issue 27's.
"""
import dataclasses
import pathlib

import numpy as np
from rosbags.highlevel import AnyReader

from haptic_bringup.bag import killed_bags
from haptic_contract.graph import (absolute, COLLISION_STATE, PUBLISHERS, SCENE_DESCRIPTION,
                                   SITE_PUBLISHERS, WAND_APPLIED_WRENCH, WAND_SESSION_START,
                                   WAND_WRENCH)
from haptic_util.stamps import to_nanoseconds

__all__ = ['Frames', 'Session', 'bags', 'read_frames', 'read_numbers', 'read_session',
           'read_session_start', 'read_vectors', 'reported', 'topic_counts', 'published_counts',
           'applied_work', 'PUBLISHERS', 'SITE_PUBLISHERS']

_STATE, _WRENCH = absolute(COLLISION_STATE), absolute(WAND_WRENCH)
_APPLIED, _SCENE = absolute(WAND_APPLIED_WRENCH), absolute(SCENE_DESCRIPTION)


@dataclasses.dataclass(frozen=True, eq=False)
class Session:
    """One row per answered pose, in stamp order (all arrays share the first dimension).

    Attributes
    ----------
    time : (n,) float, s since the first pose
    tip : (n, 3) float, m
    distance : (n,) float, m, signed, negative inside
    point, normal : (n, 3) float: closest surface point (m) and unit outward normal
    force : (n, 3) float, N, the wrench answering the pose (NaN when none came)
    torque : (n, 3) float, N·m, about the tip, of the same wrench (zero for a point tip)
    applied : (n, 3) float, N, the force the device applied over the tick that ended with the
        pose (``wand/applied_wrench``; NaN when not recorded)
    applied_torque : (n, 3) float, N·m, the torque it applied over that tick
    orientation : (n, 4) float, the pose's quaternion (x, y, z, w)
    objects : (n,) str
    status : (n,) int, CollisionState status
    compute_time : (n,) float, s
    scene : str, the scene YAML the session ran against ('' when not recorded)
    """

    time: np.ndarray
    tip: np.ndarray
    distance: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    force: np.ndarray
    torque: np.ndarray
    applied: np.ndarray
    applied_torque: np.ndarray
    orientation: np.ndarray
    objects: np.ndarray
    status: np.ndarray
    compute_time: np.ndarray
    scene: str


def bags(path: pathlib.Path) -> list:
    """Return a session's bags: ``path`` if it is a bag, else the bags in it (see above).

    A bag without its metadata (its recorder was killed) is refused with what to do, unless its
    recovered copy is there too (``haptic_bag recover``).
    """
    path = pathlib.Path(path)
    if (path / 'metadata.yaml').exists():
        return [path]
    complete = sorted(metadata.parent for metadata in path.glob('*/metadata.yaml'))
    killed = [bag for bag in killed_bags(path)
              if bag.with_name(bag.name + '-recovered') not in complete]
    if killed:
        raise ValueError(f'{killed[0]}: a bag without metadata.yaml (was its recorder killed?); '
                         f'`haptic_bag recover {path}` rebuilds it')
    if not complete:
        raise ValueError(f'{path}: no bag there')
    return complete


def topic_counts(path: pathlib.Path) -> dict:
    """Messages per topic in a session, from its bags' metadata."""
    counts = {}
    with AnyReader(bags(path)) as reader:
        for connection in reader.connections:
            counts[connection.topic] = counts.get(connection.topic, 0) + connection.msgcount
    return counts


def published_counts(path: pathlib.Path, typestore, publishers: dict = PUBLISHERS) -> dict:
    """Topic → how many messages its node says it published, from its last /diagnostics report.

    ``publishers`` maps each topic to its node (``SITE_PUBLISHERS`` for a telerobotic session).
    Topics whose node left no report (it was killed, or not recorded) are missing.
    """
    counts = reported(path, typestore, 'published')
    said = {node: int(values[-1]) for node, values in counts.items()}
    return {topic: said[node] for topic, node in publishers.items() if node in said}


def reported(path: pathlib.Path, typestore, key: str) -> dict:
    """Node → every value it reported for ``key`` on /diagnostics (either site's), in order."""
    said = {}
    with AnyReader(bags(path), default_typestore=typestore) as reader:
        connections = [c for c in reader.connections if c.topic.endswith('/diagnostics')]
        for connection, _, raw in reader.messages(connections=connections):
            for status in reader.deserialize(raw, connection.msgtype).status:
                said.setdefault(status.hardware_id, []).extend(
                    v.value for v in status.values if v.key == key)
    return {node: values for node, values in said.items() if values}


def read_session(path: pathlib.Path, typestore) -> Session:
    """Join a bag's collision states and wrenches on their stamps."""
    states, wrenches, applied, scene = {}, {}, {}, ''
    with AnyReader(bags(path), default_typestore=typestore) as reader:
        for connection, _, raw in reader.messages():
            msg = reader.deserialize(raw, connection.msgtype)
            if connection.topic == _STATE:
                states[to_nanoseconds(msg.header.stamp)] = msg
            elif connection.topic == _WRENCH:
                wrenches[to_nanoseconds(msg.header.stamp)] = msg
            elif connection.topic == _APPLIED:
                applied[to_nanoseconds(msg.header.stamp)] = msg
            elif connection.topic == _SCENE:
                scene = msg.data
    stamps = sorted(states)
    if not stamps:
        raise ValueError(f'{path}: no {_STATE} messages')
    rows = [states[s] for s in stamps]
    nan3 = (np.nan, np.nan, np.nan)
    forces = [_xyz(wrenches[s].wrench.force) if s in wrenches else nan3 for s in stamps]
    torques = [_xyz(wrenches[s].wrench.torque) if s in wrenches else nan3 for s in stamps]
    return Session(
        time=(np.array(stamps) - stamps[0]) * 1e-9,
        tip=np.array([_xyz(m.tip) for m in rows]),
        distance=np.array([m.distance for m in rows]),
        point=np.array([_xyz(m.closest_point) for m in rows]),
        normal=np.array([_xyz(m.normal) for m in rows]),
        force=np.array(forces),
        torque=np.array(torques),
        applied=np.array([_xyz(applied[s].wrench.force) if s in applied else nan3
                          for s in stamps]),
        applied_torque=np.array([_xyz(applied[s].wrench.torque) if s in applied else nan3
                                 for s in stamps]),
        orientation=np.array([(m.orientation.x, m.orientation.y, m.orientation.z,
                               m.orientation.w) for m in rows]),
        objects=np.array([m.object for m in rows]),
        status=np.array([m.status for m in rows]),
        compute_time=np.array([m.compute_time for m in rows]),
        scene=scene)


def read_vectors(path: pathlib.Path, typestore, topics: dict, stamped: bool = False) -> dict:
    """Topic → (times s, (n, 3) vectors) of stamped poses (position) or wrenches (force).

    ``topics`` maps each topic to ``'pose'`` or ``'wrench'``; a topic absent from the bag gives
    empty arrays. The times are when the recorder received each message, or with ``stamped``
    its header's stamp: when its publisher says it happened, which a busy recorder cannot delay.
    """
    series = {topic: ([], []) for topic in topics}
    with AnyReader(bags(path), default_typestore=typestore) as reader:
        connections = [c for c in reader.connections if c.topic in topics]
        for connection, stamp, raw in reader.messages(connections=connections):
            msg = reader.deserialize(raw, connection.msgtype)
            vector = (msg.pose.position if topics[connection.topic] == 'pose'
                      else msg.wrench.force)
            if stamped:
                stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            series[connection.topic][0].append(stamp * 1e-9)
            series[connection.topic][1].append(_xyz(vector))
    return {topic: (np.array(times), np.array(vectors).reshape(-1, 3))
            for topic, (times, vectors) in series.items()}


def read_numbers(path: pathlib.Path, typestore, topic: str) -> tuple:
    """Return (receive times s, values) of a ``std_msgs/Float64`` topic; empty if absent."""
    times, values = [], []
    with AnyReader(bags(path), default_typestore=typestore) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        for connection, stamp, raw in reader.messages(connections=connections):
            times.append(stamp * 1e-9)
            values.append(reader.deserialize(raw, connection.msgtype).data)
    return np.array(times, dtype=np.float64), np.array(values, dtype=np.float64)


def read_session_start(path: pathlib.Path, typestore) -> float:
    """Return when the wand's session began (s, its ``wand/session_start`` stamp).

    The scan's time zero, on the clock of the bag's receive times.
    """
    with AnyReader(bags(path), default_typestore=typestore) as reader:
        connections = [c for c in reader.connections if c.topic == absolute(WAND_SESSION_START)]
        for connection, _, raw in reader.messages(connections=connections):
            return to_nanoseconds(reader.deserialize(raw, connection.msgtype).stamp) * 1e-9
    raise ValueError(f'{path}: no {absolute(WAND_SESSION_START)} recorded: the session never '
                     'began, or the bag is older than that topic')


@dataclasses.dataclass(frozen=True, eq=False)
class Frames:
    """A recorded mono8 image stream (the probe's ``/probe/image``).

    Attributes
    ----------
    received : (n,) float, s
        When the recorder received each frame (the machine's clock).
    stamp : (n,) float, s
        Each frame's stamp: the pose it was made from.
    images : (n, height, width) uint8
    frame_ids : set of str
    """

    received: np.ndarray
    stamp: np.ndarray
    images: np.ndarray
    frame_ids: set


def read_frames(path: pathlib.Path, typestore, topic: str = '/probe/image') -> Frames:
    """Return the mono8 frames of ``topic`` in the session; raise ValueError for another encoding.

    The frames are read into memory: about 2 MB a second at 30 Hz of 256 x 256.
    """
    received, stamps, images, frame_ids = [], [], [], set()
    with AnyReader(bags(path), default_typestore=typestore) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        for connection, stamp, raw in reader.messages(connections=connections):
            msg = reader.deserialize(raw, connection.msgtype)
            if msg.encoding != 'mono8' or msg.step != msg.width:
                raise ValueError(f'{path}: {topic}: {msg.encoding!r} (step {msg.step}, width '
                                 f'{msg.width}), not packed mono8')
            received.append(stamp * 1e-9)
            stamps.append(to_nanoseconds(msg.header.stamp) * 1e-9)
            images.append(np.asarray(msg.data, dtype=np.uint8).reshape(msg.height, msg.width))
            frame_ids.add(msg.header.frame_id)
    shape = images[0].shape if images else (0, 0)
    return Frames(np.array(received), np.array(stamps),
                  np.array(images, dtype=np.uint8).reshape(-1, *shape), frame_ids)


def applied_work(session: Session) -> float:
    """Net work (J) the applied force did on the tip: > 0 means the device gave energy.

    Each tick's mean applied force times the tip's displacement over that tick, from the
    recorded poses (via their states); ticks whose neighbours are missing are left out.
    """
    step = np.diff(session.tip, axis=0)
    work = np.einsum('ij,ij->i', session.applied[1:], step)
    return float(np.nansum(work))


def _xyz(vector) -> tuple:
    return (vector.x, vector.y, vector.z)
