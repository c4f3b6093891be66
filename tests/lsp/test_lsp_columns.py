"""Positions on the wire: the language server counts columns in the code units of the encoding
it agreed with the client (UTF-16 by default), the language in characters."""

from __future__ import annotations

from lsprotocol import types

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lsp.convert import TextLines


def test_lsp_columns_count_code_units_of_the_agreed_encoding() -> None:
    text = "a\n/* 🤖 é */ visit x\n"
    where = SourceLocation("f", 2, 17, 2, 18)  # the x: the 17th character of line 2
    assert TextLines(text).range(where) == types.Range(types.Position(1, 17), types.Position(1, 18))  # 🤖: 2
    assert TextLines(text, "utf-8").range(where).start == types.Position(1, 20)  # 🤖: 4 bytes, é: 2
    assert TextLines(text, "utf-32").range(where).start == types.Position(1, 16)
    for encoding in ("utf-8", "utf-16", "utf-32"):
        lines = TextLines(text, encoding)
        assert lines.offset(lines.range(where).start) == text.index("x")
