"""Every example of every ``exscec ... --help`` runs as written (tests/support/help_examples.py
reads them and holds the walk): here, that the examples are read right and that every command with
examples has its place in a chapter; the chapters run in tests/cli/test_help_examples_*.py."""

from __future__ import annotations

import re
from pathlib import Path

from exsce_dsl.cli.main import main

from tests.support.help_examples import CHAPTERS, WALK, collected, command_tree, examples_in


def test_the_help_example_parser_joins_continuations_and_stops_at_the_block_end() -> None:
    text = """Do things.

    \b
    Example:
      exscec a --x \\
          --y 1
      exscec b  # exits 1

    Example: not a header, in prose.
    \b
    Config:
      exscec not-an-example
    """
    assert examples_in(text) == ["exscec a --x --y 1", "exscec b  # exits 1"]


def test_every_command_with_examples_has_its_place_in_the_walk() -> None:
    having = {e.command for e in collected()}
    assert having - set(WALK) == set(), "give these commands' examples a place in a chapter (CHAPTERS)"
    assert set(WALK) - having == set(), "these commands in WALK have no examples (any more)"
    assert len(set(WALK)) == len(WALK), "a command is in two chapters"
    assert all(CHAPTERS.values())
    for path, command in command_tree(main):
        if not command.hidden:
            assert examples_in(command.help or ""), f"exscec {' '.join(path)} --help has no example"


def test_every_chapter_runs_in_a_test_file_of_its_own() -> None:
    for chapter in CHAPTERS:
        test_file = Path(__file__).with_name(f"test_help_examples_{chapter}.py")
        assert f'walk("{chapter}", tmp_path)' in test_file.read_text(), test_file
    assert {p.name for p in Path(__file__).parent.glob("test_help_examples_*.py")} == {
        f"test_help_examples_{chapter}.py" for chapter in CHAPTERS
    }


def test_every_example_line_reads_as_typed() -> None:
    """A ``\\`` at a line's end in a (not raw) docstring joins the lines in Python itself: the
    help then showed one long line with the next line's indentation inside it."""
    for example in collected():
        assert not re.search(r"\S {3,}[^\s#]", example.line), str(example)  # not before a #: comments align
