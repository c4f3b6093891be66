"""Read the topics a run's metrics need from a bag (ROS 1, ROS 2 sqlite3, MCAP).

Only the needed connections are read, and of their messages only the fields
the metrics read (:mod:`exsce_dsl.runs.bags.decode`, a decoder driven by the
message definition).  A type's definition comes from the bag itself (a ROS 1
connection's definition, an MCAP schema, a ROS 2 bag's type descriptions),
else from the user's ``.msg``/``.idl`` files, else from rosbags' standard
typestores.  Several connections on one topic are merged, and every topic's
messages are put in time order.  The dispatcher's few feedback and result
messages are deserialized by rosbags.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from exsce_dsl.errors import BagError as BagError
from exsce_dsl.messages.catalogue import (
    MessageCatalogue,
    MessageTypeError,
    Source,
    parse_definition,
    standard_catalogue,
    standard_ros1_catalogue,
)
from exsce_dsl.messages.user import configured_user_catalogue
from exsce_dsl.model.messages import FieldPath, Fields, canonical_type
from exsce_dsl.model.runs import MetricValue
from exsce_dsl.runs.bags.decode import TEXTS, DecodeError, RawMessages, decode, decode_slowly, vectorisable
from exsce_dsl.runs.bags.mcap_index import CorruptBag
from exsce_dsl.runs.bags.names import BagTopics, TopicMatch
from exsce_dsl.runs.bags.objects import LazyMessage as LazyMessage
from exsce_dsl.runs.bags.objects import deserialized, deserializer_for
from exsce_dsl.runs.bags.ros1_index import UnsupportedBag, connections, read_topics

_PROGRESS = {0: 0, 1: 1}  # PENDING, ACTIVE; every other status is final
BLOCK = 4096
"""Messages decoded at a time from readers that hand out one message at a time (rosbags')."""
ANY = "*"
"""The expected type of the dispatcher's topics: whatever the bag says, deserialized whole."""
OBJECTS = "**"
"""The expected type of topics kept as message objects (a navigation stack's goals and statuses:
few messages, read by attribute): whatever the bag says, in :attr:`BagData.messages`."""
WHOLE = (ANY, OBJECTS)


@dataclass(frozen=True)
class Wanted:
    """What is read of one topic: its expected type (``*``: the dispatcher's, read whole) and
    the field paths the metrics use."""

    msgtype: str
    paths: tuple[FieldPath, ...] = ()
    texts: tuple[FieldPath, ...] = ()
    """Paths to texts (TF frame ids): their values are codes into the series' ``fields[TEXTS]``."""
    rows: bool = False
    """Keep rows of arrays even where blocks are reduced (a TFMessage's transforms: few a message)."""


@dataclass(frozen=True)
class Series:
    """One topic: receive times (seconds since the epoch, sorted) and decoded fields by key."""

    topic: str
    msgtype: str
    t: np.ndarray
    fields: Mapping[str, np.ndarray]

    def __len__(self) -> int:
        return len(self.t)


@dataclass(frozen=True)
class StatusUpdate:
    """A dispatcher feedback or result: the status of each waypoint of one goal."""

    t: float
    goal: str  # the actionlib goal id (may be empty)
    waypoints: tuple[str, ...]
    statuses: tuple[int, ...]


@dataclass
class BagData:
    path: Path
    start: float
    end: float
    topics: tuple[str, ...]
    series: dict[str, Series] = field(default_factory=dict)
    feedback: dict[str, list[StatusUpdate]] = field(default_factory=dict)  # topic -> updates
    results: dict[str, list[StatusUpdate]] = field(default_factory=dict)
    messages: dict[str, list[tuple[float, Any]]] = field(default_factory=dict)
    """Topics wanted as :data:`OBJECTS`: (receive time, rosbags message object), in time order."""
    problems: list[str] = field(default_factory=list)
    spellings: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """A wanted name → the bag's topics read for it, as the bag spells them (see ``bags.names``)."""

    def spelt(self, value: MetricValue) -> MetricValue:
        """``value`` with its topics named as the bag spells them (``groundtruth`` for a
        specification's ``/groundtruth``)."""
        if all(self.spellings.get(t, (t,)) == (t,) for t in value.topics):
            return value
        named = [real for t in value.topics for real in self.spellings.get(t, (t,))]
        return replace(value, topics=tuple(dict.fromkeys(named)))


def typestore_for(path: Path):  # type: ignore[no-untyped-def]
    from rosbags.typesys import Stores, get_typestore

    ros2 = path.is_dir() or path.suffix in (".db3", ".mcap")
    return get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)


