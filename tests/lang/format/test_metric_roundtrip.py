"""Property: any well-typed metric expression prints back (with the fewest parentheses) to text
that parses to the same expression, and the monitors generated from it compile.  Its fields
are those of one topic: plain paths, elements of arrays (``scan.ranges[-2]``), selections by
text or number (``tf.transforms[child_frame_id == "..."]``) and lengths (``len(...)``)."""

from __future__ import annotations

from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from exsce_dsl.lang import expression_text, load_spec
from exsce_dsl.lang.lexical import number_text, string_literal
from exsce_dsl.monitor_code import monitor_source

HEADER = """metric m for each robot {{
  reads vel: geometry_msgs/msg/Twist on "/{{ns}}/nav_vel"
  reads scan: sensor_msgs/msg/LaserScan on "/{{ns}}/scan"
  reads feedback: waypoint_dispatcher/msg/FollowWaypointsActionFeedback on "/{{ns}}/waypoint_dispatcher/feedback"
  reads tf: tf2_msgs/msg/TFMessage on "/{{ns}}/tf"
  reads diag: actionlib_msgs/msg/GoalStatusArray on "/{{ns}}/status"
  value {value}
}}
"""

numbers = st.sampled_from(["0.5", "2", "1.5e-3", "0.8 m/s", "3 s"])
texts = st.text(st.characters(exclude_categories=("Cs", "Cc")), max_size=8).map(string_literal)
values = st.one_of(
    st.integers(-5, 300).map(str),
    st.floats(allow_nan=False, allow_infinity=False).map(number_text),
)
FIELDS = {
    "vel": st.sampled_from(["vel.linear.x", "vel.linear.y", "vel.angular.z"]),
    "tf": st.one_of(
        texts.map(lambda t: f"tf.transforms[child_frame_id == {t}].transform.translation.x"),
        texts.map(lambda t: f"tf.transforms[header.frame_id == {t}].header.stamp.sec"),
        values.map(lambda v: f"tf.transforms[header.stamp.nanosec == {v}].transform.rotation.w"),
        st.integers(-3, 3).map(lambda i: f"tf.transforms[{i}].transform.translation.y"),
        st.just("len(tf.transforms)"),
    ),
    "diag": st.one_of(
        values.map(lambda v: f"diag.status_list[status == {v}].goal_id.stamp.sec"),
        texts.map(lambda t: f"diag.status_list[goal_id.id == {t}].status"),
        st.integers(-3, 3).map(lambda i: f"diag.status_list[{i}].status"),
        st.just("len(diag.status_list)"),
    ),
    "scan": st.one_of(
        st.integers(-3, 700).map(lambda i: f"scan.ranges[{i}]"),
        st.sampled_from(["len(scan.ranges)", "scan.angle_min", "scan.header.stamp.sec"]),
    ),
}
"""Per topic, its fields of a number per message (conditions join fields of one topic only)."""


def _per_message(depth: int, fields: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    if depth == 0:
        return fields
    inner = _per_message(depth - 1, fields)
    return st.one_of(
        fields,
        st.tuples(inner, st.sampled_from(["+", "-", "*", "/"]), st.one_of(inner, numbers)).map(" ".join),
        st.tuples(numbers, st.sampled_from(["+", "-", "*"]), inner).map(" ".join),
        inner.map(lambda e: f"({e})"),
        inner.map(lambda e: f"-({e})"),
        inner.map(lambda e: f"abs({e})"),
        st.tuples(inner, inner).map(lambda p: f"norm({p[0]}, {p[1]})"),
        st.tuples(inner, inner).map(lambda p: f"speed({p[0]}, {p[1]})"),
        inner.map(lambda e: f"derivative({e})"),
    )


def _condition(depth: int, fields: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    compare = st.tuples(_per_message(depth, fields), st.sampled_from(["<", "<=", ">", ">=", "==", "!="]), numbers)
    single = compare.map(" ".join)
    return st.one_of(
        single,
        st.tuples(single, st.sampled_from(["and", "or"]), single).map(" ".join),
        single.map(lambda c: f"not {c}"),
        single.map(lambda c: f"not ({c})"),
    )


def _value(depth: int, fields: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    aggregate = st.one_of(
        st.tuples(st.sampled_from(["min", "max", "mean", "sum", "first", "last", "integral", "change"]),
                  _per_message(depth, fields)).map(lambda p: f"{p[0]}({p[1]})"),
        st.tuples(st.sampled_from(["min", "max"]), _per_message(depth, fields), _condition(1, fields))
        .map(lambda p: f"{p[0]}({p[1]} where {p[2]})"),
        st.tuples(st.sampled_from(["duration", "count"]), _condition(depth, fields))
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
@given(value=st.one_of(*(_value(2, fields) for fields in FIELDS.values())))
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
