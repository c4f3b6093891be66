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
    # the base
    {"errors", "remedies", "suggest", "resources", "textfiles", "tables", "templating", "figures", "user_cache",
     "wording", "output_folder", "plugins", "faces"},
    {"model"},
    {"messages", "maps", "monitor_kit", "parallel"},
    {"transform"},
    {"lang"},
    {"monitor_code"},
    {"prov"},
    {"rdf"},
    {"store"},
    {"runs"},
    {"sim"},
    {"oracles"},
    {"derive"},
    {"execute"},
    {"similarity", "explore", "codegen"},
    {"report", "lsp", "mcp_server", "endpoint"},
    {"api"},
    {"cli"},
]
RANK = {name: rank for rank, names in enumerate(LAYERS) for name in names}


STEPS: dict[str, list[set[str]]] = {
    "lang": [
        # the core the other parts share
        {"locations", "lexical", "transformation_syntax", "chunks", "parser", "loader", "incremental", "stdlib"},
        # values kept while exsce's code is unchanged (the parsed standard library)
        {"code_cache"},
        # parse trees to the model
        {"builders"},
        # checked specifications kept in the user's cache: loaded through the builders
        {"spec_cache"},
        {"format"},
        {"yaml"},
        {"registration"},
        {"editor"},
    ],
    "runs": [
        {"bags"},
        {"signals"},
        {"segments"},
        {"metrics"},
        {"coverage"},
        {"recorded_execution"},
        {"analyse", "ingest", "robots", "bag_identity", "bag_info", "bag_robots", "bag_runs", "missing", "plausible_poses"},
        {"spec_draft"},
    ],
}
"""Inside a layer that has steps, the same rule between its subpackages and modules."""


def _layer(module: str) -> str:
    """``exsce_dsl.runs.ingest`` → ``runs``; ``exsce_dsl.errors`` → ``errors``."""
    return module.split(".")[1]


def _step(layer: str, module: str) -> int | None:
    """The rank of ``module``'s step inside ``layer`` (None: the layer has no steps)."""
    parts = module.split(".")
    if layer not in STEPS or len(parts) < 3:
        return None
    ranks = {name: rank for rank, names in enumerate(STEPS[layer]) for name in names}
    return ranks[parts[2].removesuffix(".py")]


def _imports(path: Path) -> list[tuple[str, int]]:
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = (
                [node.module] if node.module != "exsce_dsl" else [f"exsce_dsl.{a.name}" for a in node.names]
            )
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


@pytest.mark.parametrize("layer", sorted(STEPS))
def test_steps_inside_a_layer_go_down(layer: str) -> None:
    upward = []
    for path in sorted((PACKAGE / layer).rglob("*.py")):
        inside = path.relative_to(PACKAGE).with_suffix("").parts
        if len(inside) < 2 or inside[1] == "__init__":
            continue
        mine = _step(layer, ".".join(("exsce_dsl", *inside)))
        for name, line in _imports(path):
            theirs = _step(layer, name) if _layer(name) == layer else None
            if theirs is not None and mine is not None and theirs > mine:
                upward.append(f"{path.relative_to(PACKAGE)}:{line}: imports {name} (a later step of {layer})")
    assert not upward, "\n".join(upward)


def test_every_step_is_known() -> None:
    for layer, steps in STEPS.items():
        named = {name for names in steps for name in names}
        present = {p.name.removesuffix(".py") for p in (PACKAGE / layer).iterdir() if p.name != "__init__.py"}
        present = {name for name in present if not name.startswith("__")}
        assert present <= named, f"place these in STEPS[{layer!r}] (and DESIGN.md): {sorted(present - named)}"


def test_the_checker_sees_an_upward_import(tmp_path: Path) -> None:
    module = tmp_path / "m.py"
    module.write_text("def f():\n    from exsce_dsl.cli.main import main\n")
    [(name, line)] = _imports(module)
    assert (_layer(name), line) == ("cli", 2) and RANK["cli"] > RANK["lang"]
