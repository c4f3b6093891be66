"""The one bounded reader of the files users give (issue 46): regular files only, at most the
limit, never blocking, only inside the folders of :func:`reading_inside` when it is in force."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.textfiles import max_file_bytes, read_bytes, read_text, reading_inside


def test_a_file_of_the_limit_is_read_and_one_byte_more_is_refused(tmp_path: Path) -> None:
    exact, over = tmp_path / "exact", tmp_path / "over"
    exact.write_bytes(b"x" * 100)
    over.write_bytes(b"x" * 101)
    assert read_bytes(exact, limit=100) == b"x" * 100
    with pytest.raises(ExsceError, match="is larger than 100 bytes, the most a file may be"):
        read_bytes(over, limit=100)


def test_devices_fifos_and_folders_are_refused_at_once(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "fifo")
    start = time.monotonic()
    for path, words in [
        ("/dev/zero", "is not a regular file"),
        (tmp_path / "fifo", "is not a regular file"),
        (tmp_path, "is a folder, not a map file"),
        (tmp_path / "missing", "cannot read"),
    ]:
        with pytest.raises(ExsceError, match=words):
            read_bytes(path, "map file")
    assert time.monotonic() - start < 2


def test_the_limit_comes_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("EXSCE_MAX_FILE_MB", "2")
    assert max_file_bytes() == 2 * 1024 * 1024
    for wrong in ("", "lots", "-1", "0", "nan", "inf"):
        monkeypatch.setenv("EXSCE_MAX_FILE_MB", wrong)
        assert max_file_bytes() == 64 * 1024 * 1024


def test_a_byte_order_mark_is_left_out(tmp_path: Path) -> None:
    (tmp_path / "bom.exsce").write_bytes(b"\xef\xbb\xbfrobot type r {}\n")
    assert read_text(tmp_path / "bom.exsce") == "robot type r {}\n"


def test_reading_inside_refuses_every_file_outside_with_the_same_words(tmp_path: Path) -> None:
    inside, outside = tmp_path / "in", tmp_path / "out"
    inside.mkdir()
    outside.mkdir()
    (inside / "a.yaml").write_text("a: 1\n")
    (outside / "b.yaml").write_text("b: 1\n")
    os.symlink(outside / "b.yaml", inside / "link.yaml")
    with reading_inside(inside):
        assert read_text(inside / "a.yaml") == "a: 1\n"
        told = []
        for path in (outside / "b.yaml", outside / "missing.yaml", inside / "link.yaml", Path("/dev/zero")):
            with pytest.raises(ExsceError) as refused:
                read_text(path)
            told.append(refused.value.message.replace(str(path), "PATH"))
    assert len(set(told)) == 1 and "is outside the workspace" in told[0]
    assert read_text(outside / "b.yaml") == "b: 1\n"  # only within the block
