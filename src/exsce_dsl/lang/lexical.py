"""Lexical facts about exsce text that the parse tree does not keep."""

from __future__ import annotations

import re

# A string literal, or a comment; strings come first so `"//"` is not a comment.
_TOKEN = re.compile(r'"(?:\\.|[^"\\])*"|//[^\n]*|/\*.*?\*/', re.DOTALL)


def has_comments(text: str) -> bool:
    return any(not m.group().startswith('"') for m in _TOKEN.finditer(text))
