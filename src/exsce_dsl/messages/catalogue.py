"""A catalogue of message definitions, each with where it came from.

Definitions are rosbags' field descriptions (``Typesdict``: type name →
(constants, fields)), the form its typestores, its ``.msg`` and ``.idl``
parsers and its bag readers all give.  A catalogue is layered: the bag's own
definitions are looked up first, then the user's files, then the standard ROS 1
and ROS 2 packages that rosbags ships (``std``, ``geometry``, ``nav``,
``sensor``, ``tf2``, ``action``, ``actionlib``, ``diagnostic``,
``visualization`` ...), newest distribution first.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from exsce_dsl.errors import MessageTypeError
from exsce_dsl.messages.typestore_cache import standard_fielddefs
from exsce_dsl.model.messages import Fields, Leaf, MessageArray, Node, canonical_type

Definitions = Mapping[str, tuple[list[Any], list[tuple[str, Any]]]]
"""rosbags' ``Typesdict``: type name → (constants, [(field name, field description)])."""

# rosbags' node types (rosbags.interfaces.Nodetype), by value: BASE, NAME, ARRAY, SEQUENCE
BASE, NAME, ARRAY, SEQUENCE = 1, 2, 3, 4

NUMERIC = {
    "bool": "u1",
    "byte": "i1",  # ROS 1 defines byte as int8; rosbags reads it so in ROS 2 bags too
    "char": "u1",
    "int8": "i1",
    "uint8": "u1",
    "int16": "i2",
    "uint16": "u2",
    "int32": "i4",
    "uint32": "u4",
    "int64": "i8",
    "uint64": "u8",
    "float32": "f4",
    "float64": "f8",
}
"""ROS primitive type → numpy type code (without byte order)."""


@dataclass(frozen=True)
class Source:
    """Where a definition came from, for errors: ``the bag x.bag``, ``rosbags' ros2_jazzy``."""

    text: str


@dataclass
class MessageCatalogue:
    """Definitions by type name (ROS 2 spelling), each with its :class:`Source`."""

    definitions: dict[str, tuple[list[Any], list[tuple[str, Any]]]] = field(default_factory=dict)
    sources: dict[str, Source] = field(default_factory=dict)

    def add(self, definitions: Definitions, source: Source, replace: bool = False) -> None:
        """Add ``definitions``; a type already known is kept unless ``replace``."""
        for name, definition in definitions.items():
            key = canonical_type(name)
            if replace or key not in self.definitions:
                self.definitions[key] = (list(definition[0]), list(definition[1]))
                self.sources[key] = source

    def layered(self, *below: MessageCatalogue) -> MessageCatalogue:
        """This catalogue first, then each of ``below`` for the types it lacks."""
        merged = MessageCatalogue(dict(self.definitions), dict(self.sources))
        for other in below:
            for name, definition in other.definitions.items():
                if name not in merged.definitions:
                    merged.definitions[name] = definition
                    merged.sources[name] = other.sources[name]
        return merged

    def __contains__(self, msgtype: str) -> bool:
        return canonical_type(msgtype) in self.definitions

    def fields_of(self, msgtype: str) -> list[tuple[str, Any]]:
        """The field descriptions of ``msgtype``."""
        key = canonical_type(msgtype)
        if key not in self.definitions:
            raise MessageTypeError(f"unknown message type {msgtype}")
        return self.definitions[key][1]

    def source_of(self, msgtype: str) -> Source | None:
        return self.sources.get(canonical_type(msgtype))

    def needed(self, msgtype: str) -> dict[str, tuple[list[Any], list[tuple[str, Any]]]]:
        """The definitions of ``msgtype`` and of every type it needs that this catalogue has."""
        found: dict[str, tuple[list[Any], list[tuple[str, Any]]]] = {}
        todo = [canonical_type(msgtype)]
        while todo:
            name = todo.pop()
            if name in found or name not in self.definitions:
                continue
            found[name] = self.definitions[name]
            for _, desc in self.definitions[name][1]:
                todo.extend(_names_in(desc))
        return found

    def missing(self, msgtype: str) -> list[str]:
        """Types that ``msgtype`` needs (itself included) and this catalogue lacks."""
        lacking: list[str] = []
        seen: set[str] = set()
        todo = [canonical_type(msgtype)]
        while todo:
            name = todo.pop()
            if name in seen:
                continue
            seen.add(name)
            if name not in self.definitions:
                lacking.append(name)
                continue
            for _, desc in self.definitions[name][1]:
                todo.extend(_names_in(desc))
        return sorted(lacking)

    def tree(self, msgtype: str) -> Fields:
        """The fields of ``msgtype`` as a tree (a sub-message is a dict, an array of messages a
        :class:`MessageArray`); every type it needs must be known."""
        lacking = self.missing(msgtype)
        if lacking:
            needs = ", ".join(lacking)
            raise MessageTypeError(f"the definition of {msgtype} needs {needs}, which is unknown")
        return self._tree(canonical_type(msgtype))

    def _tree(self, name: str) -> Fields:
        return {fname: self._node(desc) for fname, desc in self.definitions[name][1]}

    def _node(self, desc: Any) -> Node:
        kind, detail = int(desc[0]), desc[1]
        if kind == BASE:
            return Leaf.TEXT if detail[0] in ("string", "wstring") else Leaf.NUMBER
        if kind == NAME:
            return self._tree(canonical_type(detail))
        element, length = detail
        inner = self._node(element)
        if isinstance(inner, Leaf):
            return Leaf.TEXTS if inner is Leaf.TEXT else Leaf.ARRAY
        assert isinstance(inner, dict)  # ROS arrays hold primitives or messages, not arrays
        return MessageArray(inner, int(length) if kind == ARRAY else None)


