"""A topic a metric reads by name is that topic of the bag (issue 49, item 1: the serving layer
went).  Ingestion served every convention's signals under the method's topic names, so a metric
over ``/{ns}/nav_vel`` had a value on a Nav2 robot whose bag holds no ``nav_vel``; now it is
missing with the usual note, which says which signal reads the robot's velocity wherever its type
says it is, and the same metric over ``robot velocity`` has its value, named by the bag's topic.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.execute.recording import recorded_topics
from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import AnalysedRun

from tests.sim.test_sim_conventions import YARD
from tests.support.yard_runs import yard_runs

METRICS = """
metric turning_by_name for each robot {
  unit rad/s
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  value max(abs(vel.angular.z))
}

metric turning for each robot {
  unit rad/s
  reads vel: robot velocity
  value max(abs(vel.angular.z))
}
"""
HINT = "(to read it wherever the robot's type says it is, read the signal `robot velocity`)"


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, AnalysedRun]]:
    return yard_runs(tmp_path_factory.mktemp("by_name"), METRICS, ("method", "nav2"))


def _whole(run: AnalysedRun, metric: str, robot: str) -> tuple[float, tuple[str, ...]] | None:
    found = [(v.value, v.topics) for v in run.run.metrics if v.metric == metric and v.robot == robot]
    return found[0] if found else None


def _topics(bag: Path) -> set[str]:
    with AnyReader([bag]) as reader:
        return {c.topic for c in reader.connections}


def test_a_method_topic_read_by_name_on_a_nav2_robot_is_missing_and_says_which_signal(runs) -> None:
    bag, run = runs["nav2"]
    assert "/r2/nav_vel" not in _topics(bag) and "/r2/cmd_vel" in _topics(bag)
    for robot, prefix in (("r1", ""), ("r2", "/r2")):
        assert _whole(run, "turning_by_name", robot) is None
        said = f"topic {prefix}/nav_vel is missing: turning_by_name of '{robot}' is missing {HINT}"
        assert said in run.problems, run.problems
        value, topics = _whole(run, "turning", robot) or (None, ())
        assert value is not None and value > 0 and topics == (f"{prefix}/cmd_vel",)


def test_on_the_methods_bag_both_read_its_nav_vel(runs) -> None:
    bag, run = runs["method"]
    assert "/r2/nav_vel" in _topics(bag)
    for robot, prefix in (("r1", ""), ("r2", "/r2")):
        assert _whole(run, "turning_by_name", robot) == _whole(run, "turning", robot)
        assert (_whole(run, "turning", robot) or (0, ()))[1] == (f"{prefix}/nav_vel",)
    assert not [p for p in run.problems if "turning" in p]


def test_a_nav2_run_records_the_topic_a_metric_reads_by_name(tmp_path: Path) -> None:
    spec = tmp_path / "yard.exsce"
    spec.write_text(YARD + METRICS, encoding="utf-8")
    recorded = recorded_topics(load_spec(spec).scenario(), "nav2")
    assert {"/nav_vel", "/r2/nav_vel", "/cmd_vel", "/r2/cmd_vel"} <= set(recorded)
