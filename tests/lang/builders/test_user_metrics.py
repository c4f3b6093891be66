"""Metrics declared in the language: checked at their line and column, computed at ingest by
generated monitors, judged by oracles, printed back by the formatter.

The example declares two metrics of its own (examples/brsu_building_c/metrics.exsce):
``fast_driving_time`` (seconds faster than 0.8 m/s) and ``mean_turn_rate`` (mean
absolute angular velocity).  Their values at ingest are checked against values
computed here by hand, message by message, from the bag as rosbags reads it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.errors import SpecError
from exsce_dsl.lang import analyse, builtin_metrics, load_spec, standard_metrics
from exsce_dsl.lang.format.metrics import metric_lines
from exsce_dsl.model.metrics import Combine, ComputedFor, Dimension, MetricInfo
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"


@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(BUILDING / "scenario_c.exsce").scenario()


@pytest.fixture(scope="module")
def overspeed_run(scenario_c, tmp_path_factory):
    out = tmp_path_factory.mktemp("overspeed")
    run = next(iter(simulate(scenario_c, out, runs=1, seed=11, faults=(Fault.parse("overspeed:tiago1"),))))
    return run.bag, analyse_bag(run.bag, scenario_c)


def _by_hand(bag: Path, topic: str) -> tuple[np.ndarray, list[float], list[float]]:
    """Receive times, linear speeds and angular z of every message on ``topic``, one by one."""
    times, speeds, turns = [], [], []
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        for connection, timestamp, raw in reader.messages(connections=connections):
            msg = reader.deserialize(raw, connection.msgtype)
            times.append(timestamp / 1e9)
            speeds.append(math.sqrt(msg.linear.x**2 + msg.linear.y**2))
            turns.append(abs(msg.angular.z))
    return np.array(times), speeds, turns


def _robot_window(analysed, robot: str) -> tuple[float, float]:
    actions = [a for task in analysed.run.tasks if task.robot == robot for a in task.actions]
    return min(a.start for a in actions).timestamp(), max(a.end for a in actions).timestamp()


def _value(analysed, metric: str, robot: str) -> float:
    (found,) = [v for v in analysed.run.metrics if v.metric == metric and v.robot == robot and v.action is None]
    return found.value


def test_the_user_metrics_at_ingest_equal_values_computed_by_hand(overspeed_run):
    bag, analysed = overspeed_run
    for robot in ("tiago1", "tiago2"):
        start, end = _robot_window(analysed, robot)
        t, speeds, turns = _by_hand(bag, f"/{robot}/nav_vel")
        inside = [i for i in range(len(t)) if start <= t[i] <= end]
        period = float(np.median(np.diff(t[inside])))
        fast = 0.0
        for k, i in enumerate(inside):  # a message holds until the next one (at most two periods)
            held = t[inside[k + 1]] - t[i] if k + 1 < len(inside) else period
            if speeds[i] > 0.8:
                fast += min(held, 2 * period)
        turn = sum(turns[i] for i in inside) / len(inside)
        assert _value(analysed, "fast_driving_time", robot) == pytest.approx(fast, rel=1e-9, abs=1e-9)
        assert _value(analysed, "mean_turn_rate", robot) == pytest.approx(turn, rel=1e-9)
    assert _value(analysed, "fast_driving_time", "tiago1") > 10  # the fault drives at ~1.3 m/s
    assert _value(analysed, "fast_driving_time", "tiago2") == 0.0


def test_a_user_metric_per_segment_has_a_value_for_every_action(overspeed_run):
    _, analysed = overspeed_run
    actions = {a.id for task in analysed.run.tasks for a in task.actions}
    per_segment = {v.action for v in analysed.run.metrics if v.metric == "fast_driving_time" and v.action}
    assert per_segment == actions
    assert not any(v.action for v in analysed.run.metrics if v.metric == "mean_turn_rate")


SPEC = """\
import "{building}/environment.exsce"
import "{building}/robots.exsce"
import "{building}/tasks/deliveries.exsce"
import "{building}/metrics.exsce"