Reduce = Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]]
"""Turns a block of decoded messages into the fields kept of them (arrays reduced per message)."""

Check = Callable[[str, str, Fields, Source | None], None]
"""(topic, message type, its fields, where the definition came from) → raises if the metrics read
a field the type does not have; called before any message of the topic is decoded."""


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
        if _is_ros1(path):
            try:
                return _Ros1(path, wanted, reduce, check).read()
            except UnsupportedBag:
                pass  # rosbags reads what our index reader does not (and reports what is broken)
        # MCAP's own index, read with numpy like ROS 1's; its reading class builds on this module's
        from exsce_dsl.runs.bags.mcap_reading import Mcap, mcap_files

        files = mcap_files(path)
        if files is not None:
            try:
                return Mcap(path, wanted, reduce, check).read(files)
            except UnsupportedBag:
                pass  # files without a summary, chunk or message indexes: rosbags reads them
        return _read_with_rosbags(path, wanted, reduce, check)
    except BagError as exc:
        if str(path) in exc.message:
            raise
        raise BagError(f"{path}: {exc.message}") from None
    except (DecodeError, MessageTypeError, CorruptBag) as exc:
        raise BagError(f"{path}: {exc.message}") from None


def _check_once(path: Path) -> None:
    """:func:`~exsce_dsl.runs.bags.files.check_bag_file`, once per file as it is (ingest lists a
    bag's topics, then reads it: 80 ms a check on a 100 MB bag)."""
    from exsce_dsl.runs.bags.files import check_bag_file  # here: bagfiles imports this module's BagError

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


def bag_topics(path: Path) -> BagTopics:
    """Topic → its message type (ROS 2 spelling), from the bag's own index (nothing decoded); a
    topic is found by any name that reads it (:mod:`~exsce_dsl.runs.bags.names`)."""
    if not path.exists():
        raise BagError(f"{path}: no such bag")
    _check_once(path)
    if _is_ros1(path):
        try:  # the bag's own index: rosbags would read every chunk's index first
            return BagTopics({topic: canonical_type(msgtype) for topic, msgtype in connections(path).items()})
        except UnsupportedBag:
            pass  # rosbags reads what the index reader does not, and says what is broken
    from rosbags.highlevel import AnyReader  # here: the index readers need none of rosbags' readers

    try:
        with AnyReader([path], default_typestore=typestore_for(path)) as reader:
            return BagTopics({c.topic: canonical_type(c.msgtype) for c in reader.connections})
    except Exception as exc:  # rosbags' readers raise their own errors for corrupt and truncated files
        raise BagError(f"{path}: cannot read the bag: {type(exc).__name__}: {exc}") from None


class _Topic:
    """The messages of one topic as they are decoded, block by block."""

    def __init__(self, topic: str, msgtype: str) -> None:
        self.topic = topic
        self.msgtype = msgtype
        self.times: list[np.ndarray] = []
        self.blocks: list[dict[str, np.ndarray]] = []
        self.texts: dict[str, int] = {}
        """The texts of the topic's text paths, in the order of their codes (every block's)."""

    def add(self, times: np.ndarray, fields: dict[str, np.ndarray], text_keys: Sequence[str] = ()) -> None:
        if TEXTS in fields:  # each block codes its own texts: recode them into the topic's table
            table = fields.pop(TEXTS)
            recode = np.array(
                [self.texts.setdefault(str(t), len(self.texts)) for t in table] + [-1], dtype=float
            )
            for key in text_keys:
                codes = fields[key]
                at = np.where(np.isnan(codes), -1, codes).astype(np.int64)
                fields[key] = np.where(at < 0, np.nan, recode[at])
        self.times.append(times)
        self.blocks.append(fields)

    def series(self) -> Series:
        times = np.concatenate(self.times) if self.times else np.zeros(0, dtype=np.int64)
        order = np.argsort(times, kind="stable")  # recordings out of time order are put in order
        in_order = bool(np.all(order[1:] > order[:-1]))
        fields = {}
        for key in self.blocks[0] if self.blocks else {}:
            values = _concatenate([b[key] for b in self.blocks])
            fields[key] = values if in_order else values[order]
        if self.texts:
            fields[TEXTS] = np.array(list(self.texts), dtype=object)
        return Series(self.topic, self.msgtype, times[order] / 1e9, fields)


