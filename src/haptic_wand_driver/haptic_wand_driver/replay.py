"""A device that plays back a recorded wand trajectory, open loop.

Sources: a pose CSV (see :mod:`haptic_wand_driver.pose_table`) or a rosbag2 recording (mcap or
sqlite3: a bag directory, or a single ``.mcap``/``.db3`` file) with ``geometry_msgs/msg/
PoseStamped`` on ``/wand/pose``, read with rosbags' pure-Python ``AnyReader``. Bag poses are timed
by their header stamps; CSV times are float seconds (epoch times there keep only ~0.2 us). The pose
is interpolated linearly between samples; the velocity comes from differencing the recording
(second-order differences at the samples, interpolated). The
applied wrench is accepted and ignored: nothing pushes back on a recording.
"""

import math
from pathlib import Path

import numpy as np

from haptic_contract.checks import finite_number
from haptic_contract.graph import absolute, WAND_POSE
from haptic_contract.wand import PitchError, roll_yaw_from_quaternion
from haptic_wand_driver.device import DeviceLimits, HapticDevice, WandState, Workspace
from haptic_wand_driver.pose_table import PoseFileError, PoseTable, read_pose_csv

__all__ = ['DEFAULT_POSE_TOPIC', 'ReplayDevice', 'ReplayError', 'read_bag_poses']

DEFAULT_POSE_TOPIC = absolute(WAND_POSE)
_POSE_TYPE = 'geometry_msgs/msg/PoseStamped'
_BAG_FILE_SUFFIXES = ('.mcap', '.db3')


class ReplayError(ValueError):
    """A recording cannot be replayed; the message names the file and the problem."""


def read_bag_poses(path: str | Path, topic: str = DEFAULT_POSE_TOPIC) -> PoseTable:
    """Read the poses on ``topic`` from a rosbag2 recording.

    Parameters
    ----------
    path : str or Path
        A bag directory (with metadata.yaml), or a single .mcap or .db3 file.
    topic : str
        Must carry geometry_msgs/msg/PoseStamped.

    Returns
    -------
    table : PoseTable
        Seconds since the first message's header stamp (taken in integer nanoseconds, so that
        epoch stamps lose no resolution), and x, y, z, roll, yaw per message, in bag order.

    Raises
    ------
    ReplayError
        If the bag cannot be opened, lacks the topic, has it with another type, has no message on
        it, or holds a pose with pitch or stamps that do not increase.
    """
    from rosbags.highlevel import AnyReader, AnyReaderError
    from rosbags.typesys import get_typestore, Stores

    path = Path(path)
    try:
        reader = AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY))
        reader.open()
    except (AnyReaderError, OSError, ValueError) as error:
        raise ReplayError(f'{path}: cannot open as a rosbag2 recording: {error}') from None
    try:
        on_topic = [c for c in reader.connections if c.topic == topic]
        if not on_topic:
            topics = sorted({c.topic for c in reader.connections}) or ['none']
            raise ReplayError(f'{path}: no topic {topic!r} in the bag (topics: '
                              f'{", ".join(topics)})')
        wrong = [c.msgtype for c in on_topic if c.msgtype != _POSE_TYPE]
        if wrong:
            raise ReplayError(f'{path}: topic {topic!r} has type {wrong[0]}, expected '
                              f'{_POSE_TYPE}')
        stamps, coordinates = [], []
        for index, (connection, _, raw) in enumerate(reader.messages(connections=on_topic)):
            message = reader.deserialize(raw, connection.msgtype)
            orientation = message.pose.orientation
            try:
                roll, yaw = roll_yaw_from_quaternion(
                    [orientation.x, orientation.y, orientation.z, orientation.w])
            except PitchError as error:
                raise ReplayError(f'{path}: {topic} message {index}: {error}') from None
            position = message.pose.position
            stamps.append(message.header.stamp.sec * 10 ** 9 + message.header.stamp.nanosec)
            coordinates.append((position.x, position.y, position.z, roll, yaw))
    except AnyReaderError as error:
        raise ReplayError(f'{path}: cannot read {topic}: {error}') from None
    finally:
        reader.close()
    if not stamps:
        raise ReplayError(f'{path}: topic {topic!r} has no messages')
    try:
        return PoseTable(1e-9 * (np.array(stamps) - stamps[0]), np.array(coordinates))
    except ValueError as error:
        raise ReplayError(f'{path}: {topic}: {error}') from None