scenario calm in brsu_building_c_with_doors {{
  robots {{
    tiago1: tiago starts at classroom_c025-w001
  }}
  mission calm_mission parallel {{
    tiago1 does delivery_a
  }}
}}

acceptance for calm {{
  scenario "drives calmly" {{
    when calm_mission runs
    then each robot fast_driving_time stays below 2 s
     and each robot mean_turn_rate stays below 0.5 rad/s
     and each robot fast_driving_time stays below 1 s during delivery_a
  }}
}}
"""


def test_oracles_on_user_metrics_pass_a_calm_run_and_fail_an_overspeed_one(tmp_path):
    (tmp_path / "spec.exsce").write_text(SPEC.format(building=BUILDING))
    for name, faults in (("clean", []), ("fast", ["--fault", "overspeed:tiago1"])):
        done = exscec_here("simulate", "spec.exsce", "-o", name, "--seed", "2", *faults, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
    bags = {name: next((tmp_path / name).glob("*.bag")) for name in ("clean", "fast")}
    ingested = exscec_here("ingest", *map(str, bags.values()), "--scenario", "spec.exsce", cwd=tmp_path)
    assert ingested.returncode == 0, ingested.stderr
    built = exscec_here("baseline", "spec.exsce", cwd=tmp_path)
    assert built.returncode == 0, built.stderr
    judged = exscec_here("verify", *map(str, bags.values()), "--scenario", "spec.exsce", "--json", cwd=tmp_path)
    assert judged.returncode == 1, judged.stderr
    verdicts = json.loads(judged.stdout)
    listed = json.loads(exscec_here("runs", "--format", "json", cwd=tmp_path).stdout)["results"]["bindings"]
    case = {row["run"]["value"]: Path(row["bag"]["value"]).parent.name for row in listed}
    case |= {row["run"]["value"]: name for row in listed for name, bag in bags.items()
             if Path(row["bag"]["value"]).name == bag.name}
    table = {(case[v["run"]], v["oracle"]): v["verdict"] for v in verdicts}
    assert table == {
        ("clean", "tiago1-fast_driving_time"): "passed",
        ("clean", "tiago1-fast_driving_time-during-delivery_a"): "passed",
        ("clean", "tiago1-mean_turn_rate"): "passed",
        ("fast", "tiago1-fast_driving_time"): "failed",
        ("fast", "tiago1-fast_driving_time-during-delivery_a"): "failed",
        ("fast", "tiago1-mean_turn_rate"): "passed",
    }
    observed = {(case[v["run"]], v["oracle"]): v["observed"] for v in verdicts}
    assert observed[("fast", "tiago1-fast_driving_time")] > 2


# A line-number matrix: each planted mistake is reported at its line and column.
_HEADER = 'metric m for each robot {\n  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"\n'
ERRORS = [
    ("value mean(vel.linar.x)", 3, 14, "has no field 'linar'; did you mean 'linear'?"),
    ("value mean(vel.linear)", 3, 14, "vel.linear is a message (x, y, z), not a number"),
    ("value max(vel.linear.x > 1)", 3, 9, "is over numbers, but this is a condition per message"),
    ("value vel.linear.x", 3, 9, "one number per window, but this is a number per message"),
    ("value max(vel.linear.x) - vel.linear.y", 3, 29, "mixes one number per window with values per message"),
    ("value max(mean(vel.linear.x))", 3, 9, "aggregates values per message over time"),
    ("value mean(speed.linear.x)", 3, 14, "unknown topic 'speed'"),
    ("value first(vel.linear.x where vel.linear.x and 1)", 3, 51, "'and' joins conditions"),
    ("value duration where vel.linear.x", 3, 9, "needs a condition per message"),
    ("value succeeded", 3, 9, "counts the robot's goals that succeeded: read them (reads goals: robot goals)"),
    ("value abs(1, 2)", 3, 9, "abs(...) takes one value"),
    ("value max(derivate(vel.linear.x))", 3, 13, "unknown function 'derivate'; did you mean 'derivative'? (the "
     "functions: min, max, mean, sum, first, last, integral, change, path_length, norm, abs, sqrt, speed, "
     "derivative)"),
    ("value max(speed(vel.linear.x))", 3, 13, "speed(...) takes two or three coordinates (x, y[, z]), not 1"),
    ("value max(derivative(vel.linear.x, vel.linear.y))", 3, 13, "derivative(...) takes one value, not 2"),
    ("value max(derivative(2))", 3, 13, "derivative(...) is over a number per message, in time, but this is a "
     "constant"),
    ("value derivative(max(vel.linear.x))", 3, 9, "derivative(...) is over a number per message, in time, but "
     "this is one number per window"),
    ("value 2 * max(norml(vel.linear.x))", 3, 17, "unknown function 'norml'; did you mean 'norm'?"),
    ("value count(vel.linear.x > 1)", 3, 9, "'count' is written without parentheses: count where <condition>"),
]


@pytest.mark.parametrize(("value", "line", "column", "message"), ERRORS)
def test_type_errors_are_reported_at_their_line_and_column(tmp_path, value, line, column, message):
    spec = tmp_path / "m.exsce"
    spec.write_text(_HEADER + f"  {value}\n}}\n")
    errors = analyse(spec).errors
    assert len(errors) == 1, errors
    (error,) = errors
    assert (error.location.line, error.location.column) == (line, column), error
    assert message in error.message


DECLARATION_ERRORS = [
    ('metric max_velocity for each robot {\n  reads v: std_msgs/Float64 on "/{ns}/v"\n  value max(v.data)\n}\n',
     1, 8, "one of exsce's built-in metrics"),
    ('metric bad-name for each robot {\n  reads v: std_msgs/Float64 on "/{ns}/v"\n  value max(v.data)\n}\n',
     1, 8, "must be letters, digits and '_'"),
    ('metric m for each robot {\n  reads v: std_msgs/Float64 on "/{ns}/v\\"; x"\n  value max(v.data)\n}\n',
     2, 3, "is not a ROS topic name"),
    ('metric m for each robot per segment {\n  reads v: std_msgs/Float64 on "/{ns}/v"\n  value mean(v.data)\n}\n',
     1, 8, "so that its values over path segments make one value"),
    ('metric m for each robot {\n  unit cm\n  reads v: std_msgs/Float64 on "/{ns}/v"\n  value max(v.data)\n}\n',
     1, 8, "write 'm', not 'cm'"),
    ('metric m for each robot {\n  unit m/s\n  safe below 1 m\n  reads v: std_msgs/Float64 on "/{ns}/v"\n'
     "  value max(v.data)\n}\n", 3, 3, "the limit is a length, but 'm' is a speed"),
    ('metric m for each robot {\n  safe above 1\n  reads v: std_msgs/Float64 on "/{ns}/v"\n  value max(v.data)\n}\n',
     2, 3, "is the min(...) of its values"),
    ('metric m for mission {\n  reads p: std_msgs/Float64 on "/{ns}/p"\n  value max(p.data)\n}\n',
     3, 13, "a mission metric reads every robot's topics"),
    ('metric m for each pair of robots (a, b) {\n  reads p: std_msgs/Float64 on "/{ns}/p"\n'
     "  value min(p.data)\n}\n", 3, 13, "say whose topic this is: a.p.data or b.p.data"),
    ('metric m for each pair of robots (a, b) {\n  reads p: sensor_msgs/LaserScan on "/{ns}/p"\n'
     "  value min(a.p.ranges - b.p.ranges)\n}\n", 3, 26, "arrays cannot be aligned in time"),
]


@pytest.mark.parametrize(("text", "line", "column", "message"), DECLARATION_ERRORS)
def test_declaration_errors_are_reported_at_their_line_and_column(tmp_path, text, line, column, message):
    spec = tmp_path / "m.exsce"
    spec.write_text(text)
    errors = analyse(spec).errors
    assert len(errors) == 1, errors
    (error,) = errors
    assert (error.location.line, error.location.column) == (line, column), error
    assert message in error.message


def test_check_prints_a_metric_error_as_file_line_col(tmp_path):
    (tmp_path / "m.exsce").write_text(_HEADER + "  value mean(vel.linar.x)\n}\n")
    done = exscec_here("check", "m.exsce", cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "m.exsce:3:14: error: vel (geometry_msgs/msg/Twist) has no field 'linar'" in done.stderr


def test_check_names_an_unknown_function_at_its_place_with_the_functions_there_are(tmp_path):
    (tmp_path / "m.exsce").write_text(_HEADER + "  value max(vel.linear.x) - min(absl(vel.linear.x))\n}\n")
    done = exscec_here("check", "m.exsce", cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "m.exsce:3:33: error: unknown function 'absl'; did you mean 'abs'? (the functions: min," in (
        done.stderr
    )
    assert "expected" not in done.stderr  # not a syntax error listing tokens


def test_a_clause_on_a_user_metric_checks_its_unit_and_scope(tmp_path):
    text = (BUILDING / "scenario_c.exsce").read_text().replace(
        "fast_driving_time stays below 2 s", "fast_driving_time stays below 2 m"
    )
    for name in ("environment.exsce", "robots.exsce", "metrics.exsce"):
        (tmp_path / name).write_text((BUILDING / name).read_text())
    (tmp_path / "tasks").mkdir()
    for task in (BUILDING / "tasks").glob("*.exsce"):
        (tmp_path / "tasks" / task.name).write_text(task.read_text())
    (tmp_path / "maps").symlink_to(BUILDING / "maps")
    (tmp_path / "scenario_c.exsce").write_text(text)
    with pytest.raises(SpecError) as raised:
        load_spec(tmp_path / "scenario_c.exsce")
    assert "'fast_driving_time' is a time, in s; '2 m' is a length" in raised.value.message


# The method's metrics as DESIGN.md §1 describes them, written out by hand (the standard library
# is their one declaration in the package: issue 49, item 2).
METHOD_METRICS = {
    "mission_duration": MetricInfo("mission_duration", Dimension.TIME, False, meaning="first goal active to last goal done"),
    "task_duration": MetricInfo("task_duration", Dimension.TIME, True, Combine.SUM, meaning="time to complete its tasks"),
    "waypoints_visited": MetricInfo("waypoints_visited", Dimension.COUNT, True, meaning="goals that succeeded"),
    "distance_travelled": MetricInfo("distance_travelled", Dimension.LENGTH, True, Combine.SUM, meaning="metres travelled"),
    "distance_to_obstacles": MetricInfo("distance_to_obstacles", Dimension.LENGTH, True, Combine.MIN, meaning="least laser range"),
    "max_velocity": MetricInfo("max_velocity", Dimension.SPEED, True, Combine.MAX, meaning="largest linear speed"),
    "distance_between_robots": MetricInfo("distance_between_robots", Dimension.LENGTH, False, meaning="least distance between two robots"),
    "violation_duration": MetricInfo(
        "violation_duration", Dimension.TIME, True, also_mission=True, meaning="seconds a safety limit was violated"
    ),
}  # fmt: skip


def test_the_standard_library_declares_the_builtin_metrics_as_the_method_describes_them():
    declared = {m.name: m for m in standard_metrics()}
    assert set(declared) == set(METHOD_METRICS) - {"violation_duration"}
    for name, metric in declared.items():
        assert metric.info() == METHOD_METRICS[name], name
        assert metric.standard
    assert builtin_metrics() == METHOD_METRICS  # violation_duration follows from the safe ones
    assert list(builtin_metrics()) == list(METHOD_METRICS)  # in the method's order
    safety = {m.name: (m.safety.bound, m.safety.limit) for m in standard_metrics() if m.safety}
    assert safety == {
        "max_velocity": ("below", 1.0),
        "distance_to_obstacles": ("above", 0.1),
        "distance_between_robots": ("above", 0.1),
    }
    assert declared["distance_between_robots"].subject is ComputedFor.PAIRS


def test_metric_declarations_print_back_to_the_same_model(tmp_path):
    source = BUILDING / "metrics.exsce"
    spec = load_spec(source)
    printed = "\n".join(text for m in spec.metrics for text, _ in [*metric_lines(m), ("", None)])
    again = tmp_path / "again.exsce"
    again.write_text(printed)
    assert load_spec(again).metrics == spec.metrics
    assert "> 0.8 m/s" in printed  # numbers keep the unit they were written with
