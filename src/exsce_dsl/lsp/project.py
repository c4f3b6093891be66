"""What the server knows: the analysis of each open document, and the index of every file.

Every open document is the root of an analysis that follows its imports, read
from the editor's text where a file is open and from disk otherwise.  Files are
parsed through one :class:`~exsce_dsl.lang.incremental.ParseCache`, so an edit
re-parses one declaration, and each file's index (its declarations and
references) is kept by its text.  A file's diagnostics are those every analysis
that reads it finds there.

An analysis imports only ``.exsce`` files inside the workspace, and reads no
other file outside it (a map): the client's workspace folders when the document
is inside one of them, else the document's own folder (a file opened alone).
An analysis that fails on a bug of ours still publishes: one diagnostic at the
document's start says so (:meth:`Project.failed`).

:meth:`Project.analyse` and :meth:`Project.scan` run on the analysis thread
only; the rest reads what they publish (whole dictionaries replaced at once)
from the event loop.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

from exsce_dsl.errors import Diagnostic, ExsceError, SourceLocation
from exsce_dsl.lang import FileIndex, ImportScope, ParseCache, analyse_for_editor, display_path, index_text
from exsce_dsl.model.document import Specification
from exsce_dsl.resources import package_file
from exsce_dsl.textfiles import read_text, reading_inside

_SKIP_FOLDERS = frozenset({"node_modules", "__pycache__", "build", "dist"})
_SCAN_LIMIT = 5000


@dataclass(frozen=True)
class OpenDocument:
    """An open document as the analysis saw it."""

    text: str
    version: int | None


@dataclass
class RootAnalysis:
    """One open document analysed with what it imports."""

    root: str
    versions: dict[str, int | None]
    """The version of each open document it read (by absolute path)."""
    files: tuple[str, ...]
    """Every file it read, the root first (absolute paths)."""
    diagnostics: dict[str, list[Diagnostic]]
    """By absolute path, the fast checks' (syntax, references, semantics)."""
    spec: Specification | None
    generation: int
    shapes: dict[str, list[Diagnostic]] = field(default_factory=dict)
    """The SHACL checks' once they are back (by absolute path)."""


