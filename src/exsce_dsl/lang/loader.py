"""Read a root ``.exsce`` file and every file it imports, transitively.

Imports are paths relative to the importing file.  Each file is parsed once,
cycles are harmless, and a syntax error in one file does not hide the errors
of the others: every problem found becomes a diagnostic.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from exsce_dsl.errors import Diagnostic, ExsceError, ExsceSyntaxError
from exsce_dsl.lang.parser import ParsedFile, parse_text
from exsce_dsl.textfiles import read_text

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


def load_files(
    root: str | Path, overlay: Mapping[str, str] | None = None, parse: Parse = parse_whole
) -> tuple[list[ParsedFile], list[Diagnostic]]:
    """Parse ``root`` and its imports; ``overlay`` maps paths to unsaved texts (editors).

    ``parse`` may keep what a syntax error leaves intact (the language server's
    :class:`~exsce_dsl.lang.incremental.ParseCache` does, declaration by declaration).
    """
    overlay = {display_path(k): v for k, v in (overlay or {}).items()}
    parsed: list[ParsedFile] = []
    diagnostics: list[Diagnostic] = []
    seen: set[str] = set()
    pending = [display_path(root)]
    while pending:
        path = pending.pop(0)
        if path in seen:
            continue
        seen.add(path)
        text = overlay.get(path)
        if text is None:
            try:
                text = read_text(path, "specification")
            except ExsceError as exc:
                if not parsed or exc.location is not None:  # imports are reported where they are written
                    diagnostics.extend(exc.diagnostics)
                continue
        pf, problems = parse(text, path)
        diagnostics.extend(problems)
        if pf is None:
            continue
        parsed.append(pf)
        for imp in pf.tree.imports:
            target = import_target(path, imp.path)
            if target not in overlay and not Path(target).is_file():
                diagnostics.append(
                    Diagnostic(
                        f"imported file '{imp.path}' not found (looked for {target})",
                        pf.span(imp),
                        code="import",
                    )
                )
                continue
            pending.append(target)
    return parsed, diagnostics
