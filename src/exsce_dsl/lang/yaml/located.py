"""YAML read with the place of each value, so that every error names its line and column."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import yaml

from exsce_dsl.errors import ExsceError, ImportFormatError, SourceLocation
from exsce_dsl.model.names import KEYWORDS, is_valid_name
from exsce_dsl.textfiles import read_text

_Key = str | int

MAX_DEPTH = 64
"""The deepest nesting of a YAML file read here (the method's files nest a handful of levels):
composing a node tree recurses once a level, and Python stops at a thousand (issue 46: a list
nested 50,000 deep was an internal error)."""


class _BoundedLoader(yaml.SafeLoader):
    """The safe loader, refusing nesting deeper than :data:`MAX_DEPTH` where it starts."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent: yaml.Node | None, index: int) -> yaml.Node | None:
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark  # type: ignore[no-untyped-call]
                raise yaml.composer.ComposerError(
                    None, None, f"nested more than {MAX_DEPTH} levels deep", mark
                )
            node: yaml.Node | None = super().compose_node(parent, index)
            return node
        finally:
            self._depth -= 1


def load_located(text: str) -> tuple[object, yaml.Node | None]:
    """The data of a YAML text and its node tree (for line and column numbers), read once by the
    safe loader, nesting at most :data:`MAX_DEPTH` deep; raises ``yaml.YAMLError``."""
    loader = _BoundedLoader(text)
    try:
        tree = loader.get_single_node()
        data = loader.construct_document(tree) if tree is not None else None
    finally:
        loader.dispose()
    return data, tree


class YamlFile:
    """A YAML file read twice: as data with ``yaml.safe_load``, and as a node tree
    (composed by the same safe loader) that only serves line and column numbers."""

    def __init__(self, name: str, data: object, tree: yaml.Node | None) -> None:
        self.name = name
        self.data = data
        self.tree = tree

    @classmethod
    def read(cls, path: Path) -> YamlFile:
        try:
            text = read_text(path, "YAML file")
        except ExsceError as e:
            raise ImportFormatError(e.message, e.location) from None
        try:
            data, tree = load_located(text)
        except yaml.YAMLError as e:
            mark = getattr(e, "problem_mark", None)
            location = node_location(str(path), mark) if mark is not None else None
            problem = getattr(e, "problem", None) or str(e)
            raise ImportFormatError(f"not valid YAML: {problem}", location) from e
        return cls(str(path), data, tree)

    def root_node(self) -> YamlNode:
        return YamlNode(self, (), self.data)

    def location(self, keys: tuple[_Key, ...]) -> SourceLocation:
        """Where the value at ``keys`` starts, or the nearest enclosing value."""
        node = self.tree
        if node is None:
            return SourceLocation(self.name, 1, 1)
        for key in keys:
            child = child_node(node, key)
            if child is None:
                break
            node = child
        return node_location(self.name, node.start_mark, node.end_mark)


def child_node(node: yaml.Node, key: _Key) -> yaml.Node | None:
    if isinstance(node, yaml.MappingNode) and isinstance(key, str):
        return next((v for k, v in node.value if getattr(k, "value", None) == key), None)
    if isinstance(node, yaml.SequenceNode) and isinstance(key, int) and key < len(node.value):
        child: yaml.Node = node.value[key]
        return child
    return None


def node_location(file: str, start: yaml.Mark, end: yaml.Mark | None = None) -> SourceLocation:
    if end is None:
        return SourceLocation(file, start.line + 1, start.column + 1)
    return SourceLocation(file, start.line + 1, start.column + 1, end.line + 1, end.column + 1)


@dataclass(frozen=True)
class YamlNode:
    """A value of a YAML file with the keys that lead to it, for error messages."""

    file: YamlFile
    keys: tuple[_Key, ...]
    value: object

    @property
    def where(self) -> str:
        text = ""
        for key in self.keys:
            text += f"[{key}]" if isinstance(key, int) else f".{key}" if text else key
        return text or "the top level"

    @property
    def location(self) -> SourceLocation:
        return self.file.location(self.keys)

    def error(self, message: str) -> ImportFormatError:
        return ImportFormatError(message, self.location)

    def _mapping(self) -> Mapping[object, object]:
        if not isinstance(self.value, Mapping):
            raise self.error(f"{self.where} should be a mapping of keys to values, not {_kind(self.value)}")
        return self.value

    def get(self, key: str) -> YamlNode:
        """The value of a required key."""
        mapping = self._mapping()
        if key not in mapping:
            raise self.error(f"missing key '{key}' in {self.where}")
        return YamlNode(self.file, (*self.keys, key), mapping[key])

    def opt(self, key: str) -> YamlNode | None:
        """The value of an optional key; ``None`` when absent or empty."""
        mapping = self._mapping()
        if mapping.get(key) is None:
            return None
        return YamlNode(self.file, (*self.keys, key), mapping[key])

    def items_of_mapping(self) -> Iterator[tuple[str, YamlNode]]:
        for key, value in self._mapping().items():
            yield str(key), YamlNode(self.file, (*self.keys, str(key)), value)

    def items_of_list(self) -> Iterator[YamlNode]:
        if not isinstance(self.value, list):
            raise self.error(f"{self.where} should be a list, not {_kind(self.value)}")
        for i, value in enumerate(self.value):
            yield YamlNode(self.file, (*self.keys, i), value)

    def text(self) -> str:
        if not isinstance(self.value, str):
            raise self.error(f"{self.where} should be text, not {_kind(self.value)}")
        return self.value

    def number(self) -> float:
        if isinstance(self.value, bool) or not isinstance(self.value, int | float):
            raise self.error(f"{self.where} should be a number, not {_kind(self.value)}")
        return float(self.value)

    def ident(self, what: str) -> str:
        """Text that must be a valid exsce id (it becomes a name in the DSL)."""
        if isinstance(self.value, bool) or not isinstance(self.value, str | int | float):
            raise self.error(f"{self.where} should be a {what} id, not {_kind(self.value)}")
        text = str(self.value)
        check_name(text, what, self.where, self)
        return text


def _kind(value: object) -> str:
    if value is None:
        return "nothing"
    if isinstance(value, Mapping):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return f"{type(value).__name__} {value!r}"


def check_name(text: str, what: str, where: str, node: YamlNode) -> None:
    """Raise an error at ``node`` unless ``text`` (a ``what`` id, found at ``where``) is a valid exsce id."""
    if not is_valid_name(text):
        raise node.error(f"{what} id '{text}' ({where}) is not a valid exsce id: {why_not_a_name(text)}")


def why_not_a_name(text: str) -> str:
    """Why ``text`` is not a valid exsce id."""
    rule = "an id is letters, digits and '_', starting with a letter or '_', with single '-' between parts"
    if not text:
        return "it is empty"
    if text in KEYWORDS:
        return f"'{text}' is a word of the exsce language"
    bad = next((c for c in text if not (c.isascii() and (c.isalnum() or c in "_-"))), None)
    if bad is not None:
        return f"it contains {bad!r}; {rule}"
    if not (text[0].isalpha() or text[0] == "_"):
        return f"it starts with {text[0]!r}; {rule}"
    return rule
