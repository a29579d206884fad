"""rosbag2 bags in the Jazzy format (mcap, metadata version 9) without rosbag2, through rosbags.

Why a layer over rosbags' ``Writer``: a haptic session can end in a crash or a ``kill -9``.
rosbags closes an mcap chunk only every 1 MiB and writes ``metadata.yaml`` only on close, so a
killed recorder could lose its last megabyte and leave a bag no reader opens. Here a chunk is
closed and flushed to the OS at least every ``flush_period`` seconds, and ``recover`` rebuilds
a readable bag from what a killed recorder left on disk.
"""
import pathlib
import time
from typing import Iterable, Optional

from rosbags.interfaces import Connection
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.storage_mcap import McapWriter
from rosbags.typesys import get_types_from_msg, get_typestore, Stores
from rosbags.typesys.store import Typestore

__all__ = ['BagWriter', 'typestore_with', 'recover', 'killed_bags', 'FLUSH_PERIOD']

FLUSH_PERIOD = 0.5  # [s] the most a kill -9 can lose


class _FlushingMcapWriter(McapWriter):
    """rosbags' mcap storage, closing and flushing a chunk at least every FLUSH_PERIOD."""

    flush_period = FLUSH_PERIOD

    def __init__(self, path, compression) -> None:
        super().__init__(path, compression)
        self._last_flush = time.monotonic()

    def write(self, connection, timestamp, data) -> None:
        super().write(connection, timestamp, data)
        self.flush_if_due()

    def flush_if_due(self) -> None:
        """Close the chunk and hand the file to the OS if FLUSH_PERIOD has passed since last."""
        now = time.monotonic()
        if now - self._last_flush >= self.flush_period:
            if self.chunk.msgs:
                self.close_chunk()
            self.bio.flush()
            self._last_flush = now


class _FlushingWriter(Writer):
    STORAGE_PLUGINS = {**Writer.STORAGE_PLUGINS, StoragePlugin.MCAP: _FlushingMcapWriter}


def typestore_with(definitions: Iterable[tuple[str, str]]) -> Typestore:
    """Return the Jazzy typestore plus custom types, given as (``pkg/msg/Name``, .msg) pairs."""
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for name, text in definitions:
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store


class BagWriter:
    """Write serialized (CDR) messages to a new rosbag2 mcap bag at ``path``.

    ``counts`` holds the number of messages written per topic.
    """

    def __init__(self, path: pathlib.Path, typestore: Typestore) -> None:
        self.path = pathlib.Path(path)
        self._typestore = typestore
        self._writer = _FlushingWriter(self.path, version=9, storage_plugin=StoragePlugin.MCAP)
        self._writer.open()
        self._connections: dict[str, Connection] = {}
        self.counts: dict[str, int] = {}

    def add_topic(self, topic: str, msgtype: str, offered_qos: Optional[list] = None) -> None:
        """Declare a topic of type ``pkg/msg/Name`` before writing to it."""
        self._connections[topic] = self._writer.add_connection(
            topic, msgtype, typestore=self._typestore, offered_qos_profiles=offered_qos or [])
        self.counts[topic] = 0

    def write(self, topic: str, timestamp_ns: int, data: bytes) -> None:
        self._writer.write(self._connections[topic], timestamp_ns, data)
        self.counts[topic] += 1

    def flush_if_due(self) -> None:
        """Flush what was written if FLUSH_PERIOD has passed (a writer calls it while idle)."""
        self._writer.storage.flush_if_due()

    def close(self) -> None:
        """Write the mcap summary and metadata.yaml; the bag is then complete."""
        self._writer.close()


def recover(path: pathlib.Path, typestore: Typestore) -> pathlib.Path:
    """Rebuild a bag a killed recorder left without its summary and metadata.yaml.

    Every message in a whole chunk is kept; the torn tail is dropped. Returns the new bag's path
    (``<path>-recovered``); the damaged bag is left untouched.
    """
    from mcap.exceptions import McapError
    from mcap.records import Channel, Message, Schema
    from mcap.stream_reader import StreamReader

    path = pathlib.Path(path)
    damaged = next(path.glob('*.mcap'), None)
    if damaged is None:
        raise ValueError(f'{path}: no .mcap file to recover')
    target = path.with_name(path.name + '-recovered')
    schemas, topics = {}, {}
    writer = BagWriter(target, typestore)
    try:
        with damaged.open('rb') as stream:
            try:
                for record in StreamReader(stream).records:
                    if isinstance(record, Schema):
                        schemas[record.id] = record.name
                    elif isinstance(record, Channel):
                        topics[record.id] = record.topic
                        if record.topic not in writer.counts:
                            writer.add_topic(record.topic, schemas[record.schema_id])
                    elif isinstance(record, Message):
                        writer.write(topics[record.channel_id], record.log_time, record.data)
            except (McapError, EOFError, ValueError, KeyError):
                pass  # the torn tail of a killed recorder: everything before it is kept
    finally:
        writer.close()
    return target


def killed_bags(path: pathlib.Path) -> list:
    """Return the bags a killed recorder left without metadata: ``path``, or those in it."""
    path = pathlib.Path(path)
    folders = [path, *sorted(f for f in path.iterdir() if f.is_dir())] if path.is_dir() else []
    return [folder for folder in folders
            if any(folder.glob('*.mcap')) and not (folder / 'metadata.yaml').exists()]
