"""A distribution installed in a temporary folder, registering entry points: a real plug-in
package, found by ``importlib.metadata`` as any installed one is."""

from __future__ import annotations

import sys
import textwrap
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from exsce_dsl.plugins import Registry


def installed_plugins(
    folder: Path,
    monkeypatch: pytest.MonkeyPatch,
    registry: Registry[Any],
    module: str,
    source: str,
    entry_points: str,
) -> Iterator[None]:
    """For a fixture to ``yield from``: ``module`` (its ``source``) and its ``*.dist-info``
    (``entry_points``, the text of an ``entry_points.txt``) in ``folder``, first on
    ``sys.path``; ``registry`` reads the plug-ins afresh, and again after the test."""
    (folder / f"{module}.py").write_text(source)
    dist_info = folder / f"{module}-1.0.dist-info"
    dist_info.mkdir()
    name = module.replace("_", "-")
    (dist_info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 1.0\n")
    (dist_info / "entry_points.txt").write_text(textwrap.dedent(entry_points))
    monkeypatch.syspath_prepend(str(folder))
    registry.forget()
    yield
    registry.forget()
    sys.modules.pop(module, None)
