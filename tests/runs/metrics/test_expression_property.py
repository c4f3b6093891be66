"""Every metric expression that passes the checks computes (issue 32, item 7).

Hypothesis writes random well-typed metric declarations over the topics of an
executor run of two robots (velocity, pose, laser scan, distance, the
dispatcher's windows, the robot's pose signal, and a topic the bag lacks):
arithmetic with signed constants nested at any depth, every function the
docs/language.md lists, conditions, aggregates over arrays, pairs of robots.  Each
declaration must pass ``check``, and ingesting the run must then give each of
its values (for the run and, per segment, for each path segment) as a finite
number or no value, never an internal error: the only exception allowed is a
located ``ExsceError``.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import analyse, load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate

from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"

IMPORTS = f"""\
import "{BUILDING}/environment.exsce"
import "{BUILDING}/robots.exsce"
import "{BUILDING}/tasks/deliveries.exsce"
"""
SCENARIO = """
scenario prop in brsu_building_c_with_doors {
  robots {
    tiago1: tiago starts at classroom_c025-w001
    tiago2: tiago starts at classroom_c025-w002
  }
  mission prop_mission parallel {
    tiago1 does delivery_a
    tiago2 does delivery_b
  }
}
"""

READS = """\
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  reads pose: geometry_msgs/msg/PoseWithCovarianceStamped on "/{ns}/robot_pose"
  reads scan: sensor_msgs/msg/LaserScan on "/{ns}/scan"
  reads dist: std_msgs/msg/Float64 on "/{ns}/distance_travelled"
  reads ghost: std_msgs/msg/Float64 on "/{ns}/not_in_the_bag"
  reads feedback: waypoint_dispatcher/msg/FollowWaypointsActionFeedback on "/{ns}/waypoint_dispatcher/feedback"
  reads result: waypoint_dispatcher/msg/FollowWaypointsActionResult on "/{ns}/waypoint_dispatcher/result"
