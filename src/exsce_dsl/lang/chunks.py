"""Cut ``.exsce`` text into its top-level declarations, and an environment into its areas.

The language server parses and caches each declaration on its own
(:mod:`exsce_dsl.lang.incremental`), and completion parses only the declaration
the cursor is in (:mod:`exsce_dsl.lang.editor.continuations`).  This is lexical only: strings,
comments and braces.  A declaration starts with its keyword at brace depth 0,
first in the text or right after the closing brace of the previous declaration
or an import's string; nothing else can stand there in valid text, so valid text
is cut exactly where its declarations begin.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass

DECLARATION_KEYWORDS = frozenset(
    {"robot", "environment", "task", "scenario", "acceptance", "derive", "metric"}
)

# What nests: strings (either quote, may be unterminated), comments and braces.
_STRUCTURE = re.compile(r'"(?:\\.|[^"\\])*"?|\'(?:\\.|[^\'\\])*\'?|//[^\n]*|/\*.*?(?:\*/|\Z)|[{}]', re.DOTALL)
# Between those: words and runs of other characters.
_PLAIN = re.compile(r"[A-Za-z_][\w-]*|[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?|[^\s\w\"'/{}]+|[\w-]+|/")

# A declaration written at the start of a line: where a declaration left open (a
# missing `}`) most likely ends.  `scenario "title"` of acceptance criteria is not one.
_LINE_HEAD = re.compile(
    r"^(?:(?:robot[ \t]+type|environment|task|scenario|derive|metric)[ \t]+[A-Za-z_]|acceptance[ \t]+for\b)",
    re.MULTILINE,
)


@dataclass(frozen=True)
class Chunk:
    """``text[start:end]``: the imports (``keyword`` None) or one declaration."""

    start: int
    end: int
    keyword: str | None


@dataclass(frozen=True)
class Token:
    start: int
    end: int
    text: str
    depth: int
    """Brace depth before the token."""

    @property
    def kind(self) -> str:
        """``word``, ``string``, ``comment``, ``{``, ``}`` or ``other``."""
        first = self.text[0]
        if first in "\"'":
            return "string"
        if self.text.startswith(("//", "/*")):
            return "comment"
        if first in "{}":
            return first
        return "word" if first.isalpha() or first == "_" else "other"


def tokens(
    text: str, start: int = 0, end: int | None = None, max_depth: int | None = None
) -> Iterator[Token]:
    """The tokens of ``text[start:end]`` with their brace depth (counted from ``start``).

    With ``max_depth``, only braces are given below that depth (a quicker scan of long texts).
    """
    end = len(text) if end is None else end
    depth, at = 0, start
    for match in _STRUCTURE.finditer(text, start, end):
        shallow = max_depth is None or depth <= max_depth
        if shallow and match.start() > at:
            for plain in _PLAIN.finditer(text, at, match.start()):
                yield Token(plain.start(), plain.end(), plain.group(), depth)
        at = match.end()
        value = match.group()
        if value == "{":
            yield Token(match.start(), at, value, depth)
            depth += 1
        elif value == "}":
            depth = max(0, depth - 1)
            yield Token(match.start(), at, value, depth + 1)
        elif shallow:
            yield Token(match.start(), at, value, depth)
    if (max_depth is None or depth <= max_depth) and end > at:
        for plain in _PLAIN.finditer(text, at, end):
            yield Token(plain.start(), plain.end(), plain.group(), depth)


def declaration_chunks(text: str) -> list[Chunk]:
    """The imports, then each declaration, covering ``text`` end to end."""
    starts: list[tuple[int, str]] = []
    previous = "start"  # start | closed | import | import-string | other
    for token in tokens(text, max_depth=0):
        kind = token.kind
        if kind == "comment":
            continue
        if token.depth == 0 and kind == "word" and token.text in DECLARATION_KEYWORDS:
            if previous in ("start", "closed", "import-string"):
                starts.append((token.start, token.text))
        if kind == "}" and token.depth == 1:
            previous = "closed"
        elif token.depth == 0 and kind == "word" and token.text == "import":
            previous = "import"
        elif kind == "string" and previous == "import":
            previous = "import-string"
        else:
            previous = "other"
    if not starts:
        return [Chunk(0, len(text), None)]
    chunks = []
    if text[: starts[0][0]].strip() and _has_code(text, 0, starts[0][0]):
        chunks.append(Chunk(0, starts[0][0], None))
    else:
        starts[0] = (0, starts[0][1])
    for (start, keyword), (end, _) in zip(starts, [*starts[1:], (len(text), "")], strict=True):
        chunks.append(Chunk(start, end, keyword))
    return chunks


def _has_code(text: str, start: int, end: int) -> bool:
    return any(t.kind != "comment" for t in tokens(text, start, end, max_depth=0))


def line_head_chunks(text: str, chunk: Chunk) -> list[Chunk]:
    """``chunk`` cut again where a line starts with a declaration: for a declaration
    that does not close, so that those after it still count."""
    heads = [m.start() for m in _LINE_HEAD.finditer(text, chunk.start, chunk.end) if m.start() > chunk.start]
    if not heads:
        return [chunk]
    bounds = [chunk.start, *heads, chunk.end]
    found = []
    for start, end in zip(bounds, bounds[1:], strict=False):
        word = re.match(r"[a-z]+", text[start:end])
        found.append(Chunk(start, end, word.group() if word and start != chunk.start else chunk.keyword))
    return found


def area_spans(text: str, chunk: Chunk) -> list[tuple[int, int]]:
    """The ``area NAME { ... }`` members of an environment declaration, as (start, end);
    empty when one of them does not close."""
    spans: list[tuple[int, int]] = []
    opened: int | None = None
    for token in tokens(text, chunk.start, chunk.end, max_depth=1):
        if token.kind == "comment":
            continue
        if opened is None and token.depth == 1 and token.text == "area":
            opened = token.start
        elif opened is not None and token.kind == "}" and token.depth == 2:
            spans.append((opened, token.end))
            opened = None
    return [] if opened is not None else spans


# A top-level declaration's keyword -> the kind of what it declares.
_DECLARES = {
    "environment": "environment",
    "task": "task",
    "scenario": "scenario",
    "derive": "scenario",
    "metric": "metric",
}


def declared_names(text: str) -> set[tuple[str, str]]:
    """What ``text`` seems to declare, as (kind, name), read from its words alone: for a
    file with a syntax error, whose parse tree (if any) lacks some of them.

    Top-level declarations (``robot type``, ``environment``, ``task``, ``scenario``,
    ``derive``, ``metric``), and an environment's areas, poses and obstacles.
    """
    words = [t for t in tokens(text) if t.kind != "comment"]
    found: set[tuple[str, str]] = set()
    within: str | None = None  # the keyword of the top-level declaration the words are in
    for i, token in enumerate(words):
        after = words[i + 1] if i + 1 < len(words) else None
        then = words[i + 2] if i + 2 < len(words) else None
        if token.depth == 0 and token.kind == "word":
            within = token.text if token.text in DECLARATION_KEYWORDS else within
        if after is None or after.kind != "word":
            continue
        if token.depth == 0 and token.text in _DECLARES:
            found.add((_DECLARES[token.text], after.text))
        elif token.depth == 0 and token.text == "robot" and after.text == "type":
            if then is not None and then.kind == "word":
                found.add(("robot type", then.text))
        elif within == "environment" and token.depth > 0 and token.text in ("area", "pose", "obstacle"):
            found.add((token.text, after.text))
    return found


def imported_paths(text: str) -> list[str]:
    """The paths of the ``import "..."`` lines of ``text``, read from its words alone (for a
    file with a syntax error)."""
    found = []
    previous: Token | None = None
    for token in tokens(text, max_depth=0):
        if token.kind == "comment":
            continue
        closed = len(token.text) > 1 and token.text[-1] == token.text[0]
        if previous is not None and previous.text == "import" and token.kind == "string" and closed:
            found.append(re.sub(r"\\(.)", r"\1", token.text[1:-1]))
        previous = token if token.depth == 0 else None
    return found
