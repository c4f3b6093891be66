"""Every other bag, with rosbags' readers: ROS 2 sqlite3 bags, and what the index readers pass
on (an MCAP file without a summary, a ROS 1 bag without an index, whole-file compression).

rosbags hands out one message at a time: they are joined into blocks of :data:`BLOCK` and each
block decoded at once.  Its readers raise their own errors for corrupt and truncated files:
they are said as :class:`~exsce_dsl.errors.BagError`\\ s.  A type's definition comes from the
bag (each connection's own: rosbags' typestore keeps one definition of a type, the last
connection's, where a bag holds two versions of it), else from the user's files, else from
rosbags' standard typestores.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from exsce_dsl.errors import BagError, DecodeError, MessageTypeError
from exsce_dsl.messages.catalogue import MessageCatalogue, Source, standard_catalogue
from exsce_dsl.messages.user import configured_user_catalogue
from exsce_dsl.model.messages import canonical_type
from exsce_dsl.runs.bags.data import OBJECTS, BagData, Check, Reduce, Wanted
from exsce_dsl.runs.bags.formats import BUILT_IN_FORMATS, ROS1_BAG, SQLITE3_FILE
from exsce_dsl.runs.bags.mcap import schema_catalogue
from exsce_dsl.runs.bags.mcap_index import Schema
from exsce_dsl.runs.bags.names import BagTopics
from exsce_dsl.runs.bags.objects import deserialized, deserializer_for
from exsce_dsl.runs.bags.raw_messages import RawMessages
from exsce_dsl.runs.bags.reader import BagReader
from exsce_dsl.runs.bags.reading_base import Reading

BLOCK = 4096
"""Messages decoded at a time from readers that hand out one message at a time (rosbags')."""


def typestore_for(path: Path):  # type: ignore[no-untyped-def]
    from rosbags.typesys import Stores, get_typestore

    ros2 = path.is_dir() or path.suffix in {f.suffix for f in BUILT_IN_FORMATS if f.in_folder}
    return get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)


def read_with_rosbags(
    path: Path, wanted: Mapping[str, Wanted], reduce: Mapping[str, Reduce] | None, check: Check | None
) -> BagData:
    """The ``wanted`` topics of the bag, read by rosbags' readers."""
    from rosbags.highlevel import AnyReader  # here: the index readers need none of rosbags' readers

    try:
        reader = AnyReader([path], default_typestore=typestore_for(path))
        reader.open()
    except Exception as exc:  # rosbags' readers raise their own errors for corrupt and truncated files
        raise BagError(f"{path}: cannot read the bag: {type(exc).__name__}: {exc}") from None
    try:
        if reader.message_count == 0:
            raise BagError(f"{path}: the bag holds no messages")
        reading = Reading(path, wanted, reduce, check)
        source = Source(f"the bag {path.name}")
        bag_types = MessageCatalogue()
        bag_types.add(reader.typestore.fielddefs, source)
        catalogue = bag_types.layered(configured_user_catalogue(), standard_catalogue())
        own: dict[tuple[str, str], MessageCatalogue] = {}
        cdr = not _is_ros1(path)
        by_topic: dict[str, list[Any]] = {}
        for conn in reader.connections:
            if conn.topic in reading.match and reading.accepts(conn.topic, conn.msgtype):
                by_topic.setdefault(conn.topic, []).append(conn)
        for _, conns in sorted(by_topic.items()):
            for conn in conns:
                types = _connection_types(conn, source, catalogue, own)
                _read_connection(reader, reading, conn, types, cdr)
        data = reading.data(
            reader.start_time / 1e9,
            reader.end_time / 1e9,
            tuple(sorted({c.topic for c in reader.connections})),
        )
    except (BagError, DecodeError, MessageTypeError):
        raise
    except Exception as exc:  # rosbags' readers raise their own errors for corrupt and truncated files
        raise BagError(f"{path}: cannot read the bag: {type(exc).__name__}: {exc}") from None
    finally:
        reader.close()
    return data


def _connection_types(
    conn: Any, source: Source, catalogue: MessageCatalogue, own: dict[tuple[str, str], MessageCatalogue]
) -> MessageCatalogue:
    """The types of ``conn``'s messages: its own definition first (once per definition, in
    ``own``), then the bag's, the user's and the standard ones (``catalogue``)."""
    from rosbags.interfaces import MessageDefinitionFormat

    msgdef = conn.msgdef
    if msgdef.format == MessageDefinitionFormat.NONE or not msgdef.data.strip():
        return catalogue
    key = (conn.msgtype, msgdef.data)
    if key not in own:
        encoding = "ros2idl" if msgdef.format == MessageDefinitionFormat.IDL else "ros2msg"
        mine = schema_catalogue(Schema(conn.msgtype, encoding, msgdef.data), source)
        own[key] = mine.layered(catalogue)
    return own[key]


def _publisher(conn: Any) -> str:
    """The node that published on ``conn`` (a ROS 1 connection's caller id), else its number."""
    return getattr(conn.ext, "callerid", None) or f"connection {conn.id}"


def _read_connection(
    reader: Any, reading: Reading, conn: Any, catalogue: MessageCatalogue, cdr: bool
) -> None:
    topic, msgtype = conn.topic, canonical_type(conn.msgtype)
    whole = reading.wanted_for(topic).msgtype == OBJECTS
    if not whole:
        reading.prepare(topic, msgtype, catalogue)
    store = deserializer_for(catalogue, msgtype) if whole else None

    for stamps, raws in _blocks(reader.messages(connections=[conn])):
        times = np.asarray(stamps, dtype=np.int64)
        if store is not None:
            read = store.deserialize_cdr if cdr else store.deserialize_ros1
            reading.add_whole(
                topic, times / 1e9, deserialized(functools.partial(read, typename=msgtype), raws, topic)
            )
        else:
            fields = reading.decode(topic, msgtype, catalogue, RawMessages.join(raws), cdr)
            reading.add(topic, msgtype, times, fields, _publisher(conn))


def _blocks(messages: Iterator[tuple[Any, int, bytes]]) -> Iterator[tuple[list[int], list[bytes]]]:
    stamps: list[int] = []
    raws: list[bytes] = []
    for _, timestamp, raw in messages:
        stamps.append(timestamp)
        raws.append(raw)
        if len(raws) == BLOCK:
            yield stamps, raws
            stamps, raws = [], []
    if raws:
        yield stamps, raws


def _is_ros1(path: Path) -> bool:
    return path.is_file() and path.suffix == ROS1_BAG.suffix


def _topics(path: Path) -> BagTopics:
    from rosbags.highlevel import AnyReader  # here: the index readers need none of rosbags' readers

    try:
        with AnyReader([path], default_typestore=typestore_for(path)) as reader:
            return BagTopics({c.topic: canonical_type(c.msgtype) for c in reader.connections})
    except Exception as exc:  # rosbags' readers raise their own errors for corrupt and truncated files
        raise BagError(f"{path}: cannot read the bag: {type(exc).__name__}: {exc}") from None


ROSBAGS = BagReader(
    "rosbags", claims=lambda path: True, read=read_with_rosbags, topics=_topics, formats=(SQLITE3_FILE,)
)
"""Every bag, by rosbags' readers: the last of the readers, which says what is broken."""
