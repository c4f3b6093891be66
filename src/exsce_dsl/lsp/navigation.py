"""Names and what they stand for: what is at a point, its definitions, its uses, renaming it.

Ids of poses, tasks, environments, robot types, scenarios and metrics are global;
a robot's or a mission's belongs to a scenario, and a derived scenario has its
base's (and those its steps add).  Everything here works on the files' indexes
(:mod:`exsce_dsl.lang.editor.symbols`), which exist even when a specification is not
valid.
"""

from __future__ import annotations

import os
from collections.abc import Collection, Sequence
from dataclasses import dataclass

from exsce_dsl.errors import RenameError, SourceLocation
from exsce_dsl.lang import SCOPED_KINDS, FileIndex, Reference, Symbol
from exsce_dsl.model.names import is_valid_name

NOT_NAMES = frozenset({"acceptance", "criterion"})
"""Symbols whose location is not a name of their own (an acceptance block names its scenario)."""

RENAMEABLE = frozenset(
    {"robot type", "environment", "area", "pose", "obstacle", "map", "world", "task", "scenario", "robot"}
    | {"mission", "metric"}
)


@dataclass(frozen=True)
class NameAtPoint:
    """A name at a point: what it is, and the occurrence under the point."""

    kind: str
    name: str
    scope: str | None
    """For robots and missions, the scenario that declares them (or names them, if none does)."""
    location: SourceLocation
    declaration: Symbol | None = None
    """When the point is on a declaration's name."""


def _contains(loc: SourceLocation, line: int, column: int) -> bool:
    start, end = (loc.line, loc.column), (loc.end_line, loc.end_column)
    return start <= (line, column) <= end


def import_at(index: FileIndex, line: int, column: int) -> str | None:
    """The path written in the import at the point, if any."""
    return next((i.path for i in index.imports if _contains(i.location, line, column)), None)


class Names:
    """The declarations and references of a set of files, looked up by kind and name."""

    def __init__(self, indexes: Sequence[FileIndex], near: Collection[str] = ()) -> None:
        """``near``: the files (absolute paths) the document at hand reads; their declarations
        win over those of other files of the workspace with the same names."""
        self.indexes = indexes
        self.near = frozenset(near)
        self._by_name: dict[tuple[str, str], list[Symbol]] = {}
        for index in indexes:
            for symbol in index.all_symbols():
                self._by_name.setdefault((symbol.kind, symbol.name), []).append(symbol)

    def nearest(self, symbols: list[Symbol]) -> list[Symbol]:
        """Those of ``symbols`` declared in the files read, if any are; else all of them."""
        mine = [s for s in symbols if os.path.abspath(s.location.file) in self.near]
        return mine or symbols

    def symbols(self, kind: str, name: str) -> list[Symbol]:
        return self._by_name.get((kind, name), [])

    def base_of(self, scenario: str) -> str | None:
        """The scenario a derived one is derived from."""
        for symbol in self.symbols("scenario", scenario):
            base = symbol.fact("derived from")
            if base is not None:
                return base
        return None

    def resolve(self, kind: str, name: str, scope: str | None = None) -> list[Symbol]:
        """The declarations ``name`` stands for, as a ``kind`` (said in scenario ``scope``)."""
        found = self.symbols(kind, name)
        if kind not in SCOPED_KINDS:
            return found
        seen: set[str] = set()
        while scope is not None and scope not in seen:
            mine = [s for s in found if s.scope == scope]
            if mine:
                return mine
            seen.add(scope)
            scope = self.base_of(scope)
        return []

    def target_at(self, index: FileIndex, line: int, column: int) -> NameAtPoint | None:
        """The name at 1-based ``line``:``column`` of the file of ``index``."""
        for ref in index.references:
            if _contains(ref.location, line, column):
                return NameAtPoint(ref.kind, ref.name, self._declaring_scope(ref), ref.location)
        for symbol in index.all_symbols():
            if symbol.kind not in NOT_NAMES and _contains(symbol.location, line, column):
                scope = symbol.scope if symbol.kind in SCOPED_KINDS else None
                return NameAtPoint(symbol.kind, symbol.name, scope, symbol.location, symbol)
        return None

    def _declaring_scope(self, ref: Reference) -> str | None:
        if ref.kind not in SCOPED_KINDS:
            return None
        found = self.resolve(ref.kind, ref.name, ref.scope)
        return found[0].scope if found else ref.scope

    def definitions(self, target: NameAtPoint) -> list[Symbol]:
        if target.declaration is not None:
            return [target.declaration]
        if target.kind in SCOPED_KINDS:
            return [s for s in self.symbols(target.kind, target.name) if s.scope == target.scope]
        return self.nearest(self.resolve(target.kind, target.name))

    def references(self, target: NameAtPoint, declarations: bool = True) -> list[SourceLocation]:
        """Every place ``target`` is named (its declarations first, with ``declarations``)."""
        found: list[SourceLocation] = []
        if declarations:
            found.extend(s.location for s in self.definitions(target))
        for index in self.indexes:
            for ref in index.references:
                if ref.kind == target.kind and ref.name == target.name:
                    if self._declaring_scope(ref) == target.scope:
                        found.append(ref.location)
        return list(dict.fromkeys(found))

    def rename(self, target: NameAtPoint, new_name: str, library: FileIndex) -> list[SourceLocation]:
        """The places to write ``new_name`` in; raise :class:`RenameError` when it cannot be done."""
        if target.kind not in RENAMEABLE:
            raise RenameError(f"a {target.kind} cannot be renamed")
        if target.kind == "metric" and any(s.name == target.name for s in library.all_symbols()):
            raise RenameError(f"'{target.name}' is one of exsce's built-in metrics; it cannot be renamed")
        if not is_valid_name(new_name):
            raise RenameError(
                f"'{new_name}' is not a valid id: letters, digits and _ (hyphens between them), "
                "starting with a letter or _, and not a keyword of the language"
            )
        if new_name == target.name:
            return []
        if not self.definitions(target):
            raise RenameError(f"'{target.name}' is not declared in any file known; nothing to rename")
        clash = [
            s
            for s in self.symbols(target.kind, new_name)
            if target.kind not in SCOPED_KINDS or s.scope == target.scope
        ]
        if clash:
            raise RenameError(f"there is already a {target.kind} '{new_name}' (at {clash[0].location})")
        return self.references(target)
