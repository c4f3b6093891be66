"""The textX side of the language: the metamodel and syntax errors in words.

textX objects never leave ``lang``; :mod:`exsce_dsl.lang.builders.specification` turns them
into the semantic model.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from typing import Any

from textx import TextXSyntaxError, metamodel_from_str

from exsce_dsl.errors import Diagnostic, ExsceSyntaxError, SourceLocation
from exsce_dsl.lang.chunks import area_spans, declaration_chunks
from exsce_dsl.lang.lexical import string_value
from exsce_dsl.lang.locations import LineIndex
from exsce_dsl.lang.transformation_syntax import step_rules
from exsce_dsl.model.metrics import UNITS
from exsce_dsl.model.names import KEYWORDS
from exsce_dsl.resources import grammar_file
from exsce_dsl.suggest import closest, did_you_mean

# How rules of the grammar are named in messages.
_RULE_WORDS = {
    "Name": "a name",
    "Ref": "a name",
    "NUMBER": "a number",
    "FLOAT": "a number",
    "STRICTFLOAT": "a number",
    "INT": "a number",
    "STRING": "a quoted string",
    "Quoted": "a quoted string",
    "EOF": "the end of the file",
    "Length": "a length (a number, in m unless followed by cm or mm)",
    "Angle": "an angle (a number, in rad unless followed by deg)",
    "Duration": "a duration (a number followed by s, min, h or ms)",
}
# Environments this long (characters) are parsed an area at a time to try a correction.
_LONG_PIECE = 4000

MAX_NESTING = 20
"""Parentheses nested deeper than this are refused before parsing: the parser recurses some
forty Python frames a level, and Python stops at a thousand (issue 46: 28 levels were an
internal error)."""

# What the nesting count skips (strings and comments), and what it counts.
_NESTING_TOKEN = re.compile(r""""(?:\\.|[^"\\])*"|'(?:\\.|[^'\\])*'|//[^\n]*|/\*.*?\*/|[()]""", re.DOTALL)


def grammar_text() -> str:
    """The whole grammar of the entry file: ``exsce.tx``, then ``derive.tx`` and the rules of the
    steps, made from the transformations' records (see ``grammar/derive.tx``)."""
    entry = grammar_file()
    derive = (entry.parent / "derive.tx").read_text(encoding="utf-8")
    return "\n".join([entry.read_text(encoding="utf-8"), derive, step_rules()])


def new_metamodel() -> Any:
    """A fresh metamodel of the exsce grammar (textX caches nothing across them)."""
    # the entry file's name, for its imports
    made = metamodel_from_str(grammar_text(), file_name=str(grammar_file()), autokwd=True)
    made.register_obj_processors({"Quoted": string_value})  # textX's STRING does not unescape
    return made


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
    too_deep = nesting_diagnostic(text, path)
    if too_deep is not None:
        raise ExsceSyntaxError([too_deep])
    try:
        # textX reads the file itself when given no text: an empty editor buffer is not the file
        tree = _shared_metamodel().model_from_str(text or " ", file_name=path)
    except TextXSyntaxError as exc:
        raise ExsceSyntaxError([_syntax_diagnostic(exc, text, path)]) from None
    except RecursionError:  # deeper than the count above foresees (a deep caller, another construct)
        _shared_metamodel.cache_clear()  # a parser stopped midway is not reused
        where = _deepest_parenthesis(text, path) or SourceLocation(path, 1, 1, 1, 1)
        message = "the file nests too deeply to be read: write its expressions flatter"
        raise ExsceSyntaxError([Diagnostic(message, where, code="syntax")]) from None
    if isinstance(tree, str):  # textX's model of a text with nothing but whitespace and comments
        where = SourceLocation(path, 1, 1, 1, 1)
        raise ExsceSyntaxError([Diagnostic("the file declares nothing (it is empty or all comments)", where)])
    return ParsedFile(path, text, tree, lines)


def nesting_diagnostic(text: str, path: str) -> Diagnostic | None:
    """The error at the first parenthesis nested deeper than :data:`MAX_NESTING`, if any
    (parentheses in strings and comments are not counted)."""
    depth = 0
    for token in _NESTING_TOKEN.finditer(text):
        if token.group() == "(":
            depth += 1
            if depth > MAX_NESTING:
                message = (
                    f"parentheses nested more than {MAX_NESTING} deep: exsce reads at most "
                    f"{MAX_NESTING} levels (write the expression flatter)"
                )
                return Diagnostic(
                    message, LineIndex(path, text).span(token.start(), token.end()), code="syntax"
                )
        elif token.group() == ")":
            depth = max(0, depth - 1)
    return None


