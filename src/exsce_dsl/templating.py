"""The one Jinja2 environment of exsce's generated code, with escaping for each target language.

It sits beside :mod:`exsce_dsl.resources` because two layers render templates:
``runs`` (the monitors that ingestion runs) and ``codegen`` (files for users).

Generated code is Python, YAML and OSC2 (and, in the ROS packages, XML, CMake and
Markdown).  Nothing from a user's file is pasted into it raw: identifiers go
through :func:`python_name` (checked, never rewritten), strings through
:func:`python_string`, :func:`yaml_string` or :func:`osc2_string` (quoted by the target's own
rules), and numbers through :func:`python_number` or :func:`yaml_number`.
Text that only informs a reader (comments) goes through :func:`comment_text`,
which leaves it on one line, and then through :func:`xml_comment_text`,
:func:`xml_text` or :func:`markdown_text` in those languages.
Undefined template variables are errors (``StrictUndefined``).
"""

from __future__ import annotations

import functools
import json
import keyword
import math
import re
import unicodedata
from collections.abc import Callable, Mapping
from typing import Any
from xml.sax.saxutils import escape

import jinja2

from exsce_dsl.errors import GenerationError
from exsce_dsl.resources import resource_dir

_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def python_name(name: str) -> str:
    """``name`` if it is a Python identifier that is not a keyword; an error otherwise."""
    if not _IDENTIFIER.fullmatch(name) or keyword.iskeyword(name) or keyword.issoftkeyword(name):
        raise GenerationError(f"'{name}' cannot be used as a name in generated Python code")
    return name


def _escaped(char: str) -> str:
    code = ord(char)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


def _double_quoted(text: str) -> str:
    """``text`` between double quotes, in ASCII: ``"`` and ``\\`` escaped, control characters as
    JSON escapes them, and every other character past ``~`` as ``\\xXX``, ``\\uXXXX`` or
    ``\\UXXXXXXXX``: one escape per code point, which Python and YAML read back alike (JSON's
    surrogate pairs for characters past U+FFFF would read back as two lone surrogates)."""
    return "".join(c if c < "\x7f" else _escaped(c) for c in json.dumps(text, ensure_ascii=False))


def python_string(text: str) -> str:
    """A Python string literal of ``text``, on one line and in ASCII."""
    return _double_quoted(text)


def yaml_string(text: str) -> str:
    """A double-quoted YAML scalar of ``text``, on one line and in ASCII."""
    return _double_quoted(text)


_BREAKING = frozenset(("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"))
"""Unicode categories a comment may not hold: control characters (NUL, \\r, \\v, \\f, U+0085...),
format characters (bidirectional overrides that make code read otherwise than it runs),
surrogates, private use, noncharacters (U+FFFF, which XML may not hold) and the line and
paragraph separators U+2028 and U+2029."""


def comment_text(text: str) -> str:
    """``text`` on one line, for a ``#`` comment of generated code (Python, YAML, CMake, INI):
    every line break and control or format character becomes a space, so that nothing after
    it is read as code."""
    return "".join(" " if unicodedata.category(c) in _BREAKING else c for c in text)


def docstring_text(text: str) -> str:
    """:func:`comment_text` inside a Python docstring: backslashes and quotes escaped besides,
    so that the text neither ends the docstring nor starts an escape sequence."""
    return comment_text(text).replace("\\", "\\\\").replace('"', '\\"').replace("'", "\\'")


def xml_comment_text(text: str) -> str:
    """:func:`comment_text` inside an XML (or Markdown) comment, which may not hold ``--``
    (``-\\u002d`` reads as ``--`` where the text is a Python literal) nor end with ``-``."""
    return comment_text(text).replace("--", "-\\u002d").removesuffix("-")


def xml_text(text: str) -> str:
    """:func:`comment_text` as XML character data (between tags, not in an attribute): ``& < >``
    escaped."""
    return escape(comment_text(text))


def markdown_text(text: str) -> str:
    """:func:`comment_text` for a Markdown page: ``& < >`` as HTML entities (no tag of the
    text reaches a renderer that shows HTML)."""
    return escape(comment_text(text))


def osc2_string(text: str) -> str:
    """An OSC2 string literal of ``text`` (scenario_execution reads a literal's body with Python's
    ``unicode_escape``), on one line and in ASCII: :func:`_double_quoted`, and ``'`` escaped too,
    which OSC2's lexer does not take bare inside a string."""
    return _double_quoted(text).replace("'", "\\'")


def python_number(value: float | int) -> str:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise GenerationError(f"{value!r} is not a number")
    if isinstance(value, float) and not math.isfinite(value):
        raise GenerationError(f"{value!r} is not a finite number")
    return repr(value)


def yaml_number(value: float | int) -> str:
    """A number as YAML 1.1 readers (PyYAML, rosparam) read it back: a float always has a '.'
    (Python's ``1e-05`` would read as text)."""
    text = python_number(value)
    if isinstance(value, float) and "e" in text and "." not in text:
        mantissa, _, exponent = text.partition("e")
        text = f"{mantissa}.0e{exponent}"
    return text


def unwrap(code: str) -> str:
    """``code`` without the parentheses around all of it, if it has them."""
    if not (code.startswith("(") and code.endswith(")")):
        return code
    depth = 0
    for i, char in enumerate(code):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if depth == 0 and i < len(code) - 1:
            return code  # the first parenthesis closes before the end: `(a) + (b)`
    return code[1:-1]


def _is_node(value: object, kind: str) -> bool:
    """``{% if e is node("Aggregate") %}``: the class of a semantic-model node."""
    return type(value).__name__ == kind


@functools.cache
def environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(resource_dir("templates"))),
        undefined=jinja2.StrictUndefined,
        autoescape=False,  # no HTML here; each value is escaped for its language by a filter
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters.update(
        pyname=python_name,
        pystr=python_string,
        yamlstr=yaml_string,
        pynum=python_number,
        yamlnum=yaml_number,
        oscstr=osc2_string,
        unwrap=unwrap,
        comment=comment_text,
        docstring=docstring_text,
        xmlcomment=xml_comment_text,
        xmltext=xml_text,
        mdtext=markdown_text,
    )
    env.tests["node"] = _is_node
    return env


def render(template: str, **context: object) -> str:
    """Render ``templates/<template>`` with ``context``."""
    return environment().get_template(template).render(**context)


def render_with_tests(template: str, tests: Mapping[str, Callable[[Any], bool]], **context: object) -> str:
    """:func:`render` with Jinja tests the template uses beyond this module's (a layer above
    passes what only it knows, such as its model's)."""
    env = environment()
    env.tests.update(tests)
    return env.get_template(template).render(**context)
