"""Code stays small enough to read at once (issue 32 item 8, issue 36 item 4).

In the package: no module over 500 lines, no function over 80, no class over 300; in ``bench/``,
no module over 500 lines.  A module or class that truly is one idea may be longer when its
docstring's first paragraph says why, in a line that starts with ``Long because:``.  Lengths are
ast's: ``end_lineno - lineno + 1``, decorators left out, the docstring counted.  Each test prints
every offender as ``path:line`` with its length.
"""

from __future__ import annotations

import ast
import functools
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "src" / "exsce_dsl"
BENCH = ROOT / "bench"
MOST_LINES = 500
MOST_FUNCTION_LINES = 80
MOST_CLASS_LINES = 300
REASON = "Long because:"
"""How a module's or class's docstring says why it is longer (in its first paragraph)."""

def _package_modules() -> Iterator[tuple[str, Path]]:
    for path in sorted(PACKAGE.rglob("*.py")):
        yield path.relative_to(PACKAGE).as_posix(), path


@functools.cache
def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"))


def _says_why(node: ast.Module | ast.ClassDef) -> bool:
    """Whether the docstring's first paragraph has a line starting with :data:`REASON`."""
    first = (ast.get_docstring(node) or "").split("\n\n")[0]
    return any(line.strip().startswith(REASON) for line in first.splitlines())


def _length(node: ast.stmt) -> int:
    assert node.end_lineno is not None
    return node.end_lineno - node.lineno + 1


def _report(offenders: list[str], what: str) -> str:
    return (
        f"{len(offenders)} {what} (split along their ideas, or say why with {REASON!r}):\n  "
        + "\n  ".join(offenders)
    )


def test_no_module_is_over_500_lines() -> None:
    modules = [(f"src/exsce_dsl/{r}", p) for r, p in _package_modules()]
    modules += [(p.relative_to(ROOT).as_posix(), p) for p in sorted(BENCH.rglob("*.py"))]
    offenders = []
    for shown, path in modules:
        lines = len(path.read_text(encoding="utf-8").splitlines())
        if lines > MOST_LINES and not _says_why(_tree(path)):
            offenders.append(f"{shown}:1 has {lines} lines")
    assert not offenders, _report(offenders, f"modules over {MOST_LINES} lines")


def test_no_function_is_over_80_lines() -> None:
    offenders = []
    for relative, path in _package_modules():
        for node in ast.walk(_tree(path)):
            if (
                isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
                and _length(node) > MOST_FUNCTION_LINES
            ):
                offenders.append(
                    f"src/exsce_dsl/{relative}:{node.lineno} {node.name} has {_length(node)} lines"
                )
    assert not offenders, _report(offenders, f"functions over {MOST_FUNCTION_LINES} lines")


def test_no_class_is_over_300_lines() -> None:
    offenders = []
    for relative, path in _package_modules():
        for node in ast.walk(_tree(path)):
            if isinstance(node, ast.ClassDef) and _length(node) > MOST_CLASS_LINES and not _says_why(node):
                offenders.append(
                    f"src/exsce_dsl/{relative}:{node.lineno} {node.name} has {_length(node)} lines"
                )
    assert not offenders, _report(offenders, f"classes over {MOST_CLASS_LINES} lines")


def test_the_reason_is_read_from_the_first_paragraph_only() -> None:
    said = ast.parse('"""A store.\n\nLong because: not here."""\n')
    assert not _says_why(said)
    said = ast.parse('"""A store.\nLong because: one protocol, one idea.\n\nMore."""\n')
    assert _says_why(said)
