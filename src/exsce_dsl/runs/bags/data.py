"""What reading a bag is asked (:class:`Wanted` topics) and what it gives (:class:`BagData`),
whatever the bag's format."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from exsce_dsl.messages.catalogue import Source
from exsce_dsl.model.messages import FieldPath, Fields

OBJECTS = "**"
"""The expected type of topics kept as message objects (a navigation stack's goals and statuses:
few messages, read by attribute): whatever the bag says, in :attr:`BagData.messages`."""


@dataclass(frozen=True)
class Wanted:
    """What is read of one topic: its expected type (:data:`OBJECTS`: kept as message objects)
    and the field paths the metrics use."""

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
    publishers: np.ndarray | None = None
    """Where the topic has several publishers (connections, channels): each message's, an index
    into :attr:`publisher_names` (its clock is judged per publisher); None: one publisher."""
    publisher_names: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.t)


@dataclass
class BagData:
    path: Path
    start: float
    end: float
    topics: tuple[str, ...]
    series: dict[str, Series] = field(default_factory=dict)
    messages: dict[str, list[tuple[float, Any]]] = field(default_factory=dict)
    """Topics wanted as :data:`OBJECTS`: (receive time, rosbags message object), in time order."""
    problems: list[str] = field(default_factory=list)
    spellings: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """A wanted name → the bag's topics read for it, as the bag spells them (see ``bags.names``)."""


Reduce = Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]]
"""Turns a block of decoded messages into the fields kept of them (arrays reduced per message)."""

Check = Callable[[str, str, Fields, Source | None], None]
"""(topic, message type, its fields, where the definition came from) → raises if the metrics read
a field the type does not have; called before any message of the topic is decoded."""
