"""A gap is a gap only on a periodic topic, and gaps are said once per kind (issue 47, item 8).

rosbag.js's turtlesim bag: ``/turtle1/cmd_vel`` is sent only while a key is held (bursts at
33 Hz, pauses of 0.5 to 1 s): it gave nine "coverage: gap" warnings per bag.  An event-driven
topic is recognised and its pauses are no gaps (said once); a periodic topic with a real hole,
written here with rosbags, still has its gap, and several are one warning with a count and the
longest.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag

from tests.runs.test_turtlesim_path import SPEC as TURTLE_SPEC
from tests.runs.test_turtlesim_path import TURTLESIM
from tests.support.bag_factory import ODOMETRY, START_NS, Topic, odometry, typestore_for, write_bag
from tests.support.yard_spec import FAR_YARD

SPEC = FAR_YARD + """
scenario holes in yard {
  robots {
    tb: bot namespace "" starts at start
  }
  mission go_far sequential {
    tb does go
  }
}
"""
PERIOD_NS = 50_000_000  # 20 Hz


@pytest.mark.parametrize("name", ["example.bag", "example-lz4.bag"])
def test_event_driven_cmd_vel_has_no_gap_warnings(name: str, tmp_path: Path) -> None:
    spec = tmp_path / "turtles.exsce"
    spec.write_text(TURTLE_SPEC.replace("WINDOW", ""))
    problems = analyse_bag(TURTLESIM / name, load_spec(spec).scenario()).problems
    assert not [p for p in problems if p.startswith("coverage: gap") or "coverage: no data" in p], problems
    (said,) = [p for p in problems if "event-driven" in p]
    assert said.startswith(
        "coverage: /turtle1/cmd_vel is event-driven (10 bursts with pauses of 0.500 to 0.976 s"
    )


def _odometry_with_holes(folder: Path, holes: list[tuple[float, float]]) -> Path:
    """``/odom`` at 20 Hz for 30 s, silent in each of ``holes`` (seconds from its start)."""
    store = typestore_for("ros1")
    messages = []
    for i in range(600):
        at = i * PERIOD_NS / 1e9
        if not any(a < at < b for a, b in holes):
            t = START_NS + i * PERIOD_NS
            messages.append((t, odometry(store, i, t)))
    bag = folder / "holes.bag"
    write_bag(bag, "ros1", [Topic("/odom", ODOMETRY, messages)], store)
    return bag


def _problems(tmp_path: Path, holes: list[tuple[float, float]]) -> list[str]:
    spec = tmp_path / "holes.exsce"
    spec.write_text(SPEC)
    return analyse_bag(_odometry_with_holes(tmp_path, holes), load_spec(spec).scenario()).problems


def test_a_periodic_topic_with_a_real_gap_is_still_told(tmp_path: Path) -> None:
    (said,) = [p for p in _problems(tmp_path, [(10.0, 13.0)]) if p.startswith("coverage")]
    assert said.startswith("coverage: gap: /odom has no message for 3.000 s"), said
    assert "of this kind" not in said


def test_gaps_of_one_kind_are_one_warning_with_a_count_and_the_longest(tmp_path: Path) -> None:
    (said,) = [p for p in _problems(tmp_path, [(5.0, 7.0), (15.0, 18.0)]) if p.startswith("coverage")]
    assert said.startswith("coverage: gap: /odom has no message for 3.000 s"), said
    assert said.endswith("; the longest of 2 of this kind in this run: /odom 2"), said
