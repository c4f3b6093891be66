"""Read a root ``.exsce`` file and every file it imports, transitively.

Imports are paths relative to the importing file.  Each file is parsed once,
cycles are harmless, and a syntax error in one file does not hide the errors
of the others: every problem found becomes a diagnostic.

What may be imported is the caller's :class:`ImportScope`: on the command line,
any ``.exsce`` file the user can read (they run it on their own files); in the
language server and the MCP server, only files inside the workspace; for a
text given alone (the MCP ``check`` tool), nothing.  A file that is not an
``.exsce`` file is never read, so a diagnostic never quotes it; one outside the
workspace gets the same words whether it exists or not.  Every file is read
with bounds (:func:`~exsce_dsl.textfiles.read_text`).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from exsce_dsl.errors import Diagnostic, ExsceError, ExsceSyntaxError, SourceLocation
from exsce_dsl.lang.chunks import imported_paths
from exsce_dsl.lang.parser import ParsedFile, parse_text
from exsce_dsl.suggest import closest
from exsce_dsl.textfiles import is_inside, read_text, without_bom

Parse = Callable[[str, str], tuple[ParsedFile | None, Sequence[Diagnostic]]]
"""Parses (text, path): the tree (None if nothing could be parsed) and the syntax errors found."""


def parse_whole(text: str, path: str) -> tuple[ParsedFile | None, Sequence[Diagnostic]]:
    """The default :data:`Parse`: the whole file at once, stopping at its first syntax error."""
    try:
        return parse_text(text, path), ()
    except ExsceSyntaxError as exc:
        return None, exc.diagnostics


def display_path(path: str | Path) -> str:
    """A stable, readable name for a file: relative to the working directory when below it."""
    normal = os.path.normpath(str(path))
    if os.path.isabs(normal):
        try:
            rel = os.path.relpath(normal)
        except ValueError:
            return normal
        return normal if rel.startswith("..") else rel
    return normal


def import_target(importer: str, import_path: str) -> str:
    return display_path(os.path.join(os.path.dirname(importer), import_path))


IMPORTED_SUFFIX = ".exsce"


@dataclass(frozen=True)
class ImportScope:
    """Which files a specification may import: any the user can read (``folders`` None), only
    those inside one of ``folders``, or none (``folders`` empty, and ``why`` says why)."""

    folders: tuple[str, ...] | None = None
    why: str = "imports are not read here"

    @classmethod
    def inside(cls, *folders: str | Path) -> ImportScope:
        """Only files inside these folders (symbolic links followed before looking)."""
        return cls(tuple(os.path.realpath(f) for f in folders))

    @classmethod
    def nowhere(cls, why: str) -> ImportScope:
        return cls((), why)

    def refusal(self, written: str, target: str) -> str | None:
        """Why the import of ``written`` (the file ``target``) is not read, or None if it may be."""
        if self.folders == ():
            return self.why
        if not target.endswith(IMPORTED_SUFFIX):
            return f"only {IMPORTED_SUFFIX} files are imported: '{written}' is not read"
        if self.folders is not None and not self.holds(target):
            shown = " or ".join(display_path(f) for f in self.folders)
            return f"'{written}' is outside the workspace ({shown}): only files inside it are imported"
        return None

    def holds(self, path: str) -> bool:
        """Whether ``path`` lies inside the scope (anywhere: always)."""
        return self.folders is None or is_inside(path, self.folders)


ANYWHERE = ImportScope()
"""The command line's scope: any ``.exsce`` file the user can read."""


@dataclass
class Sources:
    """What :func:`read_sources` read: the files that parse (the root first), the problems
    found reading them, and the text of each file that has a syntax error."""

    files: list[ParsedFile] = field(default_factory=list)
    diagnostics: list[Diagnostic] = field(default_factory=list)
    broken: dict[str, str] = field(default_factory=dict)
    """Path -> text of the files with syntax errors (their trees, if any, lack something)."""


def load_files(
    root: str | Path,
    overlay: Mapping[str, str] | None = None,
    parse: Parse = parse_whole,
    scope: ImportScope = ANYWHERE,
) -> tuple[list[ParsedFile], list[Diagnostic]]:
    """Parse ``root`` and its imports; ``overlay`` maps paths to unsaved texts (editors).

    ``parse`` may keep what a syntax error leaves intact (the language server's
    :class:`~exsce_dsl.lang.incremental.ParseCache` does, declaration by declaration).
    """
    sources = read_sources(root, overlay, parse, scope)
    return sources.files, sources.diagnostics


def read_sources(
    root: str | Path,
    overlay: Mapping[str, str] | None = None,
    parse: Parse = parse_whole,
    scope: ImportScope = ANYWHERE,
) -> Sources:
    """:func:`load_files`, also telling which files have syntax errors.

    The imports of a file that does not parse at all are read from its words, so that
    what they declare is still known (those ``scope`` allows, silently).
    """
    overlay = {display_path(k): without_bom(v) for k, v in (overlay or {}).items()}
    sources = Sources()
    parsed, diagnostics = sources.files, sources.diagnostics
    seen: set[str] = set()
    pending: list[tuple[str, SourceLocation | None]] = [(display_path(root), None)]
    while pending:
        path, where = pending.pop(0)
        quiet = where is None and bool(seen)  # imported by a file with a syntax error
        if path in seen:
            continue
        seen.add(path)
        text = overlay.get(path)
        if text is None:
            try:
                text = read_text(path, "specification")
            except ExsceError as exc:
                if exc.location is not None or (where is None and not quiet):
                    diagnostics.extend(exc.diagnostics)
                elif where is not None:  # an imported file is reported where it is imported
                    diagnostics.append(Diagnostic(f"imported file: {exc.message}", where, code="import"))
                continue
        pf, problems = parse(text, path)
        diagnostics.extend(problems)
        if problems:
            sources.broken[path] = text
        if pf is None:
            for imported in imported_paths(text):
                target = import_target(path, imported)
                if scope.refusal(imported, target) is None and (target in overlay or _is_file(target)):
                    pending.append((target, None))
            continue
        parsed.append(pf)
        for imp in pf.tree.imports:
            target = import_target(path, imp.path)
            problem = scope.refusal(imp.path, target)
            if problem is None and target not in overlay and not _is_file(target):
                closest = _closest_file(imp.path, target)
                problem = f"imported file '{imp.path}' not found (looked for {target}){closest}"
            if problem is not None:
                diagnostics.append(Diagnostic(problem, pf.span(imp), code="import"))
                continue
            pending.append((target, pf.span(imp)))
    return sources


def _is_file(target: str) -> bool:
    """Whether ``target`` names a file; a name no file can have (too long, a NUL byte: an import
    string of a broken file) names none."""
    try:
        return Path(target).is_file()
    except (OSError, ValueError):
        return False


def _closest_file(written: str, target: str) -> str:
    """``; did you mean 'tasks.exsce'?``: the ``.exsce`` file of the target's folder most like
    the one not found, written as the import wrote its path."""
    folder = Path(target).parent
    try:
        names = [p.name for p in folder.iterdir() if p.suffix == ".exsce" and p.is_file()]
    except (OSError, ValueError):  # no such folder, or a name no folder can have
        return ""
    match = closest(Path(written).name, names)
    if match is None:
        return ""
    head, _, _ = written.rpartition("/")
    return f"; did you mean '{head + '/' if head else ''}{match}'?"