def _concatenate(parts: Sequence[np.ndarray]) -> np.ndarray:
    """Blocks of one field joined; rows of arrays padded with NaN to the widest block."""
    if len(parts) == 1:
        return parts[0]
    if parts[0].ndim != 2 or all(p.shape[1] == parts[0].shape[1] for p in parts):
        return np.concatenate(parts)
    width = max(p.shape[1] for p in parts)  # one copy into the padded table, not a padded copy a block
    joined = np.full((sum(len(p) for p in parts), width), np.nan, dtype=np.result_type(*parts))
    at = 0
    for part in parts:
        joined[at : at + len(part), : part.shape[1]] = part
        at += len(part)
    return joined


def _kept(
    fields: dict[str, np.ndarray], topic: str, reduce: Mapping[str, Reduce] | None, text_keys: Sequence[str]
) -> dict[str, np.ndarray]:
    if reduce is None:
        return fields
    if topic in reduce:
        fields = reduce[topic](fields)
    return {k: v for k, v in fields.items() if v.ndim == 1 or k == TEXTS or k in text_keys}


class _Reading:
    """What reading one bag needs, whatever its format: which topics, how to decode and check.

    The bag's topics are read for the wanted names that name them (:class:`TopicMatch`): the
    readers hand in the bag's names, the data goes under the wanted ones."""

    def __init__(
        self,
        path: Path,
        wanted: Mapping[str, Wanted],
        reduce: Mapping[str, Reduce] | None,
        check: Check | None,
    ) -> None:
        self.path = path
        self.wanted = wanted
        self.match = TopicMatch(wanted)
        self.reduce = reduce
        self.check = check
        self.topics: dict[str, _Topic] = {}
        self.updates: dict[str, list[StatusUpdate]] = {}
        self.objects: dict[str, list[tuple[float, Any]]] = {}
        self.problems: list[str] = []
        self.checked: set[tuple[str, str]] = set()
        self.spellings: dict[str, list[str]] = {}
        self._wanted_for: dict[str, Wanted] = {}

    def wanted_for(self, topic: str) -> Wanted:
        """What is read of the bag's ``topic``: what the names that read it want, together."""
        found = self._wanted_for.get(topic)
        if found is None:
            names = self.match.read_for(topic)
            found = self.wanted[names[0]]
            for name in names[1:]:
                more = self.wanted[name]
                found = Wanted(
                    found.msgtype,
                    tuple(dict.fromkeys([*found.paths, *more.paths])),
                    tuple(dict.fromkeys([*found.texts, *more.texts])),
                    found.rows or more.rows,
                )
            self._wanted_for[topic] = found
        return found

    def accepts(self, topic: str, msgtype: str) -> bool:
        """Whether the connection of ``topic`` with ``msgtype`` is read (a problem says why not)."""
        expected = self.wanted_for(topic).msgtype
        msgtype = canonical_type(msgtype)
        if expected not in WHOLE and msgtype != canonical_type(expected):
            problem = f"topic {topic} carries {msgtype}, not {expected}: its metrics are missing"
            if problem not in self.problems:
                self.problems.append(problem)
            return False
        for name in self.match.read_for(topic):
            found = self.topics.get(name)
            if found is not None and found.msgtype != msgtype:
                raise BagError(f"{self.path}: topic {topic} carries both {found.msgtype} and {msgtype}")
            spelt = self.spellings.setdefault(name, [])
            if topic not in spelt:
                spelt.append(topic)
        return True

    def prepare(self, topic: str, msgtype: str, catalogue: MessageCatalogue) -> None:
        """Check the fields the metrics read of ``topic`` against the type's definition, once."""
        if (topic, msgtype) in self.checked or self.wanted_for(topic).msgtype in WHOLE:
            return
        lacking = catalogue.missing(msgtype)
        if lacking:
            raise BagError(
                f"{self.path}: no definition of {', '.join(lacking)} (topic {topic}): the bag carries none "
                "and no .msg/.idl file gives it; point EXSCE_MSG_PATH (or exscec --msg-path) at a folder "
                "of message packages"
            )
        if self.check is not None:
            tree, source = catalogue.tree(msgtype), catalogue.source_of(msgtype)
            for name in self.match.read_for(topic):
                self.check(name, canonical_type(msgtype), tree, source)
        self.checked.add((topic, msgtype))

    def add(
        self,
        topic: str,
        msgtype: str,
        times: np.ndarray,
        fields: dict[str, np.ndarray],
    ) -> None:
        msgtype = canonical_type(msgtype)
        wanted = self.wanted_for(topic)
        text_keys = [p.key for p in wanted.texts]
        for name in self.match.read_for(topic):
            found = self.topics.setdefault(name, _Topic(name, msgtype))
            kept = dict(fields) if wanted.rows else _kept(dict(fields), name, self.reduce, text_keys)
            found.add(times, kept, text_keys)

    def decode(
        self, topic: str, msgtype: str, catalogue: MessageCatalogue, messages: RawMessages, cdr: bool
    ) -> dict[str, np.ndarray]:
        """The wanted fields of one block of ``topic``'s messages: vectorised, or by rosbags
        where :func:`decode` cannot (``wstring`` and ``float128`` fields)."""
        wanted = self.wanted_for(topic)
        if vectorisable(catalogue, msgtype):
            return decode(catalogue, msgtype, messages, wanted.paths, cdr, wanted.texts)
        store = deserializer_for(catalogue, msgtype)
        raws = messages.raws()
        read = store.deserialize_cdr if cdr else store.deserialize_ros1
        return decode_slowly(lambda raw: read(raw, msgtype), raws, wanted.paths, wanted.texts)

    def add_whole(self, topic: str, times: np.ndarray, objects: Sequence[Any]) -> None:
        """Messages of a topic wanted whole (``times`` in seconds): the dispatcher's statuses, or
        the objects themselves."""
        if self.wanted_for(topic).msgtype == OBJECTS:
            for name in self.match.read_for(topic):
                self.objects.setdefault(name, []).extend(zip(times.tolist(), objects, strict=True))
        else:
            updates = [_status_update(m, t, topic) for m, t in zip(objects, times.tolist(), strict=True)]
            for name in self.match.read_for(topic):
                self.updates.setdefault(name, []).extend(updates)

    def data(self, start: float, end: float, topics: tuple[str, ...]) -> BagData:
        data = BagData(self.path, start, end, topics, problems=self.problems)
        data.spellings = {name: tuple(spelt) for name, spelt in self.spellings.items()}
        for topic, found in sorted(self.topics.items()):
            data.series[topic] = found.series()
        for topic, updates in sorted(self.updates.items()):
            # statuses only move forward: updates recorded at the same instant go in that order
            updates.sort(key=lambda u: (u.t, sum(_PROGRESS.get(s, 2) for s in u.statuses)))
            (data.results if topic.endswith("/result") else data.feedback)[topic] = updates
        for topic, objects in sorted(self.objects.items()):
            data.messages[topic] = sorted(objects, key=lambda pair: pair[0])
        return data


