"""Read the topics a run's metrics need from a bag (ROS 1, ROS 2 sqlite3, MCAP).

Only the needed connections are read, and of their messages only the fields
the metrics read (:mod:`exsce_dsl.runs.bags.decode`, a decoder driven by the
message definition).  A type's definition comes from the bag itself (a ROS 1
connection's definition, an MCAP schema, a ROS 2 bag's type descriptions),
else from the user's ``.msg``/``.idl`` files, else from rosbags' standard
typestores, per connection: two versions of one type in a bag are decoded each by
its own.  Several connections on one topic are merged, each message's connection
kept where there are several (:attr:`Series.publishers`, whose stamps are judged
apart), and every topic's messages are put in time order.  The dispatcher's few feedback and result
messages are deserialized by rosbags.

Each format has its reader (:mod:`~exsce_dsl.runs.bags.reader`), and :data:`READERS` lists
them in the order they are tried.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from exsce_dsl.errors import BagError as BagError
from exsce_dsl.errors import CorruptBag
from exsce_dsl.messages.catalogue import MessageTypeError
from exsce_dsl.runs.bags.data import ANY as ANY
from exsce_dsl.runs.bags.data import OBJECTS as OBJECTS
from exsce_dsl.runs.bags.data import WHOLE as WHOLE
from exsce_dsl.runs.bags.data import BagData as BagData
from exsce_dsl.runs.bags.data import Check as Check
from exsce_dsl.runs.bags.data import Reduce as Reduce
from exsce_dsl.runs.bags.data import Series as Series
from exsce_dsl.runs.bags.data import StatusUpdate as StatusUpdate
from exsce_dsl.runs.bags.data import Wanted as Wanted
from exsce_dsl.runs.bags.decode import DecodeError
from exsce_dsl.runs.bags.files import check_bag_file
from exsce_dsl.runs.bags.mcap import MCAP
from exsce_dsl.runs.bags.names import BagTopics
from exsce_dsl.runs.bags.objects import LazyMessage as LazyMessage
from exsce_dsl.runs.bags.reader import BagReader, UnsupportedBag
from exsce_dsl.runs.bags.ros1 import ROS1
from exsce_dsl.runs.bags.rosbags_fallback import ROSBAGS

READERS: tuple[BagReader, ...] = (ROS1, MCAP, ROSBAGS)
"""The bag formats' readers, in the order they are tried: the first that claims a bag reads it,
and one that raises :class:`UnsupportedBag` passes it on; rosbags', last, reads every bag."""


def read_bag(
    path: Path,
    wanted: Mapping[str, Wanted],
    reduce: Mapping[str, Reduce] | None = None,
    check: Check | None = None,
) -> BagData:
    """Read the ``wanted`` topics.

    ``reduce`` (topic → function) is applied to each block of decoded messages as
    it is read, so that large arrays (laser ranges) are reduced per message and
    never all held at once; given a ``reduce``, array fields are not kept (what
    is needed of them is reduced).  Without it, every wanted field is kept.
    """
    if not path.exists():
        raise BagError(f"{path}: no such bag")
    _check_once(path)
    try:
        for reader in READERS:
            if reader.claims(path):
                try:
                    return reader.read(path, wanted, reduce, check)
                except UnsupportedBag:
                    pass  # the next reader reads what this one does not (rosbags says what is broken)
        raise BagError(f"{path}: no reader claims the bag")  # pragma: no cover (rosbags claims every bag)
    except BagError as exc:
        if str(path) in exc.message:
            raise
        raise BagError(f"{path}: {exc.message}") from None
    except (DecodeError, MessageTypeError, CorruptBag) as exc:
        raise BagError(f"{path}: {exc.message}") from None


def bag_topics(path: Path) -> BagTopics:
    """Topic → its message type (ROS 2 spelling), from the bag's own index (nothing decoded); a
    topic is found by any name that reads it (:mod:`~exsce_dsl.runs.bags.names`)."""
    if not path.exists():
        raise BagError(f"{path}: no such bag")
    _check_once(path)
    for reader in READERS:
        if reader.topics is not None and reader.claims(path):
            try:
                return reader.topics(path)
            except UnsupportedBag:
                pass  # the next reader lists what this one does not (rosbags says what is broken)
    raise BagError(f"{path}: no reader lists the bag's topics")  # pragma: no cover (rosbags lists all)


def _check_once(path: Path) -> None:
    """:func:`~exsce_dsl.runs.bags.files.check_bag_file`, once per file as it is (ingest lists a
    bag's topics, then reads it: 80 ms a check on a 100 MB bag)."""
    if not path.is_file():
        check_bag_file(path)
        return
    status = path.stat()
    key = (str(path.resolve()), status.st_size, status.st_mtime_ns)
    if key not in _CHECKED:
        check_bag_file(path)
        _CHECKED.add(key)


_CHECKED: set[tuple[str, int, int]] = set()
"""Bag files that passed :func:`_check_once`, by path, size and modification time."""
