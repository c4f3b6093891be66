"""Which of a bag's topics a name in a specification reads: the one place where the two meet.

A bag holds topic names as they were recorded.  ROS 2 and ``rosbag record`` write
absolute names (``/tiago1/odom``), but ROS 1 keeps a name as its node published
it, so real bags also hold relative names (``groundtruth``) and names that ROS 2
would refuse (``ORB-SLAM``).  A name in a specification (``"groundtruth"``,
``"/{ns}/odom"`` once the namespace is filled in) reads every topic of the bag that
is the same name once both are absolute: ``"groundtruth"`` and ``"/groundtruth"``
both read the bag's ``groundtruth`` and its ``/groundtruth`` (the two merged, in
time order, if a bag holds both).  No other name is changed: ``//x`` is not ``/x``.

Data read for a name goes under the name the specification asked for; the bag's
own spelling is what the run's PROV and the readers' messages name
(:attr:`~exsce_dsl.runs.bags.reading.BagData.spellings`).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping


def topic_key(name: str) -> str:
    """What a specification's name and a bag's name are compared by: the name made absolute."""
    return name if name.startswith("/") else "/" + name


class TopicMatch:
    """The names a reading wants, and which of them a topic of the bag is read for."""

    def __init__(self, wanted: Iterable[str]) -> None:
        self._by_key: dict[str, list[str]] = {}
        for name in wanted:
            self._by_key.setdefault(topic_key(name), []).append(name)

    def __contains__(self, topic: object) -> bool:
        """Whether the bag's ``topic`` is read (the index readers ask this of each connection)."""
        return isinstance(topic, str) and topic_key(topic) in self._by_key

    def read_for(self, topic: str) -> list[str]:
        """The wanted names the bag's ``topic`` is read for (none if it is not wanted)."""
        return self._by_key.get(topic_key(topic), [])


class BagTopics(Mapping[str, str]):
    """A bag's topics → their message types, listed as the bag spells them and found by any
    name that reads them (``bag_topics(path)["/groundtruth"]`` is the type of ``groundtruth``)."""

    def __init__(self, types: Mapping[str, str]) -> None:
        self._types = dict(types)
        self._by_key: dict[str, list[str]] = {}
        for name in self._types:
            self._by_key.setdefault(topic_key(name), []).append(name)

    def spellings(self, name: str) -> tuple[str, ...]:
        """The bag's names that ``name`` reads (none if it reads none)."""
        return tuple(self._by_key.get(topic_key(name), ()))

    def __getitem__(self, name: str) -> str:
        found = self._types.get(name)
        if found is not None:
            return found
        spelt = self._by_key.get(topic_key(name))
        if not spelt:
            raise KeyError(name)
        return self._types[spelt[0]]

    def __iter__(self) -> Iterator[str]:
        return iter(self._types)

    def __len__(self) -> int:
        return len(self._types)

    def __repr__(self) -> str:
        return f"BagTopics({self._types!r})"
