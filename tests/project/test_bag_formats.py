"""What tells a bag by its name lives in the bag formats' records only (issue 49).

The suffixes of the formats (``.bag``, ``.mcap``, ``.db3``) and the ROS 2 bag's
``metadata.yaml`` are written in :mod:`exsce_dsl.runs.bags.formats`; any other module that
writes one as a string (``".mcap"``, ``"*.bag"``, ``"metadata.yaml"``) keeps a list of bag
formats of its own, which a new format would not reach.  Each place is named.
"""

from __future__ import annotations

import ast
from pathlib import Path

from exsce_dsl.runs.bags.formats import BUILT_IN_FORMATS, ROS2_METADATA

PACKAGE = Path(__file__).resolve().parents[2] / "src" / "exsce_dsl"
HOME = PACKAGE / "runs" / "bags" / "formats.py"
SUFFIXES = tuple(f.suffix for f in BUILT_IN_FORMATS)


def _names_a_format(text: str) -> bool:
    """A word (no space) that is, or ends in, a format's suffix, or the ROS 2 metadata's name."""
    return not any(c.isspace() for c in text) and (text.endswith(SUFFIXES) or text.endswith(ROS2_METADATA))


def _docstrings(tree: ast.AST) -> set[int]:
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                found.add(id(first.value))
    return found


def test_bag_suffixes_are_written_in_the_formats_records_only() -> None:
    places = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path == HOME:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        skip = _docstrings(tree)
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Constant)
                and isinstance(node.value, str)
                and id(node) not in skip
                and _names_a_format(node.value)
            ):
                places.append(f"{path.relative_to(PACKAGE)}:{node.lineno}: {node.value!r}")
    assert not places, "bag suffixes written outside runs/bags/formats.py:\n" + "\n".join(places)


def test_the_check_sees_a_suffix_list() -> None:
    """The test's own rule catches the lists it was written for (``oracles/judging.py`` had one)."""
    tree = ast.parse('_BAG_SUFFIXES = (".bag", ".mcap", ".db3")\nmeta = folder / "metadata.yaml"\n')
    written = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and _names_a_format(n.value)]
    assert written == [".bag", ".mcap", ".db3", "metadata.yaml"]
