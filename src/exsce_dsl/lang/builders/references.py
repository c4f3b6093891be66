"""What to say of a name that the files of a specification do not declare.

Three cases, told apart here so that the builders only say which name is unknown:

- a file of the specification has a syntax error and seems to declare the name (its words
  say so, its parse tree lacks it): the error most likely follows from the syntax error.
  It is not shown; one note at the syntax error counts what was withheld;
- a ``.exsce`` file that the specification does not import declares it (one in the folder
  of a file that is read, or of an import): ``unknown task 'go_b' (declared in
  tasks.exsce, which this file does not import)``.  Those files are parsed at the first
  unknown name, once per check, declaration by declaration (a syntax error in one of them
  is no one's business here: what parses of them counts);
- else the name is unknown, with a did-you-mean among the names that are declared.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path

from exsce_dsl.errors import Diagnostic, ExsceError, Severity, SourceLocation, diagnostic_order
from exsce_dsl.lang.chunks import declared_names
from exsce_dsl.lang.incremental import ParseCache
from exsce_dsl.lang.loader import Parse, display_path
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.suggest import did_you_mean
from exsce_dsl.textfiles import read_text

# The class of a top-level declaration of the grammar -> the kind of what it declares.
_KINDS = {
    "RobotType": "robot type",
    "Environment": "environment",
    "Task": "task",
    "Scenario": "scenario",
    "Derivation": "scenario",
    "Metric": "metric",
}
_NEIGHBOURS_READ = 200
"""At most this many files not imported are read to find where a name is declared."""
_FLEET_NAMED = 6
"""A robot not in the fleet: its message names this many of the fleet's robots."""
_WITHHELD_NAMED = 3
"""A note names this many of the errors it withholds."""

Name = tuple[str, str]
"""(kind, name): ``("task", "go_b")``."""


def declared_in(pf: ParsedFile) -> Iterator[Name]:
    """What a parsed file declares: its top-level declarations, and its environments'
    areas, poses and obstacles."""
    for decl in pf.tree.declarations:
        kind = _KINDS.get(decl.__class__.__name__)
        if kind is None:
            continue
        yield kind, str(decl.name)
        if kind != "environment":
            continue
        for member in decl.members:
            member_kind = member.__class__.__name__
            if member_kind == "Area":
                yield "area", str(member.name)
                yield from (("pose", str(pose.name)) for pose in member.poses)
            elif member_kind == "Obstacle":
                yield "obstacle", str(member.name)


class UnknownNames:
    """Words for the unknown names of one check of ``files``; ``broken`` maps the path of
    each file with a syntax error to its text; ``parse`` reads files that are not imported."""

    def __init__(
        self,
        files: Iterable[ParsedFile],
        broken: Mapping[str, str] | None = None,
        parse: Parse | None = None,
    ) -> None:
        files = list(files)
        broken = broken or {}
        self._parse = parse or ParseCache().parse
        self._read = {display_path(pf.path) for pf in files} | {display_path(p) for p in broken}
        self._folders = list(dict.fromkeys(os.path.dirname(p) for p in self._read))
        trees = {display_path(pf.path): set(declared_in(pf)) for pf in files}
        self._uncertain: dict[Name, str] = {}
        for path, text in broken.items():
            for name in sorted(declared_names(text) - trees.get(display_path(path), set())):
                self._uncertain.setdefault(name, display_path(path))
        self._elsewhere: dict[Name, str] | None = None
        self.withheld: dict[str, list[tuple[Name, SourceLocation | None]]] = {}
        """By broken file: the unknown names it may declare, and where they are used."""

    def message(self, kind: str, name: str, at: SourceLocation | None, known: Iterable[str]) -> str | None:
        """The message of unknown ``name`` of ``kind`` used ``at``; None when a file with a
        syntax error seems to declare it (the error is withheld, see :meth:`notes`)."""
        broken = self._uncertain.get((kind, name))
        if broken is not None:
            self.withheld.setdefault(broken, []).append(((kind, name), at))
            return None
        elsewhere = self.declared_elsewhere(kind, name)
        if elsewhere is not None:
            here = os.path.dirname(at.file) if at is not None else ""
            written = os.path.relpath(elsewhere, here or ".").replace(os.sep, "/")
            return f"unknown {kind} '{name}' (declared in {written}, which this file does not import)"
        return f"unknown {kind} '{name}'{did_you_mean(name, known)}"

    def declared_elsewhere(self, kind: str, name: str) -> str | None:
        """The path of a file not read by the check that declares ``name`` as a ``kind``."""
        if self._elsewhere is None:
            self._elsewhere = self._neighbours()
        return self._elsewhere.get((kind, name))

    def notes(self, diagnostics: Iterable[Diagnostic]) -> list[Diagnostic]:
        """One note per broken file whose names were withheld, at its first syntax error."""
        first: dict[str, SourceLocation] = {}
        for d in sorted(diagnostics, key=diagnostic_order):
            if d.location is not None and d.is_error:
                first.setdefault(display_path(d.location.file), d.location)
        notes = []
        for path, uses in sorted(self.withheld.items()):
            listed = ", ".join(
                f"unknown {kind} '{name}'" + (f" at {at}" if at is not None else "")
                for (kind, name), at in uses[:_WITHHELD_NAMED]
            )
            more = ", ..." if len(uses) > _WITHHELD_NAMED else ""
            count = f"{len(uses)} error{'s' if len(uses) != 1 else ''}"
            verb = "are" if len(uses) != 1 else "is"
            message = (
                f"{count} that may follow from the syntax error in {path} {verb} not shown: {listed}{more}"
            )
            notes.append(Diagnostic(message, first.get(path), Severity.NOTE, code="syntax"))
        return notes

    def _neighbours(self) -> dict[Name, str]:
        """What the ``.exsce`` files of the folders read, but not read themselves, declare."""
        found: dict[Name, str] = {}
        candidates: list[str] = []
        for folder in self._folders:
            try:
                entries = sorted(Path(folder or ".").iterdir())
            except OSError:
                continue
            candidates += [
                display_path(p) for p in entries if p.suffix == ".exsce" and display_path(p) not in self._read
            ]
        for path in list(dict.fromkeys(candidates))[:_NEIGHBOURS_READ]:
            try:
                text = read_text(path, "specification")
            except ExsceError:
                continue
            pf, _ = self._parse(text, path)
            if pf is None:
                continue
            for name in declared_in(pf):
                found.setdefault(name, path)
        return found


def not_in_fleet(robot: str, scenario: str, fleet: Iterable[str]) -> str:
    """``robot 'r3' is not in the fleet of scenario 's1'``, with the robot meant: the closest
    name, else the fleet's names."""
    robots = list(fleet)
    hint = did_you_mean(robot, robots)
    if not hint and robots:
        shown = ", ".join(f"'{r}'" for r in robots[:_FLEET_NAMED]) + (
            ", ..." if len(robots) > _FLEET_NAMED else ""
        )
        hint = f" (its robots: {shown})"
    elif not robots:
        hint = " (it has no robots)"
    return f"robot '{robot}' is not in the fleet of scenario '{scenario}'{hint}"
