"""Property: any well-typed metric expression prints back (with the fewest parentheses) to text
that parses to the same expression, and the monitors generated from it compile."""

from __future__ import annotations

from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from exsce_dsl.lang.build import load_spec
from exsce_dsl.lang.format_metrics import expression_text
from exsce_dsl.runs.monitor_code import monitor_source

HEADER = """metric m for each robot {{
  reads vel: geometry_msgs/msg/Twist on "/{{ns}}/nav_vel"
  reads scan: sensor_msgs/msg/LaserScan on "/{{ns}}/scan"
  reads feedback: waypoint_dispatcher/msg/FollowWaypointsActionFeedback on "/{{ns}}/waypoint_dispatcher/feedback"
  value {value}
}}
"""

numbers = st.sampled_from(["0.5", "2", "1.5e-3", "0.8 m/s", "3 s"])
fields = st.sampled_from(["vel.linear.x", "vel.linear.y", "vel.angular.z"])


def _per_message(depth: int) -> st.SearchStrategy[str]:
    if depth == 0:
        return fields
    inner = _per_message(depth - 1)
    return st.one_of(
        fields,
        st.tuples(inner, st.sampled_from(["+", "-", "*", "/"]), st.one_of(inner, numbers)).map(" ".join),
        st.tuples(numbers, st.sampled_from(["+", "-", "*"]), inner).map(" ".join),
        inner.map(lambda e: f"({e})"),
        inner.map(lambda e: f"-({e})"),
        inner.map(lambda e: f"abs({e})"),
        st.tuples(inner, inner).map(lambda p: f"norm({p[0]}, {p[1]})"),
    )


def _condition(depth: int) -> st.SearchStrategy[str]:
    compare = st.tuples(_per_message(depth), st.sampled_from(["<", "<=", ">", ">=", "==", "!="]), numbers)
    single = compare.map(" ".join)
    return st.one_of(
        single,
        st.tuples(single, st.sampled_from(["and", "or"]), single).map(" ".join),
        single.map(lambda c: f"not {c}"),
        single.map(lambda c: f"not ({c})"),
    )


def _value(depth: int) -> st.SearchStrategy[str]:
    aggregate = st.one_of(
        st.tuples(st.sampled_from(["min", "max", "mean", "sum", "first", "last", "integral", "change"]),
                  _per_message(depth)).map(lambda p: f"{p[0]}({p[1]})"),
        st.tuples(st.sampled_from(["min", "max"]), _per_message(depth), _condition(1))
        .map(lambda p: f"{p[0]}({p[1]} where {p[2]})"),
        st.tuples(st.sampled_from(["duration", "count"]), _condition(depth))
        .map(lambda p: f"({p[0]} where {p[1]})"),
        st.just("min(scan.ranges where scan.ranges >= scan.range_min)"),
        st.just("elapsed"),
    )
    return st.one_of(
        aggregate,
        st.tuples(aggregate, st.sampled_from(["+", "-", "*", "/"]), st.one_of(aggregate, numbers)).map(" ".join),
        st.tuples(aggregate, aggregate).map(lambda p: f"norm({p[0]}, {p[1]}) - sqrt({p[1]})"),
    )


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(value=_value(2))
def test_a_metric_prints_back_to_itself_and_generates_code(tmp_path_factory, value):
    folder = tmp_path_factory.mktemp("m")
    first = Path(folder / "first.exsce")
    first.write_text(HEADER.format(value=value))
    (metric,) = load_spec(first).metrics
    printed = expression_text(metric.value)
    second = Path(folder / "second.exsce")
    second.write_text(HEADER.format(value=printed))
    (again,) = load_spec(second).metrics
    assert again.value == metric.value, printed
    assert expression_text(again.value) == printed  # printing is stable
    compile(monitor_source([metric], "first.exsce"), "monitors.py", "exec")


def test_regression_a_sum_of_three_terms_keeps_every_operator(tmp_path):
    """textX lost the second operator of `x + 0.5 - x` when operators and operands were two lists."""
    spec = tmp_path / "m.exsce"
    spec.write_text(HEADER.format(value="min(vel.linear.x + 0.5 - vel.angular.z * 2 / 4)"))
    (metric,) = load_spec(spec).metrics
    assert expression_text(metric.value) == "min(vel.linear.x + 0.5 - vel.angular.z * 2 / 4)"
