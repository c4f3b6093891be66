"""The method's topic names are written in one place: its convention, in ``model/conventions.py``.

Every other module takes them from :data:`~exsce_dsl.model.conventions.METHOD_TOPICS` (the
simulator, the code generators, ingestion), so that the method is one convention among Nav2's and
move_base's, with no special path (DESIGN.md §2, ``runs/signals``).
"""

from __future__ import annotations

import re
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[2] / "src"
TABLE = SOURCE / "exsce_dsl" / "model" / "conventions.py"
METHOD_TOPIC = re.compile(
    r"/\{+ns\}+/(robot_pose|nav_vel|distance_travelled|scan|waypoint_dispatcher)\b"
    r"|waypoint_dispatcher/(feedback|result)\b"
    r"|[\"'](robot_pose|nav_vel)[\"']"
)
"""The method's topic names as code writes them: a pattern with ``{ns}``, the dispatcher's
feedback and result, or a quoted name below the namespace."""


def _hits(path: Path) -> list[str]:
    lines = path.read_text(encoding="utf-8").splitlines()
    return [
        f"{path.relative_to(SOURCE)}:{n}: {line.strip()}"
        for n, line in enumerate(lines, 1)
        if METHOD_TOPIC.search(line)
    ]


def test_the_method_topics_are_written_only_in_the_convention_table() -> None:
    found: list[str] = []
    for path in sorted(
        p for p in SOURCE.rglob("*") if p.is_file() and p.suffix in {".py", ".exsce", ".tx", ".j2"}
    ):
        if path != TABLE:
            found += _hits(path)
    assert not found, "take these from model.conventions.METHOD_TOPICS:\n" + "\n".join(found)


def test_the_convention_table_holds_them() -> None:
    """The pattern finds what it looks for: every name of the table matches it."""
    from exsce_dsl.model.conventions import METHOD_TOPICS

    assert all(METHOD_TOPIC.search(f'"{topic}"') for topic in METHOD_TOPICS.values())
    assert len(_hits(TABLE)) >= len(METHOD_TOPICS)
