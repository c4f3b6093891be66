"""Parse as an editor needs: declaration by declaration, reusing what did not change.

textX parses a whole file and stops at its first syntax error.  An editor sends
the file again at every keystroke, and a 2,000-line specification takes half a
second to parse.  :class:`ParseCache` cuts the text into its declarations (and an
environment into its areas, see :mod:`exsce_dsl.lang.chunks`), parses each piece
on its own and keeps the result by the piece's text: an edit re-parses one
declaration, and a syntax error in one leaves the others parsed, so that their
errors are found too.

A piece parsed once is reused wherever its text appears next: its objects'
positions (``_tx_position``) are moved by the distance it moved.  For valid text
the tree is the one :func:`~exsce_dsl.lang.parser.parse_text` makes, but for the
parents of declarations (a tree per piece).  Use one cache from one thread.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from textx import TextXSyntaxError

from exsce_dsl.errors import Diagnostic, SourceLocation
from exsce_dsl.lang.chunks import Chunk, area_spans, declaration_chunks, line_head_chunks
from exsce_dsl.lang.locations import LineIndex
from exsce_dsl.lang.parser import ParsedFile, metamodel, nesting_diagnostic, syntax_diagnostic_at

# An area is parsed inside an environment of its own, then moved to where it is written.
_AREA_HEAD = "environment _ {\n"
_AREA_TAIL = "\n}\n"
# Areas are worth parsing apart only in environments this long (characters).
_SPLIT_ENVIRONMENT = 4000


@dataclass
class _Piece:
    """A parsed piece: its tree (or its syntax error) and where its positions now point."""

    tree: Any
    offset: int
    error: tuple[int, list[Any]] | None = None
    """Where the piece's syntax error is (offset in the piece) and what was expected."""


class _Document:
    """A file's tree assembled from its pieces: what :class:`ParsedFile` users read."""

    def __init__(self, imports: list[Any], declarations: list[Any], end: int) -> None:
        self.imports = imports
        self.declarations = declarations
        self._tx_position = 0
        self._tx_position_end = end


