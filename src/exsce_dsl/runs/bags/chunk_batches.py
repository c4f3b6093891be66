"""Chunks of a bag decoded together, a batch at a time; what the index readers hand the decoder.

The decoder's Python work is per call and per field, not per message, so a few large calls cost
less than one per chunk (rosbag writes 768 kB chunks, rosbags' MCAP writer 1 MiB ones): the index
readers gather consecutive chunks until they hold :data:`BATCH_BYTES`, then hand the decoder each
topic's messages of the whole batch at once, offsets into the chunks joined.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field

import numpy as np

from exsce_dsl.runs.bags.raw_messages import RawMessages

BATCH_BYTES = 8 << 20
"""Bytes of chunks (decompressed) a batch gathers before it is decoded: large enough that the
per-call work is amortised, small enough that memory stays a small part of the bag's size.  On
bench/ingest.py's bags 8 MB is as fast as 16 MB (Nav2: 1.66 s both) and peaks 45 MB lower on the
method's (113 against 159 MB for a 78 MB bag)."""

Decoder = Callable[[str, str, str, np.ndarray, RawMessages, str], bool]
"""(topic, message type, its definition, receive times in ns, its messages in a batch of chunks, their
publisher) → whether it took them; False keeps their raw bytes (for messages deserialized whole).
Each connection (channel) is handed with its own definition: two versions of one type on a topic
are two definitions.  The publisher names the connection within its topic (a ROS 1 connection's
caller id, else its number), so that each publisher's stamps can be judged on their own."""


@dataclass(frozen=True)
class Messages:
    """One topic's messages: receive times (ns, bag order), and the raw bytes of each message the
    decoder did not take."""

    msgtype: str
    definition: str  # the definition the bag carries (ROS 1's concatenated form, an MCAP schema's text)
    times: np.ndarray
    raws: list[bytes]


@dataclass
class ChunkBatch:
    """Consecutive chunks not yet decoded, with the wanted messages in each, per key (a
    connection, a channel)."""

    chunks: list[np.ndarray] = field(default_factory=list)
    size: int = 0
    entries: dict[int, list[tuple[np.ndarray, np.ndarray, np.ndarray]]] = field(default_factory=dict)

    def add(self, key: int, times: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> None:
        """Messages of the chunk being read: receive times, and offsets into that chunk."""
        self.entries.setdefault(key, []).append((times, starts + self.size, ends + self.size))

    def close_chunk(self, chunk: np.ndarray) -> None:
        """The chunk being read is done: the next one's offsets start after it."""
        self.chunks.append(chunk)
        self.size += len(chunk)

    @property
    def full(self) -> bool:
        return self.size >= BATCH_BYTES

    def messages(self) -> Iterator[tuple[int, np.ndarray, RawMessages]]:
        """Each key's receive times and messages in the batch, in chunk order."""
        if not self.entries:
            return
        joined = self.chunks[0] if len(self.chunks) == 1 else np.concatenate(self.chunks)
        for key, parts in self.entries.items():
            times = np.concatenate([t for t, _, _ in parts])
            starts = np.concatenate([a for _, a, _ in parts])
            ends = np.concatenate([b for _, _, b in parts])
            yield key, times, RawMessages(joined, starts, ends)


class Gathered:
    """What an index reader gathers of each key's messages (a connection's, a channel's), batch by
    batch: their receive times, and the bytes of those the decoder did not take."""

    def __init__(self, names: Mapping[int, tuple[str, str, str, str]], decoder: Decoder) -> None:
        self.names = names
        """Key → (topic, message type, its definition, its publisher), in the order the topics are merged."""
        self.decoder = decoder
        self.times: dict[int, list[np.ndarray]] = {key: [] for key in names}
        self.raws: dict[int, list[bytes]] = {key: [] for key in names}

    def decode(self, batch: ChunkBatch) -> None:
        """Hand each key's messages of ``batch`` to the decoder; keep the bytes it does not take."""
        for key, times, messages in batch.messages():
            topic, msgtype, definition, publisher = self.names[key]
            if not self.decoder(topic, msgtype, definition, times, messages, publisher):
                self.raws[key].extend(messages.raws())
            self.times[key].append(times)

    def count(self, key: int) -> int:
        """How many of ``key``'s messages were read."""
        return sum(len(t) for t in self.times[key])

    def by_key(self) -> Iterator[tuple[str, Messages]]:
        """Each key's topic and messages (keys none of whose messages were read left out): each
        with its own definition, for the messages deserialized whole."""
        for key, (topic, msgtype, definition, _) in self.names.items():
            if self.times[key]:
                yield topic, Messages(msgtype, definition, np.concatenate(self.times[key]), self.raws[key])

    def by_topic(self) -> dict[str, Messages]:
        """Each topic's messages, those of several keys on one topic merged (the definition
        said is the first key's: :meth:`by_key` keeps each key's)."""
        out: dict[str, Messages] = {}
        for topic, messages in self.by_key():
            known = out.get(topic)
            if known is not None:  # several connections (channels) on one topic: its messages merged
                times = np.concatenate([known.times, messages.times])
                out[topic] = Messages(known.msgtype, known.definition, times, known.raws + messages.raws)
            else:
                out[topic] = messages
        return out
