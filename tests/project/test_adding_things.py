"""docs/development.md's "Adding things" names the files where each kind of extension goes: every
file it names exists, so the section stays true as code moves (issue 49, item 5)."""

from __future__ import annotations

import re

from tests.support.paths import ROOT

SECTION = re.compile(r"^## Adding things\n(.*?)^## ", re.MULTILINE | re.DOTALL)
PATH = re.compile(r"`((?:src|tests|docs|editors|grammar)/[\w./-]+)`")


def test_every_file_the_adding_things_section_names_exists() -> None:
    page = (ROOT / "docs" / "development.md").read_text(encoding="utf-8")
    found = SECTION.search(page)
    assert found is not None, "docs/development.md lost its 'Adding things' section"
    named = PATH.findall(found.group(1))
    assert len(named) >= 12, named  # each kind names its record's file and a test
    missing = [path for path in named if not (ROOT / path).exists()]
    assert missing == [], f"docs/development.md names files that do not exist: {missing}"