class _Ros1(_Reading):
    """The fast path for ROS 1 bags: the bag's own index, numpy gathers, no per-message Python."""

    def read(self) -> BagData:
        self.catalogues: dict[str, MessageCatalogue] = {}
        found = read_topics(self.path, self.match, self._decoder)
        if not found:
            raise UnsupportedBag("none of the topics")  # rosbags then says whether the bag is empty
        start = min(int(m.times.min()) for m in found.values())
        end = max(int(m.times.max()) for m in found.values())
        for topic, messages in sorted(found.items()):
            if not messages.raws:
                continue
            store = deserializer_for(self._catalogue(messages.msgtype, messages.definition), messages.msgtype)
            order = np.argsort(messages.times, kind="stable")
            read = functools.partial(store.deserialize_ros1, typename=messages.msgtype)
            lazy = topic if self.wanted_for(topic).msgtype == OBJECTS else None
            objects = deserialized(read, [messages.raws[i] for i in order.tolist()], lazy)
            self.add_whole(topic, messages.times[order] / 1e9, objects)
        return self.data(start / 1e9, end / 1e9, tuple(sorted(found)))

    def _catalogue(self, msgtype: str, definition: str) -> MessageCatalogue:
        if msgtype not in self.catalogues:
            source = Source(f"the bag {self.path.name}")
            own = MessageCatalogue()
            if definition.strip():
                own = parse_definition(definition, msgtype, "msg", source)
            self.catalogues[msgtype] = own.layered(configured_user_catalogue(), standard_ros1_catalogue())
        return self.catalogues[msgtype]

    def _decoder(
        self, topic: str, msgtype: str, definition: str, times: np.ndarray, messages: RawMessages
    ) -> bool:
        """Decode one chunk's messages of a topic; False: keep their bytes (the dispatcher's)."""
        if not self.accepts(topic, msgtype):
            return True  # nothing kept
        if self.wanted_for(topic).msgtype in WHOLE:
            return False
        catalogue = self._catalogue(msgtype, definition)
        self.prepare(topic, msgtype, catalogue)
        self.add(topic, msgtype, times, self.decode(topic, msgtype, catalogue, messages, cdr=False))
        return True


