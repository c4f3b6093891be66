"""The monitor kit imports numpy and the standard library only: ``exscec generate ros1-monitor`` and
``ros2-monitor`` copy its modules into ROS nodes, where neither exsce nor its other dependencies are
installed.

Two checks: every ``import`` statement of every module (also those inside functions) names numpy or
a standard library module, and each module, copied alone into an empty folder, imports in a fresh
Python whose import system refuses every other top-level package (exsce_dsl included).
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

KIT = Path(__file__).resolve().parents[2] / "src" / "exsce_dsl" / "monitor_kit"
ALLOWED = frozenset(sys.stdlib_module_names) | {"numpy"}
MODULES = sorted(p for p in KIT.glob("*.py") if p.name != "__init__.py")

_REFUSING = textwrap.dedent(
    """
    import importlib.util, sys

    ALLOWED = set(sys.stdlib_module_names) | {"numpy"}
    before = {name.partition(".")[0] for name in sys.modules}

    class Refuse:
        def find_spec(self, name, path=None, target=None):
            if name.partition(".")[0] not in ALLOWED:
                raise ModuleNotFoundError(f"the monitor kit may not import {name!r}", name=name)
            return None

    sys.meta_path.insert(0, Refuse())
    spec = importlib.util.spec_from_file_location(sys.argv[2], sys.argv[1])
    module = importlib.util.module_from_spec(spec)
    sys.modules[sys.argv[2]] = module
    spec.loader.exec_module(module)
    after = {name.partition(".")[0] for name in sys.modules} - before - {sys.argv[2]}
    strangers = sorted(after - ALLOWED)
    if strangers:
        sys.exit(f"imported {strangers}")
    """
)
"""Run as ``python -I -c _REFUSING FILE NAME``: import FILE as module NAME, refusing any top-level
package outside the standard library and numpy, and fail if one got imported all the same."""


def _disallowed_imports(path: Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                found.append(f"{path.name}:{node.lineno}: a relative import (from {'.' * node.level})")
            elif node.module and node.module.partition(".")[0] not in ALLOWED:
                found.append(f"{path.name}:{node.lineno}: from {node.module} import ...")
        elif isinstance(node, ast.Import):
            found += [
                f"{path.name}:{node.lineno}: import {a.name}"
                for a in node.names
                if a.name.partition(".")[0] not in ALLOWED
            ]
    return found


def _import_alone(path: Path, folder: Path) -> subprocess.CompletedProcess[str]:
    """Import a copy of ``path``, alone in ``folder``, in a fresh isolated interpreter."""
    copy = folder / path.name
    shutil.copyfile(path, copy)
    return subprocess.run(
        [sys.executable, "-I", "-c", _REFUSING, str(copy), path.stem],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


def test_the_kit_is_what_the_generators_copy() -> None:
    from exsce_dsl.codegen.ros_monitor import _COPIED

    assert {p.name for p in MODULES} == set(_COPIED)


@pytest.mark.parametrize("path", MODULES, ids=lambda p: p.name)
def test_every_import_is_numpy_or_the_standard_library(path: Path) -> None:
    assert _disallowed_imports(path) == []


@pytest.mark.parametrize("path", MODULES, ids=lambda p: p.name)
def test_a_copy_imports_alone_without_exsce(path: Path, tmp_path: Path) -> None:
    done = _import_alone(path, tmp_path)
    assert done.returncode == 0, done.stderr


def test_both_checks_refuse_a_module_that_imports_yaml(tmp_path: Path) -> None:
    planted = tmp_path / "source" / "monitor_core.py"
    planted.parent.mkdir()
    planted.write_text((KIT / "monitor_core.py").read_text(encoding="utf-8") + "\n\nimport yaml\n")
    assert _disallowed_imports(planted)[-1].endswith("import yaml")
    done = _import_alone(planted, tmp_path)
    assert done.returncode != 0 and "may not import 'yaml'" in done.stderr


def test_both_checks_refuse_a_module_that_imports_exsce(tmp_path: Path) -> None:
    planted = tmp_path / "source" / "monitor_runtime.py"
    planted.parent.mkdir()
    text = (KIT / "monitor_runtime.py").read_text(encoding="utf-8")
    planted.write_text(text + "\n\ndef later():\n    from exsce_dsl.errors import ExsceError\n")
    assert _disallowed_imports(planted)[-1].endswith("from exsce_dsl.errors import ...")
    planted.write_text(text + "\n\nfrom exsce_dsl import errors\n")
    done = _import_alone(planted, tmp_path)
    assert done.returncode != 0 and "may not import 'exsce_dsl'" in done.stderr
