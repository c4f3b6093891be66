"""The analysis an editor asks for at each keystroke: diagnostics and each file's index.

:func:`analyse_for_editor` reads a root file and its imports through a
:class:`~exsce_dsl.lang.incremental.ParseCache` (unsaved texts from ``overlay``),
checks them as :func:`~exsce_dsl.lang.builders.analyse` does, and indexes each file
(:func:`~exsce_dsl.lang.editor.symbols.index_file`) unless its text was indexed before.
Parse trees stay in ``lang``; what comes out is plain data.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from exsce_dsl.errors import Diagnostic
from exsce_dsl.lang.builders.specification import Analysis, analyse_files
from exsce_dsl.lang.editor.symbols import FileIndex, index_file
from exsce_dsl.lang.incremental import ParseCache
from exsce_dsl.lang.loader import ANYWHERE, ImportScope, parse_whole, read_sources
from exsce_dsl.lang.parser import ParsedFile


@dataclass(frozen=True)
class FileRead:
    """A file as the analysis read it."""

    path: str
    """Absolute."""
    text: str
    index: FileIndex | None
    """None when nothing of it parsed, or when its text was indexed before (``indexed`` has it)."""
    complete: bool
    """It parsed without a syntax error."""


@dataclass(frozen=True)
class EditorAnalysis:
    analysis: Analysis
    files: tuple[FileRead, ...] = field(default=())
    """Every file read, the root first."""


def analyse_for_editor(
    root: str | Path,
    overlay: Mapping[str, str],
    cache: ParseCache,
    indexed: Mapping[str, str] | None = None,
    scope: ImportScope = ANYWHERE,
) -> EditorAnalysis:
    """Analyse ``root``; ``indexed`` maps absolute paths to the texts whose index the caller has,
    ``scope`` says which files may be imported (the editor's workspace)."""
    known = indexed or {}
    read: list[FileRead] = []

    def parse(text: str, path: str) -> tuple[ParsedFile | None, Sequence[Diagnostic]]:
        pf, errors = cache.parse(text, path)
        full = os.path.abspath(path)
        index = index_file(pf) if pf is not None and known.get(full) != text else None
        read.append(FileRead(full, text, index, pf is not None and not errors))
        return pf, errors

    sources = read_sources(root, overlay, parse=parse, scope=scope)
    analysis = analyse_files(sources.files, sources.diagnostics, sources.broken, parse=cache.parse)
    return EditorAnalysis(analysis, tuple(read))


def index_text(text: str, path: str, cache: ParseCache | None = None) -> FileIndex | None:
    """The index of one file's text (of what parses of it); None if nothing does."""
    pf, _ = cache.parse(text, path) if cache is not None else parse_whole(text, path)
    return index_file(pf) if pf is not None else None
