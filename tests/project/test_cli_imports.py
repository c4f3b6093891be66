"""The command line is a thin shell over ``exsce_dsl.api`` (issue 49, item 3).

Every module of ``src/exsce_dsl/cli`` imports of exsce only the API's face, the command line's own
modules, the errors (and their remedies, in words: ``exsce_dsl.remedies``) and the semantic model: whatever a command does can be done from Python with
the same names.  Every ``import`` counts, those inside functions (lazy, for start-up speed) and
under ``TYPE_CHECKING`` too.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

CLI = Path(__file__).resolve().parents[2] / "src" / "exsce_dsl" / "cli"

ALLOWED = ("exsce_dsl.api", "exsce_dsl.cli", "exsce_dsl.errors", "exsce_dsl.remedies", "exsce_dsl.model")
"""What a command module may import of exsce (these packages and the modules below them)."""

REMAINING: dict[str, set[str]] = {}
"""Imports not moved behind the API yet, by module (each to go; the list only shrinks)."""


def _offending(path: Path) -> list[str]:
    """Each import of ``path`` that reaches into exsce past :data:`ALLOWED`, as ``line: module``."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:  # relative: inside the command line, but say it the long way
                found.append(f"{node.lineno}: a relative import")
                continue
            module = node.module or ""
            names = [f"{module}.{a.name}" for a in node.names] if module == "exsce_dsl" else [module]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        for name in names:
            inside = name == "exsce_dsl" or name.startswith("exsce_dsl.")
            if inside and not any(name == a or name.startswith(f"{a}.") for a in ALLOWED):
                found.append(f"{node.lineno}: {name}")
    return found


def _modules() -> list[Path]:
    return sorted(CLI.glob("*.py"))


@pytest.mark.parametrize("path", _modules(), ids=lambda p: p.name)
def test_a_command_module_imports_only_the_api(path: Path) -> None:
    offending = [
        line for line in _offending(path) if line.split(": ", 1)[1] not in REMAINING.get(path.name, set())
    ]
    assert not offending, f"cli/{path.name} imports past exsce_dsl.api:\n" + "\n".join(offending)


def test_the_remaining_exceptions_are_still_there() -> None:
    """An exception that was moved comes off :data:`REMAINING` (so that the list only shrinks)."""
    stale = [
        f"{module}: {name}"
        for module, names in REMAINING.items()
        for name in names
        if not any(line.endswith(f": {name}") for line in _offending(CLI / module))
    ]
    assert not stale, "take these off REMAINING:\n" + "\n".join(stale)


def test_the_checker_sees_a_lazy_import_and_the_package_root(tmp_path: Path) -> None:
    module = tmp_path / "m.py"
    module.write_text(
        "from exsce_dsl.api import load\n"
        "from exsce_dsl import __version__\n"
        "def f():\n"
        "    from exsce_dsl.store.open import open_store\n"
        "    import exsce_dsl.lang\n"
    )
    assert _offending(module) == ["2: exsce_dsl.__version__", "4: exsce_dsl.store.open", "5: exsce_dsl.lang"]


def test_every_command_module_is_checked() -> None:
    assert len([p for p in _modules() if p.name != "__init__.py"]) == 19
