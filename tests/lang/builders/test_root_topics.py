"""A metric of each robot reads each robot's own topics, ``"/{ns}/..."``; a topic without ``{ns}``
is the same for every robot, which only a robot at the root (``namespace ""``) may read as its
own (issue 32: a root robot's ground truth on ``groundtruth``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.lang import analyse

from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"
METRIC = """\
metric ground_x for each robot {{
  unit m
  reads g: nav_msgs/msg/Odometry on "{topic}"
  value mean(g.pose.pose.position.x)
}}
"""
SPEC = f"""\
import "{BUILDING}/environment.exsce"
import "{BUILDING}/robots.exsce"
import "{BUILDING}/tasks/deliveries.exsce"
import "metric.exsce"

scenario s in brsu_building_c_with_doors {{
  robots {{
    tiago1: tiago ROBOT1 starts at classroom_c025-w001
    ROBOT2
  }}
  mission m parallel {{
    tiago1 does delivery_a
  }}
}}
"""


def errors_of(folder: Path, topic: str, robot1: str, robot2: str = "") -> list[tuple[str, int, int]]:
    (folder / "metric.exsce").write_text(METRIC.format(topic=topic))
    (folder / "s.exsce").write_text(SPEC.replace("ROBOT1", robot1).replace("ROBOT2", robot2))
    found = analyse(folder / "s.exsce").errors
    return [(e.message, e.location.line, e.location.column) for e in found if e.location is not None]


@pytest.mark.parametrize("topic", ["groundtruth", "/groundtruth", "/{ns}/groundtruth", "{ns}/groundtruth"])
def test_a_robot_at_the_root_may_read_a_root_topic(tmp_path: Path, topic: str) -> None:
    assert errors_of(tmp_path, topic, 'namespace ""') == []


def test_a_namespaced_robot_may_not_read_a_topic_without_its_namespace(tmp_path: Path) -> None:
    (found,) = errors_of(tmp_path, "/groundtruth", 'namespace "tiago1"')
    message, line, column = found
    assert (line, column) == (3, 3)  # the read, in the metric's file
    assert message.startswith("a topic of each robot needs '{ns}' in its name: '/groundtruth'")
    assert "robot 'tiago1' of scenario 's' is in namespace 'tiago1'" in message


def test_one_namespaced_robot_beside_one_at_the_root_is_enough_to_refuse(tmp_path: Path) -> None:
    second = "tiago2: tiago starts at classroom_c025-w002"  # namespace: its id
    (found,) = errors_of(tmp_path, "groundtruth", 'namespace ""', second)
    assert "robot 'tiago2' of scenario 's' is in namespace 'tiago2'" in found[0]
