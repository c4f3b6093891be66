"""The suite's own settings: the files it starts first are there, and it keeps its cache apart."""

from __future__ import annotations

import os
from pathlib import Path

from tests.conftest import LONGEST_FIRST

TESTS = Path(__file__).resolve().parents[1]


def test_the_files_started_first_exist_once_each() -> None:
    assert len(set(LONGEST_FIRST)) == len(LONGEST_FIRST)
    missing = [name for name in LONGEST_FIRST if not (TESTS / name).is_file()]
    assert not missing, f"renamed or removed: update LONGEST_FIRST in tests/conftest.py: {missing}"


def test_the_run_keeps_its_cache_out_of_the_users_home() -> None:
    folder = Path(os.environ["EXSCE_CACHE"])
    users = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "exsce"
    assert folder.is_dir() and not folder.is_relative_to(users)