def _read_recording(path: Path, topic: str) -> PoseTable:
    if not path.exists():
        raise ReplayError(f'{path}: no such file or directory')
    if path.is_dir() or path.suffix.lower() in _BAG_FILE_SUFFIXES:
        return read_bag_poses(path, topic)
    if path.suffix.lower() == '.csv':
        try:
            return read_pose_csv(path)
        except PoseFileError as error:
            raise ReplayError(str(error)) from None
    raise ReplayError(f'{path}: unsupported recording type {path.suffix!r}; use a rosbag2 '
                      f'directory, .mcap, .db3 or .csv')


class ReplayDevice(HapticDevice):
    """Plays a recorded trajectory; applied wrenches are ignored.

    Parameters
    ----------
    path : str or Path
        A pose CSV, a rosbag2 directory, or a .mcap/.db3 file.
    loop : bool
        Start over at the end; otherwise hold the last pose at rest.
    time_scale : float
        Recording seconds played per second of ``now`` (2 plays twice as fast).
    start_offset : float, s
        Where in the recording (from its first sample) playback starts.
    topic : str
        Pose topic in a bag.

    Raises
    ------
    ReplayError
        If the recording cannot be read, has fewer than two poses, or an option is out of range.
    """

    def __init__(self, path: str | Path, *, loop: bool = False, time_scale: float = 1.0,
                 start_offset: float = 0.0, topic: str = DEFAULT_POSE_TOPIC):
        path = Path(path)
        table = _read_recording(path, topic)
        if table.times.size < 2:
            raise ReplayError(f'{path}: a replay needs at least two poses, found one')
        duration = float(table.times[-1] - table.times[0])
        time_scale = finite_number(time_scale, f'{path}: time_scale', minimum=0.0, strict=True,
                                   error=ReplayError)
        if not (np.isfinite(start_offset) and 0.0 <= start_offset < duration):
            raise ReplayError(f'{path}: start_offset must be in [0, {duration:.6g}) s, the '
                              f'recording length, got {start_offset!r}')
        coordinates = table.coordinates.copy()
        coordinates[:, 3:] = np.unwrap(coordinates[:, 3:], axis=0)
        self._times = table.times - table.times[0]
        self._coordinates = coordinates
        edge_order = 2 if len(self._times) > 2 else 1
        self._rates = time_scale * np.gradient(coordinates, self._times, axis=0,
                                               edge_order=edge_order)
        self._duration = duration
        self._loop = bool(loop)
        self._time_scale = float(time_scale)
        self._start_offset = float(start_offset)
        self._start: float | None = None
        self._limits = DeviceLimits(force_limit=0.0, torque_limit=0.0, workspace=Workspace(
            lower=coordinates[:, :3].min(axis=0), upper=coordinates[:, :3].max(axis=0),
            roll_limit=min(np.abs(coordinates[:, 3]).max(), np.pi),
            yaw_limit=min(np.abs(coordinates[:, 4]).max(), np.pi)))

    @property
    def limits(self) -> DeviceLimits:
        """No force or torque; the workspace is the recording's extent."""
        return self._limits

    @property
    def duration(self) -> float:
        """Length of the recording, s (recording time)."""
        return self._duration

    def read(self, now: float) -> WandState:
        """Return the recorded state at ``now`` (s); the first call starts playback."""
        self._raise_if_closed()
        now = finite_number(now, 'ReplayDevice.read now')
        if self._start is None:
            self._start = float(now)
        played = self._start_offset + (now - self._start) * self._time_scale
        if self._loop:
            played %= self._duration
        elif played >= self._duration:
            return WandState.from_coordinates(now, self._coordinates[-1], np.zeros(5))
        # One search, then a blend of the two neighbouring rows: linear interpolation, as
        # np.interp per column would give, at a tenth of the cost in the 1 kHz loop.
        times = self._times
        after = min(max(int(np.searchsorted(times, played, side='right')), 1), len(times) - 1)
        weight = (played - times[after - 1]) / (times[after] - times[after - 1])
        coordinates = self._coordinates[after - 1] + weight * (
            self._coordinates[after] - self._coordinates[after - 1])
        rates = self._rates[after - 1] + weight * (self._rates[after] - self._rates[after - 1])
        return WandState.from_coordinates(now, coordinates, rates)

    def applied(self) -> tuple[np.ndarray, np.ndarray]:
        """Return zeros: a recording renders nothing."""
        return np.zeros(3), np.zeros(3)

    def apply(self, force: np.ndarray, torque: np.ndarray, *, until: float = math.inf) -> None:
        """Ignore the wrench: a recording cannot be pushed."""
        self._raise_if_closed()
