"""One import path per name (issue 49, item 4): no module of src re-exports a name it imports by the
``from M import X as X`` alias (14 such aliases gave classes two import paths: an error from
``errors`` and from the module that raised it before).  mypy's strict mode (no implicit
re-export) then refuses an import of X from anywhere but its home."""

from __future__ import annotations

import ast

from tests.support.paths import ROOT


def test_no_module_re_exports_a_name_by_alias() -> None:
    found = []
    for path in sorted((ROOT / "src" / "exsce_dsl").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                found += [
                    f"{path.relative_to(ROOT)}:{node.lineno}: {alias.name} as {alias.asname}"
                    for alias in node.names
                    if alias.asname == alias.name
                ]
    assert found == [], "re-export aliases (import the name from its home instead):\n" + "\n".join(found)
