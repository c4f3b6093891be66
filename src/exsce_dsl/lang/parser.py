"""The textX side of the language: the metamodel and syntax errors in words.

textX objects never leave ``lang``; :mod:`exsce_dsl.lang.build` turns them
into the semantic model.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from typing import Any

from textx import TextXSyntaxError, metamodel_from_file

from exsce_dsl.errors import Diagnostic, ExsceSyntaxError, SourceLocation
from exsce_dsl.lang.locations import LineIndex
from exsce_dsl.resources import grammar_file

# How rules of the grammar are named in messages.
_RULE_WORDS = {
    "Name": "a name",
    "Ref": "a name",
    "NUMBER": "a number",
    "FLOAT": "a number",
    "STRICTFLOAT": "a number",
    "INT": "a number",
    "STRING": "a quoted string",
    "EOF": "the end of the file",
    "Length": "a length (a number, in m unless followed by cm or mm)",
    "Angle": "an angle (a number, in rad unless followed by deg)",
}


def new_metamodel() -> Any:
    """A fresh metamodel of the exsce grammar (textX caches nothing across them)."""
    return metamodel_from_file(str(grammar_file()), autokwd=True)


@functools.lru_cache(maxsize=1)
def _shared_metamodel() -> Any:
    return new_metamodel()


@dataclass(frozen=True)
class ParsedFile:
    """A parse tree with what is needed to locate its objects."""

    path: str
    text: str
    tree: Any
    lines: LineIndex

    def span(self, obj: Any) -> SourceLocation:
        return self.lines.span(obj._tx_position, obj._tx_position_end)


def parse_text(text: str, path: str) -> ParsedFile:
    """Parse one file's text; raise :class:`ExsceSyntaxError` on bad syntax."""
    lines = LineIndex(path, text)
    try:
        # textX reads the file itself when given no text: an empty editor buffer is not the file
        tree = _shared_metamodel().model_from_str(text or " ", file_name=path)
    except TextXSyntaxError as exc:
        raise ExsceSyntaxError([_syntax_diagnostic(exc, text, path)]) from None
    if isinstance(tree, str):  # textX's model of a text with nothing but whitespace and comments
        where = SourceLocation(path, 1, 1, 1, 1)
        raise ExsceSyntaxError([Diagnostic("the file declares nothing (it is empty or all comments)", where)])
    return ParsedFile(path, text, tree, lines)


def metamodel() -> Any:
    """The metamodel :func:`parse_text` uses, made once per process."""
    return _shared_metamodel()


def _syntax_diagnostic(exc: TextXSyntaxError, text: str, path: str) -> Diagnostic:
    rules = getattr(exc, "expected_rules", None) or []
    return syntax_diagnostic_at(exc.line or 1, exc.col or 1, rules, text, path)


def syntax_diagnostic_at(line: int, col: int, rules: list[Any], text: str, path: str) -> Diagnostic:
    """The diagnostic of a syntax error at ``line``:``col`` of ``text``, where the grammar
    expected ``rules`` (those of a textX syntax error)."""
    expected = _expected_words(rules)
    found = _token_at(text, line, col)
    message = f"expected {expected}, found {found}" if expected else f"syntax error near {found}"
    end_col = col + max(1, len(found) - 2 if found.startswith("'") else 1)
    return Diagnostic(message, SourceLocation(path, line, col, line, end_col), code="syntax")


_KEYWORD = re.compile(r"[A-Za-z_][\w-]*")


def _expected_words(rules: list[Any]) -> str:
    words: list[str] = []
    for rule in rules:
        name = getattr(rule, "rule_name", "") or ""
        literal = getattr(rule, "to_match", None)
        if name in _RULE_WORDS:
            word = _RULE_WORDS[name]
        elif isinstance(literal, str) and rule.__class__.__name__ == "StrMatch":
            word = f"'{literal}'"
        elif isinstance(literal, str) and not name and _KEYWORD.fullmatch(literal):
            word = f"'{literal}'"  # a keyword, which textX matches by a regex of its own (autokwd)
        elif name:
            word = _RULE_WORDS.get(name.upper(), f"a {name.lower()}")
        else:
            continue
        if word not in words:
            words.append(word)
    if not words:
        return ""
    if len(words) == 1:
        return words[0]
    return ", ".join(words[:-1]) + " or " + words[-1]


def _token_at(text: str, line: int, col: int) -> str:
    lines = text.splitlines()
    if line > len(lines):
        return "the end of the file"
    rest = lines[line - 1][col - 1 :].strip()
    if not rest:
        return "the end of the line" if line < len(lines) else "the end of the file"
    token = rest.split()[0]
    for stop in "{}(),:":
        if stop in token and token != stop:
            token = token.split(stop)[0] or stop
    return f"'{token}'"