def _names_in(desc: Any) -> list[str]:
    kind, detail = int(desc[0]), desc[1]
    if kind == NAME:
        return [canonical_type(detail)]
    if kind in (ARRAY, SEQUENCE):
        return _names_in(detail[0])
    return []


STANDARD_STORES = ("ros2_jazzy", "ros2_humble", "ros1_noetic")
"""rosbags' typestores whose types every catalogue knows, looked up in this order."""


@functools.lru_cache(maxsize=1)
def standard_catalogue() -> MessageCatalogue:
    """The standard ROS 1 and ROS 2 message packages that rosbags ships, and Nav2's and
    move_base's messages, which exsce ships."""
    from exsce_dsl.messages.navigation import navigation_catalogue  # which builds on this module

    catalogue = MessageCatalogue()
    for name in STANDARD_STORES:
        catalogue.add(standard_fielddefs(name), Source(f"rosbags' {name} typestore"))
    # rosbag2 stores no definitions in sqlite3 bags, and none of an action's feedback anywhere:
    # the navigation stacks' own types come with exsce
    return catalogue.layered(navigation_catalogue())


def standard_ros1_catalogue() -> MessageCatalogue:
    """ROS 1's definitions first (``std_msgs/Header`` has its ``seq``), then the others."""
    return _ros1_first()


@functools.lru_cache(maxsize=1)
def _ros1_first() -> MessageCatalogue:
    catalogue = MessageCatalogue()
    catalogue.add(standard_fielddefs("ros1_noetic"), Source("rosbags' ros1_noetic typestore"))
    return catalogue.layered(standard_catalogue())


def parse_definition(text: str, msgtype: str, kind: str, source: Source) -> MessageCatalogue:
    """Definitions from one text: ``msg`` (a ``.msg`` file, or ROS 1's concatenated form with
    its dependencies) or ``idl``; a text that does not parse is a :class:`MessageTypeError`."""
    from rosbags.typesys import get_types_from_idl, get_types_from_msg

    try:
        found = get_types_from_msg(text, msgtype) if kind == "msg" else get_types_from_idl(text)
    except Exception as exc:  # rosbags' parser raises its own errors (TypesysError, grammar errors)
        raise MessageTypeError(f"{source.text}: the definition of {msgtype} does not parse: {exc}") from None
    catalogue = MessageCatalogue()
    catalogue.add(found, source)
    return catalogue