def _deepest_parenthesis(text: str, path: str) -> SourceLocation | None:
    """Where the parentheses of ``text`` are nested deepest (the first such), if it has any."""
    depth, deepest, at = 0, 0, None
    for token in _NESTING_TOKEN.finditer(text):
        if token.group() == "(":
            depth += 1
            if depth > deepest:
                deepest, at = depth, token
        elif token.group() == ")":
            depth = max(0, depth - 1)
    return LineIndex(path, text).span(at.start(), at.end()) if at is not None else None


def metamodel() -> Any:
    """The metamodel :func:`parse_text` uses, made once per process."""
    return _shared_metamodel()


def _syntax_diagnostic(exc: TextXSyntaxError, text: str, path: str) -> Diagnostic:
    rules = getattr(exc, "expected_rules", None) or []
    return syntax_diagnostic_at(exc.line or 1, exc.col or 1, rules, text, path)


def syntax_diagnostic_at(line: int, col: int, rules: list[Any], text: str, path: str) -> Diagnostic:
    """The diagnostic of a syntax error at ``line``:``col`` of ``text``, where the grammar
    expected ``rules`` (those of a textX syntax error).

    Two mistakes are told in their own words: a unit the language does not know
    (``facing 180 degs``: the number parses without it, and the word after it does
    not), and a misspelt keyword, either where the error is (``mision``) or just
    before it, read as a name (``r1: turtle start at p``).
    """
    lines = LineIndex(path, text)
    at = min(len(text), lines.offset(line, col))
    found = _token_at(text, line, col)
    better = _unknown_unit(text, at, lines) or _misspelt_keyword(text, at, rules, lines)
    if better is not None:
        return better
    expected = _expected_words(rules)
    message = f"expected {expected}, found {found}" if expected else f"syntax error near {found}"
    end_col = col + max(1, len(found) - 2 if found.startswith("'") else 1)
    return Diagnostic(message, SourceLocation(path, line, col, line, end_col), code="syntax")


# --------------------------------------------------------------- unknown units
@dataclass(frozen=True)
class _UnitFamily:
    """The units one kind of quantity token takes.  ``probe`` is one of them that no kind
    tried after it takes: the first probe that parses in place of an unknown unit tells
    which kind of quantity the grammar wanted there."""

    probe: str
    units: tuple[str, ...]


_METRIC_UNITS = tuple(UNITS)
# Tried in this order: each probe fits its own family and the ones before it only.
_UNIT_FAMILIES = (
    _UnitFamily("std", (*_METRIC_UNITS, "std", "%")),  # acceptance criteria: 1 std, 5 %
    _UnitFamily("m/s", _METRIC_UNITS),  # metrics
    _UnitFamily("m", ("m", "cm", "mm")),  # lengths: positions, sizes, tolerances
    _UnitFamily("deg", ("deg", "rad")),  # angles: headings
)
# Units as people write them in words.
_UNIT_WORDS = {
    **dict.fromkeys(("meter", "meters", "metre", "metres", "mtr", "mt"), "m"),
    **dict.fromkeys(("centimeter", "centimeters", "centimetre", "centimetres"), "cm"),
    **dict.fromkeys(("millimeter", "millimeters", "millimetre", "millimetres"), "mm"),
    **dict.fromkeys(("degree", "degrees", "degs", "grad"), "deg"),
    **dict.fromkeys(("radian", "radians", "rads"), "rad"),
    **dict.fromkeys(("sec", "secs", "second", "seconds"), "s"),
    **dict.fromkeys(("minute", "minutes", "mins"), "min"),
    **dict.fromkeys(("mps",), "m/s"),
}
_NUMBER_BEFORE = re.compile(r"(?<![\w.])[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?[ \t]*\Z")
_UNIT_WORD = re.compile(r"[A-Za-z_%°][\w/%°]*")


def _unknown_unit(text: str, at: int, lines: LineIndex) -> Diagnostic | None:
    """``unknown unit 'degs'; expected deg or rad; did you mean 'deg'?`` when the error is at
    a word right after a number, and a known unit there would have parsed."""
    word = _UNIT_WORD.match(text, at)
    if word is None or not _NUMBER_BEFORE.search(text, max(0, at - 40), at):
        return None
    written = word.group()
    for family in _UNIT_FAMILIES:
        if _parses_further(text, at, word.end(), family.probe, at):
            units = family.units
            listed = ", ".join(units[:-1]) + " or " + units[-1]
            if written in _UNIT_FAMILIES[0].units:  # a unit, of another kind of quantity
                message = f"unit '{written}' does not fit here; expected {listed}"
            else:
                guess = _UNIT_WORDS.get(written.lower())
                hint = f"; did you mean '{guess}'?" if guess in units else did_you_mean(written, units)
                message = f"unknown unit '{written}'; expected {listed}{hint}"
            return Diagnostic(message, lines.span(at, word.end()), code="syntax")
    return None


