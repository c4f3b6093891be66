"""The code that runs on robots keeps to Python 3.8 (ROS Noetic's): the metric core and the
runtime copied into the generated node packages, and the generated modules themselves.

ast.parse(feature_version=(3, 8)) catches new syntax; the walk below catches the newer
run-time spellings that parse fine but fail on 3.8: ``X | Y`` of types and ``list[...]``
outside annotations, ``zip(..., strict=...)``, ``str.removeprefix``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from exsce_dsl.resources import package_file

GOLDEN = Path(__file__).parents[1] / "golden"
_TYPES = {"int", "float", "str", "bool", "bytes", "list", "tuple", "dict", "set", "frozenset", "type"}
_BUILTIN_GENERICS = {"list", "tuple", "dict", "set", "frozenset", "type"}


def _sources() -> list[tuple[str, str]]:
    found = [(f"monitor_kit/{name}", package_file("monitor_kit", name).read_text()) for name in
             ("monitor_core.py", "monitor_runtime.py")]
    for folder in ("monitors", "ros1_monitor", "ros2_monitor"):
        for path in sorted((GOLDEN / folder).rglob("*")):
            if path.is_file() and (path.suffix == ".py" or path.name == "exsce_monitor_node"):
                found.append((str(path.relative_to(GOLDEN)), path.read_text()))
    return found


def _annotations(tree: ast.AST) -> set[int]:
    """ids of every node inside an annotation (never evaluated under `from __future__ import annotations`)."""
    inside: set[int] = set()
    for node in ast.walk(tree):
        roots: list[ast.AST | None] = []
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            args = node.args
            roots += [a.annotation for a in args.args + args.kwonlyargs + args.posonlyargs]
            roots += [args.vararg.annotation if args.vararg else None, args.kwarg.annotation if args.kwarg else None]
            roots.append(node.returns)
        elif isinstance(node, ast.AnnAssign):
            roots.append(node.annotation)
        for root in roots:
            if root is not None:
                inside.update(id(n) for n in ast.walk(root))
    return inside


def _is_type(node: ast.AST) -> bool:
    return (
        (isinstance(node, ast.Name) and (node.id in _TYPES or node.id[:1].isupper()))
        or (isinstance(node, ast.Constant) and node.value is None)
        or (isinstance(node, ast.Subscript))
        or (isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitOr))
    )


@pytest.mark.parametrize(("name", "source"), _sources(), ids=[n for n, _ in _sources()])
def test_runs_on_python_3_8(name, source):
    tree = ast.parse(source, feature_version=(3, 8))
    future = any(isinstance(n, ast.ImportFrom) and n.module == "__future__" for n in tree.body)
    skip = _annotations(tree) if future else set()  # without the import, annotations run too
    problems = []
    abc_names = {
        alias.asname or alias.name
        for n in ast.walk(tree)
        if isinstance(n, ast.ImportFrom) and n.module == "collections.abc"
        for alias in n.names
    }
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitOr) and (
            _is_type(node.left) and _is_type(node.right)
        ):
            problems.append(f"line {node.lineno}: X | Y of types")
        if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and (
            node.value.id in _BUILTIN_GENERICS
        ):
            problems.append(f"line {node.lineno}: {node.value.id}[...] at run time")
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "zip" and any(
            k.arg == "strict" for k in node.keywords
        ):
            problems.append(f"line {node.lineno}: zip(strict=...)")
        if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and node.value.id in abc_names:
            problems.append(f"line {node.lineno}: collections.abc.{node.value.id}[...] at run time")
        if isinstance(node, ast.Attribute) and node.attr in ("removeprefix", "removesuffix"):
            problems.append(f"line {node.lineno}: {node.attr}")
    assert not problems, problems


def test_the_check_finds_what_it_looks_for():
    bad = "from __future__ import annotations\nNumber = float | int\nx = list[int]\nzip(a, b, strict=True)\n"
    tree = ast.parse(bad)
    assert isinstance(tree.body[1].value, ast.BinOp) and _is_type(tree.body[1].value.left)
    with pytest.raises(AssertionError):
        test_runs_on_python_3_8("bad.py", bad)
