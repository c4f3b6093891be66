"""Turn character offsets in a source text into line and column numbers."""

from __future__ import annotations

import bisect

from exsce_dsl.errors import SourceLocation


class LineIndex:
    """Maps offsets of one text to 1-based (line, column), in O(log lines)."""

    def __init__(self, path: str, text: str) -> None:
        self.path = path
        self._starts = [0]
        self._starts.extend(i + 1 for i, ch in enumerate(text) if ch == "\n")

    def line_col(self, offset: int) -> tuple[int, int]:
        line = bisect.bisect_right(self._starts, offset) - 1
        return line + 1, offset - self._starts[line] + 1

    def offset(self, line: int, col: int) -> int:
        """The offset of 1-based (line, column); the inverse of :meth:`line_col`."""
        return self._starts[min(max(line, 1), len(self._starts)) - 1] + col - 1

    def span(self, start: int, end: int) -> SourceLocation:
        line, col = self.line_col(start)
        end_line, end_col = self.line_col(max(start, end))
        return SourceLocation(self.path, line, col, end_line, end_col)
