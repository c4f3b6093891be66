"""The package's imports go down the layers of DESIGN.md, never up or sideways into a higher one.

Every ``import`` of every module counts, also those inside functions (a lazy import is still an
upward edge).  The order, bottom to top; a module may import its own layer and those below it.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "src" / "exsce_dsl"

LAYERS: list[set[str]] = [
    {"errors", "suggest", "resources", "textfiles", "tables", "templating", "figures"},  # the base
    {"model"},
    {"transform"},
    {"messages"},
    {"lang"},
    {"prov"},
    {"rdf"},
    {"store"},
    {"sim", "runs"},
    {"oracles"},
    {"derive"},
    {"similarity", "explore", "codegen"},
    {"report", "lsp", "mcp_server"},
    {"api"},
    {"cli"},
]
RANK = {name: rank for rank, names in enumerate(LAYERS) for name in names}


def _layer(module: str) -> str:
    """``exsce_dsl.runs.ingest`` → ``runs``; ``exsce_dsl.errors`` → ``errors``."""
    return module.split(".")[1]


def _imports(path: Path) -> list[tuple[str, int]]:
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] if node.module != "exsce_dsl" else [f"exsce_dsl.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        found += [(name, node.lineno) for name in names if name.startswith("exsce_dsl.")]
    return found


def _modules() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py") if p.relative_to(PACKAGE).parts[0] != "__init__.py")


def test_every_layer_is_known() -> None:
    layers = {p.relative_to(PACKAGE).parts[0].removesuffix(".py") for p in _modules()}
    assert layers <= RANK.keys(), f"place these in LAYERS (and DESIGN.md): {sorted(layers - RANK.keys())}"


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_imports_go_down(path: Path) -> None:
    mine = path.relative_to(PACKAGE).parts[0].removesuffix(".py")
    upward = [
        f"{path.relative_to(PACKAGE)}:{line}: imports {name} ({_layer(name)} is above {mine})"
        for name, line in _imports(path)
        if RANK.get(_layer(name), -1) > RANK[mine]
    ]
    assert not upward, "\n".join(upward)


def test_the_checker_sees_an_upward_import(tmp_path: Path) -> None:
    module = tmp_path / "m.py"
    module.write_text("def f():\n    from exsce_dsl.cli.main import main\n")
    [(name, line)] = _imports(module)
    assert (_layer(name), line) == ("cli", 2) and RANK["cli"] > RANK["lang"]
