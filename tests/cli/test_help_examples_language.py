"""The ``--help`` examples of the language: check, compile, export and import, fmt, generate: each runs as written, in order, on the state the chapter's
earlier examples made (tests/support/help_examples.py)."""

from __future__ import annotations

from pathlib import Path

from tests.support.help_examples import walk


def test_every_help_example_of_the_language_chapter_runs_as_written(tmp_path: Path) -> None:
    walk("language", tmp_path)
