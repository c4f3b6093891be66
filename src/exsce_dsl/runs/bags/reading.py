"""Read the topics a run's metrics need from a bag (ROS 1, ROS 2 sqlite3, MCAP).

Only the needed connections are read, and of their messages only the fields
the metrics read (:mod:`exsce_dsl.runs.bags.decode`, a decoder driven by the
message definition).  A type's definition comes from the bag itself (a ROS 1
connection's definition, an MCAP schema, a ROS 2 bag's type descriptions),
else from the user's ``.msg``/``.idl`` files, else from rosbags' standard
typestores, per connection: two versions of one type in a bag are decoded each by
its own.  Several connections on one topic are merged, each message's connection
kept where there are several (:attr:`Series.publishers`, whose stamps are judged
apart), and every topic's messages are put in time order.  Topics wanted as message objects (a
navigation stack's few goals and statuses) are deserialized by rosbags.

Each format has its reader (:mod:`~exsce_dsl.runs.bags.reader`), and :data:`BAG_READERS` holds
them: exsce's, the plug-ins', rosbags' last (:func:`readers`, in the order they are tried).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from exsce_dsl.errors import BagError, CorruptBag, DecodeError, MessageTypeError, UnsupportedBag
from exsce_dsl.plugins import Registry
from exsce_dsl.runs.bags.data import BagData, Check, Reduce, Wanted
from exsce_dsl.runs.bags.files import check_bag_file
from exsce_dsl.runs.bags.formats import BagFormat, is_ros2_folder
from exsce_dsl.runs.bags.mcap import MCAP
from exsce_dsl.runs.bags.names import BagTopics
from exsce_dsl.runs.bags.reader import BagReader
from exsce_dsl.runs.bags.ros1 import ROS1
from exsce_dsl.runs.bags.rosbags_fallback import ROSBAGS


def _accepted(name: str, loaded: object) -> BagReader | None:
    made = loaded() if callable(loaded) and not isinstance(loaded, BagReader) else loaded
    return made if isinstance(made, BagReader) and made.name == name else None


BAG_READERS: Registry[BagReader] = Registry(
    "bag reader", ((r.name, r) for r in (ROS1, MCAP, ROSBAGS)), _accepted, "a BagReader"
)
"""exsce's bag readers and the plug-ins' (:mod:`exsce_dsl.plugins`), by name."""


def readers() -> tuple[BagReader, ...]:
    """The readers in the order they are tried: the first that claims a bag reads it, and one
    that raises :class:`UnsupportedBag` passes it on; rosbags', last, reads every bag."""
    return (*(r for r in BAG_READERS.entries().values() if r is not ROSBAGS), ROSBAGS)


def bag_formats() -> tuple[BagFormat, ...]:
    """Every file format a reader reads, each once, in the readers' order."""
    return tuple(dict.fromkeys(f for reader in readers() for f in reader.formats))


def is_bag(path: Path) -> bool:
    """Whether ``path`` is named as a bag is (a reader's format's suffix), or is a ROS 2 bag
    folder; nothing is read but whether a folder holds a bag's metadata."""
    return names_a_bag(str(path)) or is_ros2_folder(path)


def names_a_bag(text: str) -> bool:
    """Whether ``text``, a path not looked at, ends in a bag format's suffix."""
    return Path(text).suffix in {f.suffix for f in bag_formats()}


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
    _check_once(_existing(path))
    return _read(path, wanted, reduce, check)


def _read(
    path: Path, wanted: Mapping[str, Wanted], reduce: Mapping[str, Reduce] | None, check: Check | None
) -> BagData:
    """:func:`read_bag` of a bag already checked: the first reader that claims it reads it."""
    try:
        for reader in readers():
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


@dataclass(frozen=True)
class OpenedBag:
    """A bag looked at once: checked, its topics and their types known from its own index
    (nothing decoded); :meth:`read` reads what is wanted of it.  Analysis opens a bag here, in
    the bags step, and hands it to the signals step, which reads what the robots' conventions and
    the metrics want: the walk does not come back to the bags step to read."""

    path: Path
    topics: BagTopics

    def read(
        self,
        wanted: Mapping[str, Wanted],
        reduce: Mapping[str, Reduce] | None = None,
        check: Check | None = None,
    ) -> BagData:
        """:func:`read_bag` of this bag, not checked again."""
        return _read(self.path, wanted, reduce, check)


def open_bag(path: Path) -> OpenedBag:
    """The bag at ``path``, checked and its topics listed (:func:`bag_topics`)."""
    return OpenedBag(path, bag_topics(path))


def bag_topics(path: Path) -> BagTopics:
    """Topic → its message type (ROS 2 spelling), from the bag's own index (nothing decoded); a
    topic is found by any name that reads it (:mod:`~exsce_dsl.runs.bags.names`)."""
    _check_once(_existing(path))
    for reader in readers():
        if reader.topics is not None and reader.claims(path):
            try:
                return reader.topics(path)
            except UnsupportedBag:
                pass  # the next reader lists what this one does not (rosbags says what is broken)
    raise BagError(f"{path}: no reader lists the bag's topics")  # pragma: no cover (rosbags lists all)


def _existing(path: Path) -> Path:
    """``path``, or a :class:`BagError` saying there is no such bag."""
    if not path.exists():
        raise BagError(f"{path}: no such bag")
    return path


def _check_once(path: Path) -> None:
    """:func:`~exsce_dsl.runs.bags.files.check_bag_file`, once per file as it is (``bag info`` lists a
    bag's topics, then reads it: 80 ms a check on a 100 MB bag; an :class:`OpenedBag` is read
    unchecked, as it was checked when opened)."""
    if not path.is_file():
        check_bag_file(path, bag_formats())
        return
    status = path.stat()
    key = (str(path.resolve()), status.st_size, status.st_mtime_ns)
    if key not in _CHECKED:
        check_bag_file(path, bag_formats())
        _CHECKED.add(key)


_CHECKED: set[tuple[str, int, int]] = set()
"""Bag files that passed :func:`_check_once`, by path, size and modification time."""
