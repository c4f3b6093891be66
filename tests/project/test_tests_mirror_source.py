"""Tests mirror the source tree (issue 49, item 5): a test folder below ``tests/runs/`` or
``tests/lang/`` is named after the subpackage of ``src/exsce_dsl/runs/`` or ``lang/`` whose code
its files test, so that a reader finds a module's tests beside where its path says, and a
subpackage that moves or is renamed takes its tests along (this test fails until it does).

Mirrored so far: ``runs`` and ``lang``. Not yet: the flat folders of the other packages
(``store``, ``oracles``, ``execute``, ``explore``, ``derive``...), whose tests still sit in one
folder per package.  Add a package to :data:`MIRRORED` when its tests are moved."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TESTS = ROOT / "tests"
SOURCE = ROOT / "src" / "exsce_dsl"

MIRRORED = ("runs", "lang")
"""Packages whose test folders mirror their subpackages."""


def _test_folders(package: str) -> list[Path]:
    """The folders below ``tests/<package>/`` that hold test files (caches aside)."""
    top = TESTS / package
    return sorted(
        folder
        for folder in top.rglob("*")
        if folder.is_dir() and folder.name != "__pycache__" and any(folder.glob("test_*.py"))
    )


def test_each_test_folder_of_a_mirrored_package_has_its_source_folder() -> None:
    missing = [
        str(folder.relative_to(TESTS))
        for package in MIRRORED
        for folder in _test_folders(package)
        if not (SOURCE / folder.relative_to(TESTS)).is_dir()
    ]
    assert not missing, f"test folders without a source package of that path: {missing}"


def test_runs_four_steps_have_their_test_folders() -> None:
    """The four steps of a bag's walk (bags, signals, segments, metrics) each have their tests."""
    steps = ("bags", "signals", "segments", "metrics")
    assert all((SOURCE / "runs" / step / "__init__.py").is_file() for step in steps)
    without = [step for step in steps if not any((TESTS / "runs" / step).glob("test_*.py"))]
    assert not without, f"steps of runs/ without tests in tests/runs/<step>/: {without}"


def test_lang_subpackages_have_their_test_folders() -> None:
    """The language's builders, formatter, YAML import/export and editor support each have their
    tests in ``tests/lang/<subpackage>/``."""
    parts = ("builders", "format", "yaml", "editor")
    assert all((SOURCE / "lang" / part / "__init__.py").is_file() for part in parts)
    without = [part for part in parts if not any((TESTS / "lang" / part).glob("test_*.py"))]
    assert not without, f"subpackages of lang/ without tests in tests/lang/<subpackage>/: {without}"