class ParseCache:
    """Parses files piece by piece; keeps the pieces of the texts it saw last of each file."""

    def __init__(self) -> None:
        self._pieces: dict[tuple[str, str, str, int], _Piece] = {}
        self._used: dict[str, set[tuple[str, str, str, int]]] = {}
        self._files: dict[str, tuple[str, ParsedFile | None, tuple[Diagnostic, ...]]] = {}

    def parse(self, text: str, path: str) -> tuple[ParsedFile | None, Sequence[Diagnostic]]:
        """The tree of what parses and the syntax errors of what does not (a
        :data:`~exsce_dsl.lang.loader.Parse`)."""
        known = self._files.get(path)
        if known is not None and known[0] == text:
            return known[1], known[2]
        too_deep = nesting_diagnostic(text, path)
        if too_deep is not None:  # the parser would recurse past Python's limit
            self._files[path] = (text, None, (too_deep,))
            return None, (too_deep,)
        used: set[tuple[str, str, str, int]] = set()
        lines = LineIndex(path, text)
        errors: list[Diagnostic] = []
        imports: list[Any] = []
        declarations: list[Any] = []
        for chunk in declaration_chunks(text):
            parts = self._chunk(text, lines, chunk, used, errors)
            if parts is None:
                parts = self._resplit(text, lines, chunk, used, errors)
            for tree in parts:
                imports.extend(tree.imports)
                declarations.extend(tree.declarations)
        for key in self._used.get(path, set()) - used:
            self._pieces.pop(key, None)
        self._used[path] = used
        parsed = None
        if imports or declarations:
            parsed = ParsedFile(path, text, _Document(imports, declarations, len(text.rstrip())), lines)
        elif not errors:  # as parse_text says it
            where = SourceLocation(path, 1, 1, 1, 1)
            errors.append(Diagnostic("the file declares nothing (it is empty or all comments)", where))
        result = (parsed, tuple(errors))
        self._files[path] = (text, *result)
        return result

    def forget(self, path: str) -> None:
        """Drop what is kept of ``path`` (a closed file)."""
        self._files.pop(path, None)
        for key in self._used.pop(path, set()):
            self._pieces.pop(key, None)

    # ------------------------------------------------------------------ pieces
    def _chunk(
        self, text: str, lines: LineIndex, chunk: Chunk, used: set[Any], errors: list[Diagnostic]
    ) -> list[Any] | None:
        """The trees of one chunk, or None (its error reported) when it does not parse."""
        if chunk.keyword == "environment" and chunk.end - chunk.start > _SPLIT_ENVIRONMENT:
            tree = self._environment(text, lines, chunk, used, errors)
            if tree is not None:
                return [tree]
        piece = self._piece(lines.path, "chunk", text[chunk.start : chunk.end], chunk.start, used)
        if piece.error is not None:
            errors.append(_error(piece, text, lines))
            return None
        return [piece.tree]

    def _resplit(
        self, text: str, lines: LineIndex, chunk: Chunk, used: set[Any], errors: list[Diagnostic]
    ) -> list[Any]:
        """What parses of a chunk that does not: its error is reported; a declaration
        that does not close most likely ends where a line starts another one."""
        parts = line_head_chunks(text, chunk)
        if len(parts) == 1:
            return []
        reported = errors[-1]
        found = []
        for part in parts[1:]:
            piece = self._piece(lines.path, "chunk", text[part.start : part.end], part.start, used)
            if piece.error is None:
                found.append(piece.tree)
                continue
            where = reported.location
            diagnostic = _error(piece, text, lines)
            at = diagnostic.location
            if where is None or at is None or (at.line, at.column) != (where.line, where.column):
                errors.append(diagnostic)
        return found

    def _environment(
        self, text: str, lines: LineIndex, chunk: Chunk, used: set[Any], errors: list[Diagnostic]
    ) -> Any | None:
        """A long environment: its areas one by one, the rest (areas blanked out) at once.
        None when the rest does not parse (the whole chunk is parsed then, for its error)."""
        spans = area_spans(text, chunk)
        if not spans:
            return None
        skeleton = list(text[chunk.start : chunk.end])
        for start, end in spans:
            for i in range(start - chunk.start, end - chunk.start):
                if skeleton[i] != "\n":
                    skeleton[i] = " "
        rest = self._piece(lines.path, "skeleton", "".join(skeleton), chunk.start, used)
        if rest.error is not None:
            return None
        environment = rest.tree.declarations[0]
        members = [m for m in environment.members if m.__class__.__name__ != "Area"]  # areas of a last use
        for start, end in spans:
            area = self._piece(lines.path, "area", text[start:end], start - len(_AREA_HEAD), used)
            if area.error is not None:
                errors.append(_error(area, text, lines))
                continue
            members.append(area.tree)
            area.tree.parent = environment
        environment.members = sorted(members, key=lambda m: m._tx_position)
        return rest.tree

    def _piece(self, path: str, kind: str, source: str, offset: int, used: set[Any]) -> _Piece:
        key = (path, kind, source, 0)
        while key in used:  # the same text twice in a file (a duplicate): a tree for each
            key = (path, kind, source, key[3] + 1)
        used.add(key)
        piece = self._pieces.get(key)
        if piece is None:
            piece = _parse_piece(kind, source, path, offset)
            self._pieces[key] = piece
        elif piece.offset != offset and piece.tree is not None:
            _shift(piece.tree, offset - piece.offset)
            piece.offset = offset
        elif piece.offset != offset:
            piece.offset = offset
        return piece


def _parse_piece(kind: str, source: str, path: str, offset: int) -> _Piece:
    text = _AREA_HEAD + source + _AREA_TAIL if kind == "area" else source or " "  # (textX reads
    try:  # the file itself when given no text)
        tree = metamodel().model_from_str(text, file_name=path)
    except TextXSyntaxError as exc:
        where = LineIndex(path, text).offset(exc.line or 1, exc.col or 1)
        return _Piece(None, offset, (where, list(getattr(exc, "expected_rules", None) or [])))
    if isinstance(tree, str):  # textX's model of nothing but whitespace and comments
        return _Piece(_Document([], [], 0), offset)
    if kind == "area":
        tree = tree.declarations[0].members[0]
    if offset:
        _shift(tree, offset)
    return _Piece(tree, offset)


def _error(piece: _Piece, text: str, lines: LineIndex) -> Diagnostic:
    assert piece.error is not None
    where, rules = piece.error
    line, col = lines.line_col(min(len(text), piece.offset + where))
    return syntax_diagnostic_at(line, col, rules, text, lines.path)


def _shift(tree: Any, delta: int) -> None:
    """Move every position in ``tree`` by ``delta`` characters."""
    stack = [tree]
    while stack:
        obj = stack.pop()
        obj._tx_position += delta
        obj._tx_position_end += delta
        for name in getattr(obj, "_tx_attrs", ()):
            value = getattr(obj, name, None)
            if isinstance(value, list):
                stack.extend(v for v in value if hasattr(v, "_tx_position"))
            elif hasattr(value, "_tx_position"):
                stack.append(value)