# ------------------------------------------------------------ misspelt keywords
_WORD_AT = re.compile(r"[A-Za-z_][\w-]*")
_WORD_BEFORE = re.compile(r"(?<![\w-])([A-Za-z_][\w-]*)[ \t\r\n]*\Z")


def _misspelt_keyword(text: str, at: int, rules: list[Any], lines: LineIndex) -> Diagnostic | None:
    """A did-you-mean for a keyword written wrong: the word at the error, when it is close to a
    keyword the grammar expected there; else the word before it, when it was read as a name
    and a keyword close to it would have parsed further."""
    word = _WORD_AT.match(text, at)
    wanted = [w for w in (_keyword_of(r) for r in rules) if w is not None]
    if word is not None and word.group() not in KEYWORDS:
        match = closest(word.group(), wanted)
        if match is not None:
            message = f"expected {_expected_words(rules)}, found '{word.group()}'; did you mean '{match}'?"
            return Diagnostic(message, lines.span(at, word.end()), code="syntax")
    before = _WORD_BEFORE.search(text, max(0, at - 200), at)
    if before is None or before.group(1) in KEYWORDS:  # a reserved word is never read as a name
        return None
    written, start, end = before.group(1), before.start(1), before.end(1)
    for keyword in _close_keywords(written):
        if _parses_further(text, start, end, keyword, at):
            message = f"expected '{keyword}', found '{written}'; did you mean '{keyword}'?"
            return Diagnostic(message, lines.span(start, end), code="syntax")
    return None


def _keyword_of(rule: Any) -> str | None:
    literal = getattr(rule, "to_match", None)
    name = getattr(rule, "rule_name", "") or ""
    if isinstance(literal, str) and not name and _KEYWORD.fullmatch(literal):
        return literal
    return None


def _close_keywords(word: str, most: int = 3) -> list[str]:
    """Up to ``most`` keywords most like ``word``, the closest first."""
    candidates = set(grammar_keywords()) - {word}
    found: list[str] = []
    while len(found) < most and (match := closest(word, candidates)) is not None:
        found.append(match)
        candidates.discard(match)
    return found


@functools.lru_cache(maxsize=1)
def grammar_keywords() -> frozenset[str]:
    """Every keyword of the grammar (``starts``, ``visit``, ``nav2``...)."""
    found: set[str] = set()
    seen: set[int] = set()
    stack = [_shared_metamodel()._parser_blueprint.parser_model]
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        keyword = _keyword_of(node)
        if keyword is not None:
            found.add(keyword)
        stack.extend(getattr(node, "nodes", ()))
    return frozenset(found)


def _parses_further(text: str, start: int, end: int, replacement: str, error_at: int) -> bool:
    """Whether ``text`` with ``text[start:end]`` replaced parses past ``error_at``, where its
    syntax error is (the start of the replaced text, or after its end), and past the replacement.

    Only the declaration around the change is parsed, up to the end of the error's line
    (of a long environment, only the area it is in): it is enough to see the parse go on.
    """
    chunk = next((c for c in reversed(declaration_chunks(text)) if c.start <= start), None)
    head, begin = "", chunk.start if chunk is not None else 0
    if chunk is not None and chunk.keyword == "environment" and chunk.end - chunk.start > _LONG_PIECE:
        area = next(((a, b) for a, b in area_spans(text, chunk) if a <= start and error_at < b), None)
        if area is not None:
            head, begin = "environment _ {\n", area[0]
    line_end = text.find("\n", error_at)
    line_end = len(text) if line_end < 0 else line_end
    piece = head + text[begin:start] + replacement + text[end:line_end]
    # where the original error is in the piece (the text after the change moved with it):
    # the parse must get past it, and past the whole replacement
    shift = len(replacement) - (end - start) if error_at >= end else 0
    original = len(head) + error_at - begin + shift
    replaced_end = len(head) + start - begin + len(replacement)
    try:
        _shared_metamodel().model_from_str(piece)
    except TextXSyntaxError as exc:
        reached = LineIndex("", piece).offset(exc.line or 1, exc.col or 1)
        return reached > original and reached >= replaced_end
    return True


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
