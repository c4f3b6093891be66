"""Modules stay small enough to read at once (issue 32, item 8): none in ``runs/`` over 500 lines."""

from __future__ import annotations

from pathlib import Path

import pytest

RUNS = Path(__file__).resolve().parents[2] / "src" / "exsce_dsl" / "runs"
MOST_LINES = 500


@pytest.mark.parametrize("path", sorted(RUNS.rglob("*.py")), ids=lambda p: str(p.relative_to(RUNS)))
def test_no_module_in_runs_is_over_500_lines(path: Path) -> None:
    lines = len(path.read_text(encoding="utf-8").splitlines())
    assert lines <= MOST_LINES, f"{path.relative_to(RUNS)} has {lines} lines: split it along its ideas"
