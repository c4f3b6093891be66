"""A robot's goals as a signal (issue 49, item 1): ``reads goals: robot goals`` reads its navigation
goals from whatever recorded them, as its path segments do, so that the standard library's
mission_duration, task_duration and waypoints_visited name none of the method's topics.

The reference for what succeeded is the bag's own goal statuses, read with rosbags (each goal id
that reached SUCCEEDED: Nav2's action status 4, actionlib's 3), not exsce's segmentation.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import analyse
from exsce_dsl.model.runs import MetricScope
from exsce_dsl.runs.analyse import AnalysedRun
from exsce_dsl.sim.executor import Fault

from tests.support.yard_runs import yard_runs

USER_METRICS = """
metric goal_time for each robot per segment {
  unit s
  reads g: robot goals
  value elapsed
}

metric goals_done for each robot {
  reads g: robot goals
  value succeeded
}

metric goals_span for mission {
  unit s
  reads g: robot goals
  value elapsed
}
"""
SKIPPED = (Fault.parse("skip-waypoint:r2:2"),)  # r2's second goal is aborted
STATUS = {"nav2": ("navigate_to_pose/_action/status", 4), "move_base": ("move_base/status", 3)}
"""Where each stack says how its goals ended, and its SUCCEEDED."""
PREFIXES = {"r1": "", "r2": "/r2"}


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, AnalysedRun]]:
    return yard_runs(tmp_path_factory.mktemp("goals"), USER_METRICS, ("method", "nav2", "move_base"), SKIPPED)


def _values(
    run: AnalysedRun, metric: str
) -> dict[tuple[str | None, int | None], tuple[float, tuple[str, ...]]]:
    """(robot, waypoint) → value and topics of ``metric`` (waypoint None: the whole run)."""
    return {
        (v.robot or (v.action.robot if v.action else None), v.action.waypoint if v.action else None): (
            v.value,
            v.topics,
        )
        for v in run.run.metrics
        if v.metric == metric and v.safety_metric is None
    }


def _succeeded(bag: Path, topic: str, succeeded: int) -> int:
    """How many distinct goals the status topic says reached SUCCEEDED (read with rosbags)."""
    done: set[bytes] = set()
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        for connection, _, raw in reader.messages(connections=connections):
            message = reader.deserialize(raw, connection.msgtype)
            for status in message.status_list:
                goal = status.goal_info.goal_id.uuid if hasattr(status, "goal_info") else status.goal_id.id
                if status.status == succeeded:
                    done.add(bytes(goal) if not isinstance(goal, str) else goal.encode())
    return len(done)


@pytest.mark.parametrize("convention", ["method", "nav2", "move_base"])
def test_a_user_metric_over_the_goals_is_the_standard_librarys(runs, convention: str) -> None:
    _, run = runs[convention]
    assert _values(run, "goal_time") == _values(run, "task_duration")
    assert _values(run, "goals_done") == _values(run, "waypoints_visited")
    assert _values(run, "goals_span") == _values(run, "mission_duration")
    assert {k: v for k, (v, _) in _values(run, "goals_done").items()} == {
        ("r1", None): 2.0,
        ("r2", None): 1.0,
    }


@pytest.mark.parametrize("convention", ["nav2", "move_base"])
def test_goals_that_succeeded_are_the_stacks_own_count(runs, convention: str) -> None:
    bag, run = runs[convention]
    topic, succeeded = STATUS[convention]
    for robot, prefix in PREFIXES.items():
        value, topics = _values(run, "goals_done")[(robot, None)]
        assert value == _succeeded(bag, f"{prefix}/{topic}", succeeded)
        assert f"{prefix}/{topic}" in topics  # named as the bag has them, not as the method's


def test_the_dispatchers_goals_are_named_by_its_feedback_and_its_result(runs) -> None:
    _, run = runs["method"]
    for robot, prefix in PREFIXES.items():
        assert _values(run, "goal_time")[(robot, None)][1] == (f"{prefix}/waypoint_dispatcher/feedback",)
        assert _values(run, "goals_done")[(robot, None)][1] == (f"{prefix}/waypoint_dispatcher/result",)
    assert all(
        v.scope is not MetricScope.SEGMENT or v.value > 0 for v in run.run.metrics if v.metric == "goal_time"
    )


HEADER = "metric m for each robot {\n  reads g: robot goals\n"


@pytest.mark.parametrize(
    ("body", "column", "message"),
    [
        ("  value max(g.x)\n", 13, "the robot's goals are read as windows: use 'elapsed' or 'succeeded'"),
        ("  value count where g.status == 4\n", 21, "the robot's goals are read as windows"),
    ],
)
def test_a_field_of_the_goals_is_refused_where_it_is_written(
    tmp_path: Path, body: str, column: int, message: str
):
    spec = tmp_path / "m.exsce"
    spec.write_text(HEADER + body + "}\n")
    (error,) = analyse(spec).errors
    assert (error.location.line, error.location.column) == (3, column), error
    assert message in error.message


def test_elapsed_without_the_goals_says_to_read_them(tmp_path: Path) -> None:
    spec = tmp_path / "m.exsce"
    spec.write_text(
        'metric m for each robot {\n  unit s\n  reads v: std_msgs/msg/Float64 on "/{ns}/v"\n  value elapsed\n}\n'
    )
    (error,) = analyse(spec).errors
    assert (error.location.line, error.location.column) == (4, 9), error
    assert "'elapsed' measures the robot's goals: read them (reads goals: robot goals)" in error.message


def test_a_mission_metric_reads_every_robots_goals(tmp_path: Path) -> None:
    """Other signals are read of one robot or a pair; a mission's windows span every robot's goals."""
    spec = tmp_path / "m.exsce"
    spec.write_text("metric span for mission {\n  unit s\n  reads g: robot goals\n  value elapsed\n}\n")
    assert not analyse(spec).errors
    spec.write_text("metric span for mission {\n  unit s\n  reads p: robot pose\n  value elapsed\n}\n")
    first, *_ = analyse(spec).errors
    assert (first.location.line, first.location.column) == (3, 3), first
    assert "the robot's pose is read for each robot or each pair of robots" in first.message
