"""One loader for every kind of plug-in: what installed packages register through entry points.

Each kind of extension is a :class:`Registry`: exsce's own entries (the built-ins) and those
installed packages register under the kind's entry-point group (:data:`GROUPS`), read once, on
first use.  One policy for every kind: a built-in is never replaced (a plug-in of its name is
ignored, with a warning), and a plug-in that cannot be loaded, or is not of its kind, is left out
with a warning, so that one broken package stops nothing else.  A plug-in is only ever loaded
by its registered name: never by a module name found in a data file.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable, Mapping
from importlib.metadata import entry_points
from typing import Generic, TypeVar

__all__ = ["GROUPS", "Registry", "registries"]

T = TypeVar("T")

GROUPS: Mapping[str, str] = {
    "relation": "exsce.relations",
    "executor": "exsce.executors",
    "simulator": "exsce.simulators",
    "bag reader": "exsce.bag_readers",
    "store flavour": "exsce.store_flavours",
}
"""Each kind of plug-in and the entry-point group a package registers it under."""

_REGISTRIES: list[Registry[object]] = []


class Registry(Generic[T]):
    """The entries of one kind (a key of :data:`GROUPS`), by name: built-ins first, in their
    order, then the plug-ins.  ``accept(name, loaded)`` makes an entry of what an entry point
    loads (None: it is not one; it may raise: the plug-in is broken); ``expected`` says what an
    entry is, for the warning when it is not (``a Relation``)."""

    def __init__(
        self,
        kind: str,
        built_in: Iterable[tuple[str, T]],
        accept: Callable[[str, object], T | None],
        expected: str,
    ) -> None:
        self.kind = kind
        self.group = GROUPS[kind]
        self.built_in: dict[str, T] = dict(built_in)
        self._accept = accept
        self._expected = expected
        self._entries: dict[str, T] | None = None
        _REGISTRIES.append(self)  # type: ignore[arg-type]  # read by registries() only

    def entries(self) -> Mapping[str, T]:
        """Every entry by name, the plug-ins read the first time this is asked."""
        if self._entries is None:
            self._entries = self._load()
        return self._entries

    def names(self) -> tuple[str, ...]:
        return tuple(self.entries())

    def get(self, name: str) -> T | None:
        return self.entries().get(name)

    def forget(self) -> None:
        """Read the plug-ins again on next use (a package was installed meanwhile; tests)."""
        self._entries = None

    def _load(self) -> dict[str, T]:
        found = dict(self.built_in)
        for point in entry_points(group=self.group):
            where = f"the plug-in {self.kind} '{point.name}' ({point.value})"
            if point.name in found:
                whose = "exsce's own" if point.name in self.built_in else "another plug-in's"
                warnings.warn(f"{where} cannot replace {whose} '{point.name}'; ignored", stacklevel=4)
                continue
            try:
                made = self._accept(point.name, point.load())
            except Exception as exc:  # a broken third-party package
                warnings.warn(f"{where} cannot be loaded: {exc!r}; ignored", stacklevel=4)
                continue
            if made is None:
                warnings.warn(f"{where} is not {self._expected} named '{point.name}'; ignored", stacklevel=4)
                continue
            found[point.name] = made
        return found


def registries() -> tuple[Registry[object], ...]:
    """Every registry made so far (those of the modules imported), for the documentation's test."""
    return tuple(_REGISTRIES)
