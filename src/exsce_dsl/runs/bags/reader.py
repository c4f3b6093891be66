"""What a bag format's reader is: a record in :data:`~exsce_dsl.runs.bags.reading.BAG_READERS`.

:func:`~exsce_dsl.runs.bags.reading.read_bag` and
:func:`~exsce_dsl.runs.bags.reading.bag_topics` try the readers in order: the first that
claims the bag reads it, and one that raises :class:`UnsupportedBag` (a part of the bag it
does not read: a compression, a missing index) passes it to the next.  The last, rosbags',
claims every bag and reads what the others do not (and says what is broken).  Packages add
readers under the entry-point group ``exsce.bag_readers`` (:mod:`exsce_dsl.plugins`), tried
after exsce's own and before rosbags'.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from exsce_dsl.runs.bags.data import BagData, Check, Reduce, Wanted
from exsce_dsl.runs.bags.formats import BagFormat
from exsce_dsl.runs.bags.names import BagTopics

Read = Callable[[Path, Mapping[str, Wanted], Mapping[str, Reduce] | None, Check | None], BagData]
"""(the bag, the wanted topics, their reductions, the check of their fields) → what was read."""


@dataclass(frozen=True)
class BagReader:
    """One bag format's reader."""

    name: str
    claims: Callable[[Path], bool]
    """Whether the reader tries the bag at this path (told by its name, nothing read)."""
    read: Read
    topics: Callable[[Path], BagTopics] | None = None
    """The bag's topics and their types, from its own index; None: the next reader lists them."""
    formats: tuple[BagFormat, ...] = ()
    """The file formats it reads (their suffixes, magic bytes and checks): what tells a bag."""
