"""Between exsce's places and the protocol's: paths and URIs, locations and ranges.

exsce counts lines and columns from 1, in characters; LSP counts from 0, in
code units of the encoding agreed with the client (UTF-16 unless it prefers
another).  Files are named by absolute paths
inside the server.
"""

from __future__ import annotations

import bisect
import os
import re

from lsprotocol import types
from pygls.uris import from_fs_path, to_fs_path

from exsce_dsl.errors import Diagnostic, Severity, SourceLocation

_SEVERITY = {
    Severity.ERROR: types.DiagnosticSeverity.Error,
    Severity.WARNING: types.DiagnosticSeverity.Warning,
    Severity.NOTE: types.DiagnosticSeverity.Information,
    Severity.INFO: types.DiagnosticSeverity.Information,
    Severity.HINT: types.DiagnosticSeverity.Hint,
}
_NAME_AT = re.compile(r"[A-Za-z_][\w-]*")


def path_of(uri: str) -> str:
    """The absolute path of a ``file:`` URI."""
    return os.path.abspath(to_fs_path(uri) or uri)


def uri_of(path: str) -> str:
    return from_fs_path(os.path.abspath(path)) or path


def _width(char: str, encoding: str) -> int:
    """How many code units of ``encoding`` (utf-8, utf-16 or utf-32) ``char`` takes."""
    if encoding == "utf-8":
        return len(char.encode("utf-8"))
    if encoding == "utf-32":
        return 1
    return 2 if ord(char) > 0xFFFF else 1


def unit_column(line: str, column: int, encoding: str = "utf-16") -> int:
    """Code units before 0-based character ``column`` of ``line``."""
    head = line[:column]
    return len(head) if head.isascii() else sum(_width(c, encoding) for c in head)


def character_column(line: str, units: int, encoding: str = "utf-16") -> int:
    """The 0-based character column at ``units`` code units into ``line``."""
    if line.isascii():
        return units
    count = 0
    for index, char in enumerate(line):
        if count >= units:
            return index
        count += _width(char, encoding)
    return len(line)


class TextLines:
    """One text's lines, for converting positions both ways (columns in code units of
    ``encoding``, the position encoding agreed with the client)."""

    def __init__(self, text: str, encoding: str = "utf-16") -> None:
        self.text = text
        self.encoding = encoding
        self.lines = text.split("\n")
        self._starts = [0]
        for line in self.lines[:-1]:
            self._starts.append(self._starts[-1] + len(line) + 1)

    def line(self, number: int) -> str:
        """0-based line ``number`` ('' past the end)."""
        return self.lines[number] if 0 <= number < len(self.lines) else ""

    def position(self, line: int, column: int) -> types.Position:
        """The LSP position of 1-based ``line`` and ``column`` (in characters)."""
        text = self.line(line - 1)
        return types.Position(max(0, line - 1), unit_column(text, max(0, column - 1), self.encoding))

    def offset(self, position: types.Position) -> int:
        """The character offset of an LSP position."""
        if position.line >= len(self.lines):
            return len(self.text)
        line = self.lines[position.line]
        column = character_column(line, position.character, self.encoding)
        return self._starts[position.line] + min(len(line), column)

    def location(self, offset: int) -> tuple[int, int]:
        """1-based (line, column) of a character offset."""
        line = bisect.bisect_right(self._starts, offset) - 1
        return line + 1, offset - self._starts[line] + 1

    def index(self, line: int, column: int) -> int:
        """The character offset of 1-based ``line`` and ``column``."""
        if line > len(self._starts):
            return len(self.text)
        return min(len(self.text), self._starts[max(1, line) - 1] + column - 1)

    def slice(self, loc: SourceLocation) -> str:
        """The text ``loc`` spans."""
        return self.text[self.index(loc.line, loc.column) : self.index(loc.end_line, loc.end_column)]

    def range(self, loc: SourceLocation) -> types.Range:
        """The range of ``loc``; without an end, the word (or character) it starts at."""
        start = self.position(loc.line, loc.column)
        if loc.end_line > 0 and (loc.end_line, loc.end_column) > (loc.line, loc.column):
            return types.Range(start, self.position(loc.end_line, loc.end_column))
        text = self.line(loc.line - 1)
        word = _NAME_AT.match(text, max(0, loc.column - 1))
        end_column = word.end() + 1 if word else min(len(text), loc.column) + 1
        if end_column <= loc.column:  # at the end of a line: the line break
            return types.Range(start, types.Position(start.line + 1, 0))
        return types.Range(start, self.position(loc.line, end_column))


def lsp_diagnostic(diagnostic: Diagnostic, lines: TextLines) -> types.Diagnostic:
    loc = diagnostic.location
    where = lines.range(loc) if loc is not None else types.Range(types.Position(0, 0), types.Position(0, 1))
    return types.Diagnostic(
        range=where,
        message=diagnostic.message,
        severity=_SEVERITY[diagnostic.severity],
        code=diagnostic.code,
        source="exsce",
        data={"hint": diagnostic.hint} if diagnostic.hint else None,
    )
