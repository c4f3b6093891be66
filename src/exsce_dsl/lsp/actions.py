"""Quick fixes: each did-you-mean diagnostic offers to write the name it suggests.

The suggestion is read from the diagnostic's hint, or from its message
(``unknown pose 'c025-w01'; did you mean 'classroom_c025-w001'?``); the unknown
name (the word a syntax error found, else the message's first quoted word) is
replaced where it is written inside the diagnostic's range.
"""

from __future__ import annotations

import re

from lsprotocol import types

from exsce_dsl.lsp.convert import TextLines

_SUGGESTION = re.compile(r"did you mean '([^']+)'\?")
_QUOTED = re.compile(r"'([^']+)'")
_FOUND = re.compile(r"found '([^']+)'")  # a syntax error's word: `expected 'starts', found 'start'`


def suggestion(diagnostic: types.Diagnostic) -> str | None:
    """The name a diagnostic suggests instead of the one written, if it does."""
    data = diagnostic.data
    if isinstance(data, dict) and isinstance(data.get("hint"), str):
        hint = _SUGGESTION.search(data["hint"])
        return hint.group(1) if hint else None
    found = _SUGGESTION.search(diagnostic.message)
    return found.group(1) if found else None


def quick_fixes(uri: str, lines: TextLines, diagnostics: list[types.Diagnostic]) -> list[types.CodeAction]:
    """A quick fix for each diagnostic of ``diagnostics`` that suggests a name."""
    actions = []
    for diagnostic in diagnostics:
        better = suggestion(diagnostic)
        written = _FOUND.search(diagnostic.message) or _QUOTED.search(diagnostic.message)
        if better is None or written is None:
            continue
        where = _find(lines, diagnostic.range, written.group(1))
        if where is None:
            continue
        edit = types.WorkspaceEdit(changes={uri: [types.TextEdit(where, better)]})
        actions.append(
            types.CodeAction(
                title=f"Change '{written.group(1)}' to '{better}'",
                kind=types.CodeActionKind.QuickFix,
                diagnostics=[diagnostic],
                edit=edit,
                is_preferred=True,
            )
        )
    return actions


def _find(lines: TextLines, within: types.Range, name: str) -> types.Range | None:
    """The range of ``name`` written as a whole word inside ``within``."""
    start, end = lines.offset(within.start), lines.offset(within.end)
    pattern = re.compile(rf"(?<![\w-]){re.escape(name)}(?![\w-])")
    found = pattern.search(lines.text, start, max(end, start + len(name)))
    if found is None:
        return None
    first = lines.location(found.start())
    last = lines.location(found.end())
    return types.Range(lines.position(*first), lines.position(*last))
