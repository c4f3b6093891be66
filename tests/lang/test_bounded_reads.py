"""Issue 46: the files a specification names (its imports, a map's YAML and image) are read with
bounds: regular files only, at most ``$EXSCE_MAX_FILE_MB``, never waiting on a FIFO; and a
specification that starts with a UTF-8 byte order mark is read as if it had none."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from exsce_dsl.lang import analyse

from tests.support.cli import run_exscec

ENVIRONMENT = """environment e {{
  map m from package "p" path "maps/" file "{map}"
  area a {{
    pose p1 at (0.0, 0.0) facing 0
  }}
}}
"""


def _map_yaml(folder: Path, image: str) -> Path:
    found = folder / "m.yaml"
    found.write_text(f"image: {image}\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n", encoding="utf-8")
    return found


def test_map_naming_dev_zero_is_a_located_error(tmp_path: Path) -> None:
    _map_yaml(tmp_path, "/dev/zero")
    (tmp_path / "env.exsce").write_text(ENVIRONMENT.format(map="m.yaml"), encoding="utf-8")
    done = run_exscec("check", "env.exsce", cwd=tmp_path, timeout=60)
    assert done.returncode == 2, done.stderr
    assert "env.exsce:2:3: error: /dev/zero is not a regular file (a map image is read from a file)" in (
        done.stderr
    )


def test_map_file_naming_dev_zero_is_a_located_error(tmp_path: Path) -> None:
    (tmp_path / "env.exsce").write_text(ENVIRONMENT.format(map="/dev/zero"), encoding="utf-8")
    analysis = analyse(tmp_path / "env.exsce")
    (error,) = analysis.errors
    assert error.message == "/dev/zero is not a regular file (a map file is read from a file)"
    assert error.location is not None and (error.location.line, error.location.column) == (2, 3)


def test_environment_fifo_does_not_block(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "fifo.yaml")  # no one ever writes it: reading it would wait forever
    (tmp_path / "env.exsce").write_text(ENVIRONMENT.format(map="fifo.yaml"), encoding="utf-8")
    done = run_exscec("check", "env.exsce", cwd=tmp_path, timeout=30)
    assert done.returncode == 2, done.stderr
    assert "env.exsce:2:3: error: fifo.yaml is not a regular file" in done.stderr


def test_map_image_that_is_a_fifo_does_not_block(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "m.pgm")
    _map_yaml(tmp_path, "m.pgm")
    (tmp_path / "env.exsce").write_text(ENVIRONMENT.format(map="m.yaml"), encoding="utf-8")
    done = run_exscec("check", "env.exsce", cwd=tmp_path, timeout=30)
    assert done.returncode == 2 and "env.exsce:2:3: error: " in done.stderr and "m.pgm is not a regular file" in (
        done.stderr
    )


def test_import_too_large_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("EXSCE_MAX_FILE_MB", "0.001")  # 1 KiB
    big = "".join(f"robot type r{i} {{\n}}\n" for i in range(200))
    assert len(big) > 1100
    (tmp_path / "big.exsce").write_text(big, encoding="utf-8")
    (tmp_path / "small.exsce").write_text("robot type s {\n}\n", encoding="utf-8")
    (tmp_path / "main.exsce").write_text('import "small.exsce"\nimport "big.exsce"\n', encoding="utf-8")
    analysis = analyse(tmp_path / "main.exsce")
    (error,) = analysis.errors
    assert error.location is not None and (error.location.line, error.location.column) == (2, 1)
    assert error.message.startswith("imported file: ") and "big.exsce is larger than 1048 bytes" in error.message
    assert "EXSCE_MAX_FILE_MB" in error.message
    monkeypatch.setenv("EXSCE_MAX_FILE_MB", "1")
    assert analyse(tmp_path / "main.exsce").errors == []


def test_map_image_too_large_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("EXSCE_MAX_FILE_MB", "0.001")
    (tmp_path / "m.pgm").write_bytes(b"P5\n100 100\n255\n" + bytes(10000))
    _map_yaml(tmp_path, "m.pgm")
    (tmp_path / "env.exsce").write_text(ENVIRONMENT.format(map="m.yaml"), encoding="utf-8")
    (error,) = analyse(tmp_path / "env.exsce").errors
    assert "m.pgm is larger than 1048 bytes" in error.message
    assert error.location is not None and error.location.line == 2


def test_a_map_yaml_error_quotes_nothing_of_the_file(tmp_path: Path) -> None:
    secret = tmp_path / "secret.yaml"
    secret.write_text("password: [hunter2-secret\n", encoding="utf-8")  # not valid YAML
    (tmp_path / "env.exsce").write_text(ENVIRONMENT.format(map="secret.yaml"), encoding="utf-8")
    (error,) = analyse(tmp_path / "env.exsce").errors
    assert "is not valid YAML" in error.message and "hunter2" not in error.message


def test_spec_with_bom_checks(tmp_path: Path) -> None:
    text = "task t { visit nowhere }\n"
    (tmp_path / "plain.exsce").write_text(text, encoding="utf-8")
    (tmp_path / "bom.exsce").write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    (plain,) = analyse(tmp_path / "plain.exsce").errors
    (bom,) = analyse(tmp_path / "bom.exsce").errors
    assert "unknown pose 'nowhere'" in bom.message
    assert plain.location is not None and bom.location is not None
    assert (bom.location.line, bom.location.column, bom.location.end_column) == (
        plain.location.line,
        plain.location.column,
        plain.location.end_column,
    ) == (1, 16, 23)
    (tmp_path / "bom_ok.exsce").write_bytes(b"\xef\xbb\xbfrobot type r {\n}\n")
    done = run_exscec("check", "bom_ok.exsce", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
