"""Messages kept as objects: deserialised by rosbags, once per distinct message, or when first
read (a navigation stack's plans: hundreds of poses each, and only the first of a goal is read)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from rosbags.typesys import Stores, get_typestore

from exsce_dsl.errors import BagError
from exsce_dsl.messages.catalogue import MessageCatalogue


def deserialized(
    read: Callable[[bytes], Any], raws: Sequence[bytes | memoryview], lazy: str | None = None
) -> list[Any]:
    """``read`` of each message, once per distinct message: a status array published once a
    second is mostly the same bytes again (its objects are then shared, and only read).  With
    ``lazy`` (the topic's name), each is read when first used (:class:`LazyMessage`)."""
    seen: dict[bytes, Any] = {}
    found = []
    for raw in raws:
        key = bytes(raw)
        if key not in seen:
            seen[key] = LazyMessage(read, key, lazy) if lazy is not None else read(key)
        found.append(seen[key])
    return found


class LazyMessage:
    """A message deserialised when one of its fields is first read.  A navigation stack replans
    about once a second, and each global plan is hundreds of poses; a goal's target needs only the
    first plan of the goal, so the others are never deserialised.  A message that does not
    deserialise is a :class:`BagError` naming its topic, when it is read."""

    __slots__ = ("_read", "_raw", "_topic", "_value")

    def __init__(self, read: Callable[[bytes], Any], raw: bytes, topic: str) -> None:
        self._read, self._raw, self._topic = read, raw, topic
        self._value: Any = None

    @property
    def value(self) -> Any:
        if self._value is None:
            try:
                self._value = self._read(self._raw)
            except Exception as exc:  # rosbags raises struct, index and its own errors on bad bytes
                raise BagError(f"a message on {self._topic} does not deserialize: {exc}") from None
        return self._value

    def __getattr__(self, name: str) -> Any:
        return getattr(self.value, name)


def deserializer_for(catalogue: MessageCatalogue, msgtype: str) -> Any:
    """A rosbags typestore that knows ``msgtype`` (and only what it needs: registering costs)."""
    store = get_typestore(Stores.EMPTY)
    store.register(catalogue.needed(msgtype))
    return store