class Project:
    """The analyses of the open documents, the files' indexes, and the parse cache under them."""

    def __init__(self) -> None:
        self.cache = ParseCache()
        self.roots: dict[str, RootAnalysis] = {}
        self.indexes: dict[str, FileIndex] = {}
        """The latest index of every file parsed (absolute path -> index)."""
        self.texts: dict[str, str] = {}
        """The text of each file as last read (its index is of it, unless nothing of it parsed)."""
        self.complete: dict[str, FileIndex] = {}
        """Of each file, the index of its last text without syntax errors (completion falls back on it)."""
        self.library = _library_index()
        """The standard library of metrics."""
        self.workspace: tuple[str, ...] = ()
        """The client's workspace folders (absolute paths)."""
        self._generation = 0

    # ---------------------------------------------------------- analysis thread
    def roots_to_analyse(self, changed: Iterable[str], documents: Mapping[str, OpenDocument]) -> list[str]:
        """The open documents to analyse after ``changed`` changed: those first, then those that read them."""
        changed = set(changed)
        roots = sorted(p for p in changed if p in documents)
        roots += sorted(
            r for r, a in self.roots.items() if r in documents and r not in roots and changed & set(a.files)
        )
        return roots

    def analyse(self, root: str, documents: Mapping[str, OpenDocument]) -> RootAnalysis:
        """Analyse the open document ``root`` with what it imports (open ones as the editor has them)."""
        overlay = {path: doc.text for path, doc in documents.items()}
        scope = self.import_scope(root)
        with reading_inside(*(scope.folders or ())):  # maps too: nothing outside the workspace
            result = analyse_for_editor(root, overlay, self.cache, self.texts, scope)
        indexes, texts, complete = dict(self.indexes), dict(self.texts), dict(self.complete)
        for file in result.files:
            texts[file.path] = file.text
            if file.index is not None:
                indexes[file.path] = file.index
                if file.complete:
                    complete[file.path] = file.index
        by_file: dict[str, list[Diagnostic]] = {}
        for d in result.analysis.diagnostics:
            where = os.path.abspath(d.location.file) if d.location else root
            by_file.setdefault(where, []).append(d)
        read = [f.path for f in result.files]
        if root not in read:
            read.insert(0, root)
        self._generation += 1
        done = RootAnalysis(
            root,
            {p: documents[p].version for p in read if p in documents},
            tuple(read),
            by_file,
            result.analysis.spec,
            self._generation,
        )
        self.indexes, self.texts, self.complete = indexes, texts, complete
        self.roots = {**self.roots, root: done}
        return done

    def import_scope(self, root: str) -> ImportScope:
        """What ``root`` may import: files inside the workspace folders when it is inside one of
        them, else inside its own folder."""
        workspace = ImportScope.inside(*self.workspace)
        if self.workspace and workspace.holds(root):
            return workspace
        return ImportScope.inside(os.path.dirname(os.path.abspath(root)))

    def failed(self, root: str, documents: Mapping[str, OpenDocument], error: BaseException) -> RootAnalysis:
        """The analysis of ``root`` that raised ``error`` (a bug): one diagnostic at its start
        saying so, in place of what an analysis would have found."""
        kind = type(error).__name__
        message = f"internal error: exsce could not check this file ({kind}), so no other problem is shown"
        if isinstance(error, RecursionError):
            message += "; something in it is nested too deeply for the checker"
        message += "; please report it, with the file"
        where = SourceLocation(root, 1, 1, 1, 1)
        self._generation += 1
        versions = {root: documents[root].version} if root in documents else {}
        done = RootAnalysis(
            root,
            versions,
            (root,),
            {root: [Diagnostic(message, where, code="internal")]},
            None,
            self._generation,
        )
        self.roots = {**self.roots, root: done}
        return done

    def close(self, path: str, documents: Mapping[str, OpenDocument]) -> None:
        """``path`` is no longer open: it is no longer a root (its analysis is dropped)."""
        roots = dict(self.roots)
        roots.pop(path, None)
        self.roots = roots
        if not any(path in a.files for a in roots.values()):
            self.cache.forget(display_path(path))

    def scan(self, folders: Iterable[str]) -> int:
        """Index every ``.exsce`` file below ``folders`` that is not indexed yet (for references,
        renaming and workspace symbols); returns how many were read."""
        indexes, texts, complete = dict(self.indexes), dict(self.texts), dict(self.complete)
        count = 0
        for path in _exsce_files(folders):
            if path in indexes:
                continue
            try:
                text = read_text(path, "specification")
            except ExsceError:  # not a regular file (a FIFO would block), too large, not UTF-8
                continue
            index = index_text(text, display_path(path), self.cache)
            if index is not None:
                indexes[path] = index
                texts[path] = text
                count += 1
                if not self.cache.parse(text, display_path(path))[1]:  # parsed once, kept by the cache
                    complete[path] = index  # an edit with a syntax error still completes its names
        self.indexes, self.texts, self.complete = indexes, texts, complete
        return count

    # -------------------------------------------------------------- event loop
    def set_shapes(self, root: str, generation: int, diagnostics: Sequence[Diagnostic]) -> bool:
        """Keep SHACL's diagnostics of an analysis, if it is still the latest of its root."""
        analysis = self.roots.get(root)
        if analysis is None or analysis.generation != generation:
            return False
        shapes: dict[str, list[Diagnostic]] = {}
        for d in diagnostics:
            where = os.path.abspath(d.location.file) if d.location else root
            shapes.setdefault(where, []).append(d)
        analysis.shapes = shapes
        return True

    def diagnostics(self) -> dict[str, list[Diagnostic]]:
        """Every file's diagnostics: what the analyses reading it found there, each once.  Of an
        open file, only analyses of its latest version count (the others are not done yet)."""
        latest = self.latest_versions()
        found: dict[str, list[Diagnostic]] = {}
        for analysis in self.roots.values():
            for source in (analysis.diagnostics, analysis.shapes):
                for path, items in source.items():
                    if path in latest and analysis.versions.get(path) != latest[path]:
                        continue
                    bucket = found.setdefault(path, [])
                    bucket.extend(d for d in items if d not in bucket)
        return found

    def latest_versions(self) -> dict[str, int]:
        """Of each open file analysed, the latest version an analysis read."""
        latest: dict[str, int] = {}
        for analysis in self.roots.values():
            for path, version in analysis.versions.items():
                if version is not None:
                    latest[path] = max(latest.get(path, version), version)
        return latest

    def visible_indexes(self, path: str | None = None, last_complete: bool = False) -> list[FileIndex]:
        """The indexes a name in ``path`` may refer to: the files its analysis read first (when it
        has one), then every other file known, then the standard library.  With ``last_complete``,
        a file whose text has a syntax error also gives its last index without one."""
        first: list[str] = []
        for analysis in self.roots.values():
            if path is not None and path in analysis.files:
                first.extend(f for f in analysis.files if f not in first)
        indexes = self.indexes
        ordered = [indexes[p] for p in first if p in indexes]
        ordered += [i for p, i in indexes.items() if p not in first]
        if last_complete:
            complete = self.complete
            ordered += [i for p, i in complete.items() if p in indexes and indexes[p] is not i]
        return [*ordered, self.library]

    def reachable(self, path: str) -> set[str]:
        """The files an analysis that reads ``path`` also reads (and the standard library)."""
        found = {path, self.library.path}
        for analysis in self.roots.values():
            if path in analysis.files:
                found.update(analysis.files)
        return found


def _library_index() -> FileIndex:
    source = package_file("lang", "stdlib", "metrics.exsce")
    path = os.path.abspath(str(source))
    index = index_text(source.read_text(encoding="utf-8"), path)
    assert index is not None, path  # the package's own file parses
    return index


def _exsce_files(folders: Iterable[str]) -> Iterable[str]:
    count = 0
    for folder in folders:
        for here, dirs, files in os.walk(folder):
            dirs[:] = sorted(d for d in dirs if not d.startswith(".") and d not in _SKIP_FOLDERS)
            for name in sorted(files):
                if name.endswith(".exsce"):
                    count += 1
                    if count > _SCAN_LIMIT:
                        return
                    yield os.path.abspath(os.path.join(here, name))
