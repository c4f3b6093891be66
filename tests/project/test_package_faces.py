"""One face per package (issue 49, item 4): other packages import a package's names from its face.

A face is the package's ``__init__``; it lists its names once, as imports under ``if TYPE_CHECKING:``,
and imports each from its module when first asked for (``exsce_dsl/faces.py``).  Every import in
src counts, also those inside functions and TYPE_CHECKING blocks.  Tests may import a package's
modules (they test them one by one).  ``/work/scripts/faces.py`` (issue 49's note) writes the faces
and routes outsiders through them.
"""

from __future__ import annotations

import ast
import importlib
import json
import subprocess
import sys
from functools import cache
from pathlib import Path

import pytest

from exsce_dsl.faces import face_names

from tests.support.paths import ROOT

PACKAGE = ROOT / "src" / "exsce_dsl"
FACES = ["store", "runs", "oracles", "derive", "transform", "execute", "lang"]


@cache
def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"))


def _names(package: str) -> dict[str, str]:
    return face_names((PACKAGE / package / "__init__.py").read_text(encoding="utf-8"))


def _is_module(dotted: str) -> bool:
    base = ROOT / "src" / Path(*dotted.split("."))
    return base.with_suffix(".py").exists() or (base / "__init__.py").exists()


def _reaches_inside(path: Path, package: str) -> list[str]:
    """Where ``path`` imports a module of ``package`` (or a name from one) instead of its face."""
    inside = f"exsce_dsl.{package}."
    found = []
    for node in ast.walk(_tree(path)):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            modules = [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]
            found += [f"{node.lineno}: {m}" for m in modules if m.startswith(inside) and _is_module(m)]
        elif isinstance(node, ast.Import):
            found += [f"{node.lineno}: {a.name}" for a in node.names if a.name.startswith(inside)]
    return found


def _outsiders(package: str) -> list[Path]:
    return sorted(
        p for p in PACKAGE.rglob("*.py") if p.relative_to(PACKAGE).parts[0].removesuffix(".py") != package
    )


@pytest.mark.parametrize("package", FACES)
def test_other_packages_import_only_the_face(package: str) -> None:
    found = [
        f"{path.relative_to(ROOT)}:{where}"
        for path in _outsiders(package)
        for where in _reaches_inside(path, package)
    ]
    assert not found, f"import these from exsce_dsl.{package} (python /work/scripts/faces.py):\n" + "\n".join(
        found
    )


@pytest.mark.parametrize("package", FACES)
def test_each_name_of_a_face_is_its_module_s(package: str) -> None:
    face = importlib.import_module(f"exsce_dsl.{package}")
    names = _names(package)
    assert names and face.__all__ == list(names)
    for name, home in names.items():
        assert home.startswith(f"exsce_dsl.{package}."), f"{name}: a face re-exports only its own package"
        assert getattr(face, name) is getattr(importlib.import_module(home), name), name


@pytest.mark.parametrize("package", FACES)
def test_no_name_of_a_face_is_a_module_s_name(package: str) -> None:
    """Once ``exsce_dsl.runs.bag_info`` is imported, the package's attribute ``bag_info`` is the module."""
    clashes = [name for name in _names(package) if _is_module(f"exsce_dsl.{package}.{name}")]
    assert not clashes, f"rename (a function named as its module): {clashes}"


@pytest.mark.parametrize("package", FACES)
def test_each_name_of_a_face_is_used_outside(package: str) -> None:
    """By name (``from exsce_dsl.store import open_store``) or off the face as a module
    (``from exsce_dsl import store as face``, ``face.open_store``), in src or tests."""
    used: set[str] = set()
    for path in [*_outsiders(package), *sorted((ROOT / "tests").rglob("*.py"))]:
        tree = _tree(path)
        faces = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module == f"exsce_dsl.{package}":
                used.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module == "exsce_dsl":
                faces |= {alias.asname or alias.name for alias in node.names if alias.name == package}
        used |= {
            node.attr
            for node in ast.walk(tree)
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in faces
        }
    assert set(_names(package)) <= used, f"nobody imports these: {sorted(set(_names(package)) - used)}"


def test_a_name_not_on_the_face_is_an_attribute_error() -> None:
    store = importlib.import_module("exsce_dsl.store")
    with pytest.raises(AttributeError, match="no attribute 'open_stor'"):
        store.open_stor  # noqa: B018


def test_importing_a_face_imports_none_of_its_modules() -> None:
    code = (
        "import importlib, json, sys\n"
        f"for p in {FACES!r}: importlib.import_module('exsce_dsl.' + p)\n"
        "print(json.dumps(sorted(sys.modules)))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = json.loads(done.stdout)
    assert [m for m in loaded if any(m.startswith(f"exsce_dsl.{p}.") for p in FACES)] == []


def test_one_name_imports_its_module_only() -> None:
    code = "import json, sys\nfrom exsce_dsl.store import Store\nprint(json.dumps(sorted(sys.modules)))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = {m for m in json.loads(done.stdout) if m.startswith("exsce_dsl.store.")}
    assert "exsce_dsl.store.base" in loaded and "exsce_dsl.store.remote" not in loaded


def test_the_checker_sees_an_import_inside_a_function(tmp_path: Path) -> None:
    module = tmp_path / "m.py"
    module.write_text("def f():\n    from exsce_dsl.store.open import open_store\n")
    assert _reaches_inside(module, "store") == ["2: exsce_dsl.store.open"]
