"""What reading one bag needs, whatever its format: the shared base of every format's reader.

:class:`Reading` knows which of the bag's topics are read (for which wanted names), checks
their types and the fields the metrics read, decodes blocks of their messages into numpy
columns (:mod:`~exsce_dsl.runs.bags.decode`) and gathers them, in time order, into
:class:`~exsce_dsl.runs.bags.data.BagData`.  :class:`IndexReading` adds what the readers over
a format's own index share: a catalogue of message types per definition the bag carries, and
the decoder they hand each batch of a topic's messages to.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from exsce_dsl.errors import BagError
from exsce_dsl.messages.catalogue import MessageCatalogue
from exsce_dsl.messages.user import configured_user_catalogue
from exsce_dsl.model.messages import canonical_type, standard_type
from exsce_dsl.remedies import POINT_MSG_PATH
from exsce_dsl.runs.bags.data import OBJECTS, BagData, Check, Reduce, Series, Wanted
from exsce_dsl.runs.bags.decode import TEXTS, decode, decode_slowly, vectorisable
from exsce_dsl.runs.bags.names import TopicMatch
from exsce_dsl.runs.bags.objects import deserializer_for
from exsce_dsl.runs.bags.raw_messages import RawMessages


class _Topic:
    """The messages of one topic as they are decoded, block by block."""

    def __init__(self, topic: str, msgtype: str) -> None:
        self.topic = topic
        self.msgtype = msgtype
        self.times: list[np.ndarray] = []
        self.blocks: list[dict[str, np.ndarray]] = []
        self.texts: dict[str, int] = {}
        """The texts of the topic's text paths, in the order of their codes (every block's)."""
        self.publishers: dict[str, int] = {}
        """The topic's publishers (connections), in the order they were first met."""
        self.block_publishers: list[int] = []
        """Each block's publisher."""

    def add(
        self,
        times: np.ndarray,
        fields: dict[str, np.ndarray],
        text_keys: Sequence[str] = (),
        publisher: str = "",
    ) -> None:
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
        self.block_publishers.append(self.publishers.setdefault(publisher, len(self.publishers)))

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
        if len(self.publishers) < 2:
            return Series(self.topic, self.msgtype, times[order] / 1e9, fields)
        sizes = [len(t) for t in self.times]  # per block, not per message: a block is one publisher's
        publishers = np.repeat(np.array(self.block_publishers, dtype=np.int32), sizes)
        return Series(
            self.topic, self.msgtype, times[order] / 1e9, fields, publishers[order], tuple(self.publishers)
        )


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


class Reading:
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
        self.objects: dict[str, list[tuple[float, Any]]] = {}
        self.problems: list[str] = []
        self.checked: set[tuple[str, str, int]] = set()
        self.spellings: dict[str, list[str]] = {}
        self._wanted_for: dict[str, Wanted] = {}
        self.catalogues: dict[Hashable, MessageCatalogue] = {}
        """The types of each message type, as the bag defines it (see :class:`IndexReading`)."""

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
        if expected != OBJECTS and standard_type(msgtype) != standard_type(expected):
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
        """Check the fields the metrics read of ``topic`` against the type's definition, once per
        definition (``catalogue``: each version of a type the bag carries is checked)."""
        key = (topic, msgtype, id(catalogue))  # catalogues live as long as the reading
        if key in self.checked or self.wanted_for(topic).msgtype == OBJECTS:
            return
        lacking = catalogue.missing(msgtype)
        if lacking:
            raise BagError(
                f"{self.path}: no definition of {', '.join(lacking)} (topic {topic}): the bag carries none "
                "and no .msg/.idl file gives it",
                remedy=POINT_MSG_PATH,
            )
        if self.check is not None:
            tree, source = catalogue.tree(msgtype), catalogue.source_of(msgtype)
            for name in self.match.read_for(topic):
                self.check(name, canonical_type(msgtype), tree, source)
        self.checked.add(key)

    def add(
        self,
        topic: str,
        msgtype: str,
        times: np.ndarray,
        fields: dict[str, np.ndarray],
        publisher: str = "",
    ) -> None:
        """One block of ``publisher``'s messages on ``topic`` (a connection's: per connection,
        never per message)."""
        msgtype = canonical_type(msgtype)
        wanted = self.wanted_for(topic)
        text_keys = [p.key for p in wanted.texts]
        for name in self.match.read_for(topic):
            found = self.topics.setdefault(name, _Topic(name, msgtype))
            kept = dict(fields) if wanted.rows else _kept(dict(fields), name, self.reduce, text_keys)
            found.add(times, kept, text_keys, publisher)

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
        """Messages of a topic wanted as :data:`OBJECTS` (``times`` in seconds)."""
        for name in self.match.read_for(topic):
            self.objects.setdefault(name, []).extend(zip(times.tolist(), objects, strict=True))

    def data(self, start: float, end: float, topics: tuple[str, ...]) -> BagData:
        data = BagData(self.path, start, end, topics, problems=self.problems)
        data.spellings = {name: tuple(spelt) for name, spelt in self.spellings.items()}
        for topic, found in sorted(self.topics.items()):
            data.series[topic] = found.series()
        for topic, objects in sorted(self.objects.items()):
            data.messages[topic] = sorted(objects, key=lambda pair: pair[0])
        return data


class IndexReading(Reading):
    """A reading over a format's own index (ROS 1's, MCAP's), which hands :meth:`decoder` each
    batch of a wanted topic's messages with the definition the bag carries for them."""

    cdr = False
    """Whether the format's messages are CDR (ROS 2's) rather than ROS 1's."""

    def own_types(self, topic: str, msgtype: str, definition: str) -> MessageCatalogue:
        """The types the bag itself defines for ``topic``'s ``msgtype``, given its ``definition``."""
        raise NotImplementedError

    def standard_types(self) -> MessageCatalogue:
        """rosbags' standard types of the format's ROS."""
        raise NotImplementedError

    def catalogue_key(self, msgtype: str, definition: str) -> Hashable:
        """What one catalogue serves: a type as one definition defines it."""
        return (msgtype, definition)

    def catalogue(self, topic: str, msgtype: str, definition: str) -> MessageCatalogue:
        """The types of ``msgtype``: the bag's own definition, else the user's, else rosbags'."""
        key = self.catalogue_key(msgtype, definition)
        found = self.catalogues.get(key)
        if found is None:
            own = self.own_types(topic, msgtype, definition)
            found = self.catalogues[key] = own.layered(configured_user_catalogue(), self.standard_types())
        return found

    def keep_whole(self, topic: str, msgtype: str, definition: str) -> None:
        """A batch of a topic read whole is kept as bytes, to deserialize once all are read; what
        its deserializer needs of the batch's file is taken now (nothing, by default)."""

    def decoder(
        self,
        topic: str,
        msgtype: str,
        definition: str,
        times: np.ndarray,
        messages: RawMessages,
        publisher: str = "",
    ) -> bool:
        """Decode one batch's messages of a connection, by its own definition; False: keep their
        bytes (messages read whole)."""
        if not self.accepts(topic, msgtype):
            return True  # nothing kept
        if self.wanted_for(topic).msgtype == OBJECTS:
            self.keep_whole(topic, msgtype, definition)
            return False
        catalogue = self.catalogue(topic, msgtype, definition)
        self.prepare(topic, msgtype, catalogue)
        self.add(topic, msgtype, times, self.decode(topic, msgtype, catalogue, messages, self.cdr), publisher)
        return True