def _read_with_rosbags(
    path: Path, wanted: Mapping[str, Wanted], reduce: Mapping[str, Reduce] | None, check: Check | None
) -> BagData:
    from rosbags.highlevel import AnyReader

    try:
        reader = AnyReader([path], default_typestore=typestore_for(path))
        reader.open()
    except Exception as exc:  # rosbags' readers raise their own errors for corrupt and truncated files
        raise BagError(f"{path}: cannot read the bag: {type(exc).__name__}: {exc}") from None
    try:
        if reader.message_count == 0:
            raise BagError(f"{path}: the bag holds no messages")
        reading = _Reading(path, wanted, reduce, check)
        bag_types = MessageCatalogue()
        bag_types.add(reader.typestore.fielddefs, Source(f"the bag {path.name}"))
        catalogue = bag_types.layered(configured_user_catalogue(), standard_catalogue())
        cdr = not _is_ros1(path)
        by_topic: dict[str, list[Any]] = {}
        for conn in reader.connections:
            if conn.topic in reading.match and reading.accepts(conn.topic, conn.msgtype):
                by_topic.setdefault(conn.topic, []).append(conn)
        for _, conns in sorted(by_topic.items()):
            for conn in conns:
                _read_connection(reader, reading, conn, catalogue, cdr)
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


def _read_connection(
    reader: Any, reading: _Reading, conn: Any, catalogue: MessageCatalogue, cdr: bool
) -> None:
    topic, msgtype = conn.topic, canonical_type(conn.msgtype)
    whole = reading.wanted_for(topic).msgtype in WHOLE
    if not whole:
        reading.prepare(topic, msgtype, catalogue)
    store = deserializer_for(catalogue, msgtype) if whole else None

    for stamps, raws in _blocks(reader.messages(connections=[conn])):
        times = np.asarray(stamps, dtype=np.int64)
        if store is not None:
            read = store.deserialize_cdr if cdr else store.deserialize_ros1
            lazy = topic if reading.wanted_for(topic).msgtype == OBJECTS else None
            reading.add_whole(
                topic, times / 1e9, deserialized(functools.partial(read, typename=msgtype), raws, lazy)
            )
        else:
            reading.add(
                topic, msgtype, times, reading.decode(topic, msgtype, catalogue, RawMessages.join(raws), cdr)
            )


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
    return path.is_file() and path.suffix == ".bag"


def _status_update(msg: Any, t: float, topic: str) -> StatusUpdate:
    try:
        payload = getattr(msg, "feedback", None) or msg.result
        status_list = payload.goal_status.status_list
        goal = getattr(getattr(msg, "status", None), "goal_id", None)
    except AttributeError:
        raise BagError(f"topic {topic} does not carry the waypoint dispatcher's goal statuses") from None
    return StatusUpdate(
        t,
        getattr(goal, "id", "") or "",
        tuple(str(s.goal_id.id) for s in status_list),
        tuple(int(s.status) for s in status_list),
    )