"""
SIGNAL_READ = "  reads here: robot pose\n"

# Numbers per message, by topic (a per-message field of each).
FIELDS = {
    "vel": ["vel.linear.x", "vel.linear.y", "vel.angular.z"],
    "pose": ["pose.pose.pose.position.x", "pose.pose.pose.position.y", "pose.pose.pose.orientation.w"],
    "scan": [
        "scan.range_min",
        "scan.range_max",
        "scan.ranges[0]",
        "scan.ranges[-1]",
        "len(scan.ranges)",
        "len(scan.intensities)",
    ],
    "dist": ["dist.data"],
    "ghost": ["ghost.data"],
    "here": ["here.x", "here.y", "here.yaw"],
}
ARRAYS = ["scan.ranges", "scan.intensities"]
CONSTANTS = ["0", "1", "-1", "2.5", "-100", "(0 - 100)", "0.8 m/s", "-0.5 m", "1e-3", "-(2 * 3)", "(1 / 0)"]
COMPARE = ["<", "<=", ">", ">=", "==", "!="]
ARITHMETIC = ["+", "-", "*", "/"]
AGGREGATES = ["min", "max", "mean", "sum", "first", "last"]


def _paren(text: str) -> str:
    return f"({text})"


def _field(written: str, prefix: str) -> str:
    """A field of the robot ``prefix`` names (``a.``, ``b.``: of a pair), as written."""
    if written.startswith("len("):
        return f"len({prefix}{written[4:]}"
    return prefix + written


@st.composite
def numbers(draw: st.DrawFn, topic: str, depth: int, prefix: str = "") -> str:
    """A number per message of ``topic`` (it reads at least one of its fields)."""
    if depth == 0:
        return _field(draw(st.sampled_from(FIELDS[topic])), prefix)
    inner = numbers(topic, depth - 1, prefix)
    choice = draw(st.integers(0, 9))
    if choice == 0:
        return _field(draw(st.sampled_from(FIELDS[topic])), prefix)
    if choice == 1:  # a constant on either side, signed or not
        op, const = draw(st.sampled_from(ARITHMETIC)), draw(st.sampled_from(CONSTANTS))
        return draw(st.sampled_from([f"{draw(inner)} {op} {const}", f"{const} {op} {draw(inner)}"]))
    if choice == 2:
        return f"{draw(inner)} {draw(st.sampled_from(ARITHMETIC))} {_paren(draw(inner))}"
    if choice == 3:
        return f"-{_paren(draw(inner))}"
    if choice == 4:
        return f"{draw(st.sampled_from(['abs', 'sqrt']))}({draw(inner)})"
    if choice == 5:
        other = draw(st.one_of(inner, st.sampled_from(CONSTANTS)))
        return f"norm({draw(inner)}, {other})"
    if choice == 6:
        return f"derivative({draw(inner)})"
    if choice == 7:
        coordinates = draw(st.lists(inner, min_size=2, max_size=3))
        return f"speed({', '.join(coordinates)})"
    return _paren(draw(inner))


@st.composite
def conditions(draw: st.DrawFn, topic: str, depth: int, prefix: str = "") -> str:
    """A condition per message of ``topic``."""
    left = draw(numbers(topic, depth, prefix))
    right = draw(st.one_of(numbers(topic, depth, prefix), st.sampled_from(CONSTANTS)))
    compared = f"{left} {draw(st.sampled_from(COMPARE))} {right}"
    if depth == 0:
        return compared
    choice = draw(st.integers(0, 3))
    if choice == 0:
        return compared
    if choice == 1:
        return f"not {_paren(compared)}"
    other = draw(conditions(topic, depth - 1, prefix))
    return f"{_paren(compared)} {'and' if choice == 2 else 'or'} {other}"


@st.composite
def arrays(draw: st.DrawFn, depth: int) -> str:
    """An array per message of the scan (arrays are never aligned with another topic)."""
    if depth == 0:
        return draw(st.sampled_from(ARRAYS))
    inner = draw(arrays(depth - 1))
    choice = draw(st.integers(0, 3))
    if choice == 0:
        return inner
    if choice == 1:
        other = draw(st.one_of(st.sampled_from(CONSTANTS), numbers("scan", 1)))
        return f"{_paren(inner)} {draw(st.sampled_from(ARITHMETIC))} {other}"
    if choice == 2:
        return f"abs({inner})"
    return f"-{_paren(inner)}"


@st.composite
def per_window(draw: st.DrawFn, depth: int) -> str:
    """One number per window, for each robot."""
    topic = draw(st.sampled_from(sorted(FIELDS)))
    values = numbers(topic, draw(st.integers(0, 3)))
    choice = draw(st.integers(0, 12 if depth > 0 else 8))
    func = draw(st.sampled_from(AGGREGATES))
    if choice == 0:
        return f"{func}({draw(values)})"
    if choice == 1:
        return f"{func}({draw(values)} where {draw(conditions(topic, 1))})"
    if choice == 2:
        where = draw(
            st.sampled_from(
                ["", f" where {draw(st.sampled_from(ARRAYS))} > 0.5", f" where {draw(conditions('scan', 1))}"]
            )
        )
        return f"{draw(st.sampled_from(['min', 'max', 'mean', 'sum']))}({draw(arrays(2))}{where})"
    if choice == 3:
        return f"{draw(st.sampled_from(['duration', 'count']))} where {draw(conditions(topic, 2))}"
    if choice == 4:
        coordinates = draw(st.lists(values, min_size=2, max_size=3))
        return f"path_length({', '.join(coordinates)})"
    if choice == 5:
        return f"{draw(st.sampled_from(['integral', 'change']))}({draw(values)})"
    if choice == 6:  # two topics, aligned in time
        other = draw(st.sampled_from(sorted(set(FIELDS) - {topic})))
        return f"{func}({draw(values)} {draw(st.sampled_from(ARITHMETIC))} {draw(numbers(other, 1))})"
    if choice == 7:
        return draw(st.sampled_from(["elapsed", "succeeded"]))
    if choice == 8:
        return draw(st.sampled_from(CONSTANTS)) + f" * {func}({draw(values)})"
    inner = per_window(depth - 1)
    if choice == 9:  # in parentheses: 'duration where' would take what follows into its condition
        return f"{_paren(draw(inner))} {draw(st.sampled_from(ARITHMETIC))} {_paren(draw(inner))}"
    if choice == 10:
        return f"-{_paren(draw(inner))}"
    if choice == 11:
        return f"{draw(st.sampled_from(['abs', 'sqrt']))}({draw(inner)})"
    return f"norm({draw(inner)}, {draw(st.one_of(inner, st.sampled_from(CONSTANTS)))})"


@st.composite
def pair_values(draw: st.DrawFn) -> str:
    """One number per window of a pair of robots: their topics aligned in time."""
    topic = draw(st.sampled_from(["vel", "pose", "dist", "here"]))
    a, b = draw(numbers(topic, 2, "a.")), draw(numbers(topic, 2, "b."))
    func = draw(st.sampled_from(["min", "max", "sum"]))  # what combines over the pairs
    return f"{func}({a} {draw(st.sampled_from(ARITHMETIC))} {b})"


@st.composite
def per_segment(draw: st.DrawFn) -> str:
    """A value that combines over path segments (a sum, min or max of it), over short windows."""
    topic = draw(st.sampled_from(sorted(FIELDS)))
    values = numbers(topic, draw(st.integers(0, 2)))
    choice = draw(st.integers(0, 3))
    if choice == 0:
        return f"{draw(st.sampled_from(['min', 'max', 'sum']))}({draw(values)})"
    if choice == 1:
        return f"{draw(st.sampled_from(['duration', 'count']))} where {draw(conditions(topic, 1))}"
    if choice == 2:
        return f"path_length({draw(values)}, {draw(values)})"
    return f"{draw(st.sampled_from(['integral', 'change']))}({draw(values)})"


def _declaration(number: int, value: str, pair: bool, segments: bool = False, otherwise: bool = False) -> str:
    subject = "each pair of robots (a, b)" if pair else "each robot"
    reads = READS
    if pair:  # a pair's values are aligned fields: the dispatcher's windows are a robot's
        reads = "".join(line + "\n" for line in READS.splitlines() if "dispatcher" not in line)
    if otherwise:  # the value reads a topic the bag lacks: the run has what 'otherwise' gives
        value = f"max(ghost.data)\n  otherwise {value}"
    segment = " per segment" if segments else ""
    return f"metric m{number} for {subject}{segment} {{\n{reads}{SIGNAL_READ}  value {value}\n}}\n"


@pytest.fixture(scope="module")
def executor_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("expressions")
    (folder / "base.exsce").write_text(IMPORTS + SCENARIO)
    run = next(iter(simulate(load_spec(folder / "base.exsce").scenario(), folder, runs=1, seed=4)))
    return folder, run.bag


@settings(
    max_examples=30,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(
    robot=st.lists(st.tuples(per_window(2), st.booleans()), min_size=1, max_size=3),
    segments=st.lists(per_segment(), max_size=2),
    pairs=st.lists(pair_values(), max_size=1),
)
def test_every_checked_expression_computes_a_finite_value_or_none(executor_run, robot, segments, pairs):
    folder, bag = executor_run
    declared = [_declaration(k, v, False, otherwise=o) for k, (v, o) in enumerate(robot)]
    declared += [_declaration(len(declared) + k, v, False, segments=True) for k, v in enumerate(segments)]
    declared += [_declaration(len(declared) + k, v, True) for k, v in enumerate(pairs)]
    spec = folder / "metrics_spec.exsce"
    spec.write_text(IMPORTS + "".join(declared) + SCENARIO)
    errors = analyse(spec).errors
    assert not errors, "\n".join(map(str, errors))
    try:
        analysed = analyse_bag(bag, load_spec(spec).scenario())
    except ExsceError as error:
        assert error.location is not None, error
        return
    names = {f"m{k}" for k in range(len(declared))}
    for value in analysed.run.metrics:
        if value.metric in names:
            assert math.isfinite(value.value), (value, declared)


def test_the_generated_declarations_read_what_they_say(executor_run):
    """The property above is not vacuous: a declaration like the generated ones has values."""
    folder, bag = executor_run
    spec = folder / "plain.exsce"
    spec.write_text(IMPORTS + _declaration(0, "max(vel.linear.x * -1 + (0 - 100)) - -1", False) + SCENARIO)
    analysed = analyse_bag(bag, load_spec(spec).scenario())
    values = [v for v in analysed.run.metrics if v.metric == "m0" and v.action is None]
    assert {v.robot for v in values} == {"tiago1", "tiago2"}
    assert all(-101 < v.value < -98 for v in values)
