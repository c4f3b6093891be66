"""The ``--help`` examples of explore: campaigns, simulated and on a live graph: each runs as written, in order, on the state the chapter's
earlier examples made (tests/support/help_examples.py)."""

from __future__ import annotations

from pathlib import Path

from tests.support.help_examples import walk


def test_every_help_example_of_the_explore_chapter_runs_as_written(tmp_path: Path) -> None:
    walk("explore", tmp_path)
