"""A package's face: the names other packages use, each imported from its module when first asked for.

A face is a package's ``__init__`` that lists its names once, as imports under ``if TYPE_CHECKING:``
(mypy reads them there; the face's ``# mypy: implicit-reexport`` makes them its exports).  At run
time the same lines are read from the face's source, so that ``from exsce_dsl.store import
open_store`` imports ``store/open.py`` and not the whole package::

    if TYPE_CHECKING:
        from exsce_dsl.store.open import open_store
    else:
        __getattr__, __dir__ = lazy_face(__name__, __file__)

``tests/project/test_package_faces.py`` holds that other packages import only through faces.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any


def face_blocks(source: str) -> list[dict[str, str]]:
    """Each ``if TYPE_CHECKING:`` block of a face's source (a face may group its names so): the
    names it imports, and the module each is imported from."""
    import ast  # only when a face is first asked for a name

    blocks = []
    for node in ast.parse(source).body:
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            blocks.append(
                {
                    alias.asname or alias.name: statement.module
                    for statement in node.body
                    if isinstance(statement, ast.ImportFrom) and statement.module
                    for alias in statement.names
                }
            )
    return blocks


def face_names(source: str) -> dict[str, str]:
    """Each name a face's source imports under ``if TYPE_CHECKING:``, and the module it is imported from."""
    return {name: module for block in face_blocks(source) for name, module in block.items()}


def lazy_face(package: str, file: str) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of the face ``file`` of ``package``."""

    @cache
    def homes() -> dict[str, str]:
        return face_names(Path(file).read_text(encoding="utf-8"))

    def getattr_(name: str) -> Any:
        if name == "__all__":
            return list(homes())
        home = homes().get(name)
        if home is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(home), name)
        setattr(sys.modules[package], name, value)
        return value

    def dir_() -> list[str]:
        return sorted({*vars(sys.modules[package]), *homes()})

    return getattr_, dir_
