"""Field paths in metrics: any message type rosbags knows or the user defines, element access
(``scan.ranges[-1]``), selections (``tf.transforms[child_frame_id == "base_link"]``) and
lengths (``len(diag.status_list)``).

Known answers for what each path is (a number or an array per message, its key), a line and
column for every mistake, a warning (not an error) for a type exsce does not know, the same
checks against a bag's definition at ingest, the user's ``.msg``/``.idl`` files, the
formatter, the live runtime's reading of message objects, and the editor's completion.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from exsce_dsl.cli.common import REMEDIES
from exsce_dsl.codegen.ros_monitor import attribute_path, monitor_topics
from exsce_dsl.errors import MessageTypeError
from exsce_dsl.lang import analyse
from exsce_dsl.lang.format.metrics import expression_text, metric_lines
from exsce_dsl.lsp.fields import field_hover, offers
from exsce_dsl.messages.catalogue import Source, parse_definition, standard_catalogue
from exsce_dsl.messages.field_check import check_fields
from exsce_dsl.messages.user import configured_catalogue, user_catalogue
from exsce_dsl.model.expressions import Aggregate, Field
from exsce_dsl.model.messages import FieldPath, Index, Select
from exsce_dsl.monitor_kit import monitor_runtime

from tests.support.cli import exscec_here

READS = """\
metric m for each robot {
  reads tf: tf2_msgs/msg/TFMessage on "/{ns}/tf"
  reads diag: actionlib_msgs/msg/GoalStatusArray on "/{ns}/status"
  reads mk: visualization_msgs/msg/MarkerArray on "/{ns}/markers"
  reads scan: sensor_msgs/msg/LaserScan on "/{ns}/scan"
  reads odom: nav_msgs/Odometry on "/{ns}/odom"
"""
"""Five reads of types the old hand-written table did not have; the value goes on line 7."""


def _analysis(tmp_path: Path, text: str):
    spec = tmp_path / "m.exsce"
    spec.write_text(text)
    return analyse(spec)


def _field(tmp_path: Path, written: str) -> Field:
    analysis = _analysis(tmp_path, READS + f"  value max({written})\n}}\n")
    assert analysis.errors == [], analysis.errors
    (metric,) = analysis.spec.metrics
    assert isinstance(metric.value, Aggregate)
    (found,) = metric.value.args
    assert isinstance(found, Field)
    return found


# (as written, its key, an array per message?)
KINDS = [
    ("scan.ranges", "ranges", True),
    ("scan.ranges[0]", "ranges[0]", False),
    ("scan.ranges[-1]", "ranges[-1]", False),
    ("len(scan.ranges)", "len(ranges)", False),
    ("odom.pose.covariance", "pose.covariance", True),
    ("odom.pose.covariance[35]", "pose.covariance[35]", False),
    ("odom.pose.pose.position.x", "pose.pose.position.x", False),
    ("tf.transforms.transform.translation.x", "transforms.transform.translation.x", True),
    (
        'tf.transforms[child_frame_id == "base_link"].transform.translation.x',
        'transforms[child_frame_id == "base_link"].transform.translation.x',
        False,
    ),
    (
        'tf.transforms[header.frame_id == "map"].header.stamp.sec',
        'transforms[header.frame_id == "map"].header.stamp.sec',
        False,
    ),
    ("len(tf.transforms)", "len(transforms)", False),
    ("tf.transforms[-1].header.stamp.nanosec", "transforms[-1].header.stamp.nanosec", False),
    ("diag.status_list.status", "status_list.status", True),
    ("diag.status_list[0].status", "status_list[0].status", False),
    ("diag.status_list[status == 3].goal_id.stamp.sec", "status_list[status == 3].goal_id.stamp.sec", False),
    ("diag.status_list[status == 1.5].status", "status_list[status == 1.5].status", False),
    ("mk.markers[0].points.x", "markers[0].points.x", True),
    ("mk.markers[1].points[-1].z", "markers[1].points[-1].z", False),
    ("len(mk.markers[0].points)", "len(markers[0].points)", False),
]


@pytest.mark.parametrize(("written", "key", "arrays"), KINDS)
def test_what_each_path_is(tmp_path, written, key, arrays):
    found = _field(tmp_path, written)
    assert found.path.key == key
    assert found.arrays is arrays
    assert found.path.length is written.startswith("len(")
    assert found.path.picks is ("[" in written)


def test_a_path_is_its_steps(tmp_path):
    found = _field(tmp_path, 'tf.transforms[child_frame_id == "base_link"].transform.translation.x')
    assert found.read == "tf"
    assert found.path == FieldPath(
        ("transforms", Select(("child_frame_id",), "base_link"), "transform", "translation", "x")
    )
    found = _field(tmp_path, "len(mk.markers[-2].points)")
    assert found.path == FieldPath(("markers", Index(-2), "points"), length=True)
    found = _field(tmp_path, "diag.status_list[status == 3].status")
    assert found.path.steps[1] == Select(("status",), 3.0)


def test_the_kind_decides_what_applies(tmp_path):
    """An array per message takes min, max, mean or sum; a picked element is a number again."""
    arrays = _analysis(tmp_path, READS + "  value first(tf.transforms.transform.translation.x)\n}\n")
    assert [e.message for e in arrays.errors] == [
        "first(...) of an array has no single time course: take min, max, mean or sum"
    ]
    picked = _analysis(tmp_path, READS + "  value first(tf.transforms[0].transform.translation.x)\n}\n")
    assert picked.errors == []
    counted = _analysis(tmp_path, READS + "  value mean(len(tf.transforms) + len(scan.ranges) * 0)\n}\n")
    assert counted.errors == []
    mixed = _analysis(tmp_path, READS + "  value max(tf.transforms.transform.translation.x - scan.ranges)\n}\n")
    assert [(e.location.line, e.location.column) for e in mixed.errors] == [(7, 53)]
    assert "arrays cannot be aligned in time" in mixed.errors[0].message


def test_every_field_a_metric_reads_is_kept_on_its_read_with_its_place(tmp_path):
    text = READS + "  value max(scan.ranges[0]) + max(len(tf.transforms))\n  otherwise min(scan.ranges)\n}\n"
    (metric,) = _analysis(tmp_path, text).spec.metrics
    reads = {r.name: r for r in metric.reads}
    assert [(f.path.key, f.location.line, f.location.column) for f in reads["scan"].fields] == [
        ("ranges[0]", 7, 13),
        ("ranges", 8, 17),
    ]
    assert [(f.path.key, f.location.column) for f in reads["tf"].fields] == [("len(transforms)", 35)]
    assert reads["odom"].fields == ()


def test_a_pair_metric_says_whose_topic_before_the_path(tmp_path):
    text = (
        "metric m for each pair of robots (a, b) {\n"
        '  reads tf: tf2_msgs/msg/TFMessage on "/{ns}/tf"\n'
        '  value min(a.tf.transforms[child_frame_id == "base_link"].transform.translation.x'
        ' - b.tf.transforms[child_frame_id == "base_link"].transform.translation.x)\n}\n'
    )
    (metric,) = _analysis(tmp_path, text).spec.metrics
    assert expression_text(metric.value) == text.split("value ")[1].split("\n")[0]
    assert {f.robot for f in metric.reads[0].fields} == {"a", "b"}
    unsaid = _analysis(tmp_path, text.replace("a.tf.transforms", "tf.transforms", 1))
    assert 'say whose topic this is: a.tf.transforms[child_frame_id == "base_link"]' in unsaid.errors[0].message


# A line-number matrix: each planted mistake is reported at its line and column.
ERRORS = [
    ("max(tf.transforms[0].transfrom.x)", 7, 13,
     "tf.transforms[0] (tf2_msgs/msg/TFMessage.transforms[0]) has no field 'transfrom'; did you mean 'transform'?"),
    ("max(odom.pose.pose.postion.x)", 7, 13, "has no field 'postion'; did you mean 'position'?"),
    ("max(tf.transforms[0].transform)", 7, 13,
     "tf.transforms[0].transform is a message (translation, rotation), not a number: name one of its fields"),
    ("max(tf.transforms)", 7, 13,
     "tf.transforms is an array of messages (header, child_frame_id, transform), not a number: name a field "
     "of its elements (tf.transforms.header) or pick one (tf.transforms[0])"),
    ("max(tf.transforms[0].child_frame_id)", 7, 13, "tf.transforms[0].child_frame_id is text, not a number"),
    ("max(diag.status_list.goal_id.id)", 7, 13, "diag.status_list.goal_id.id is text, not a number"),
    ("max(tf.transforms[child_frame_id == 3].transform.translation.x)", 7, 13,
     'child_frame_id is text: compare it to a quoted string (child_frame_id == "...")'),
    ('max(diag.status_list[status == "3"].status)', 7, 13,
     "status is a number: compare it to a number, not to text"),
    ("max(scan.angle_min[0])", 7, 13, "scan.angle_min is a number, not an array: [0] picks an element"),
    ("max(odom.pose[1].pose.position.x)", 7, 13, "odom.pose is a message (pose, covariance), not an array"),
    ("max(scan.ranges[x == 1])", 7, 13,
     "scan.ranges is an array of numbers: [x == ...] picks an element of an array of messages by one of its "
     "fields; pick a position instead: scan.ranges[0]"),
    ('max(scan.header[frame_id == "map"].stamp.sec)', 7, 13,
     "scan.header is a message (stamp, frame_id), not an array of messages"),
    ('max(tf.transforms[child_frame == "a"].transform.translation.x)', 7, 13,
     "an element of tf.transforms has no field 'child_frame'; did you mean 'child_frame_id'?"),
    ('max(tf.transforms[header.frame == "a"].transform.translation.x)', 7, 13,
     "header in an element of tf.transforms has no field 'frame'; did you mean 'frame_id'?"),
    ("max(tf.transforms[header.stamp == 1].transform.translation.x)", 7, 13,
     "header.stamp in an element of tf.transforms is a message (sec, nanosec): a selection compares"),
    ("max(len(scan.angle_min))", 7, 13,
     "len(...) counts the elements of an array, but scan.angle_min is a number"),
    ("max(len(odom.pose))", 7, 13, "len(...) counts the elements of an array, but odom.pose is a message"),
    ("max(mk.markers.points.x)", 7, 13,
     "mk.markers.points is an array of messages (x, y, z) in each element of mk.markers, an array of arrays: "
     "pick one element of mk.markers, e.g. mk.markers[0].points.x"),
    ("max(len(mk.markers.points))", 7, 13, "pick one element of mk.markers, e.g. len(mk.markers[0].points)"),
    ("max(mk.markers.colors[0].r)", 7, 13, "e.g. mk.markers[0].colors[0].r"),
    ("max(scan.ranges.x)", 7, 13, "scan.ranges is an array of numbers: it has no field 'x'"),
    ("max(scan[0].ranges)", 7, 17, "'scan' is a topic, not an array: [...] picks an element of an array field"),
    ("mean(diag.status_list[0].status) - len(diag.status_list)", 7, 44,
     "mixes one number per window with values per message"),
]


@pytest.mark.parametrize(("value", "line", "column", "message"), ERRORS)
def test_path_errors_are_reported_at_their_line_and_column(tmp_path, value, line, column, message):
    errors = _analysis(tmp_path, READS + f"  value {value}\n}}\n").errors
    assert len(errors) == 1, errors
    (error,) = errors
    assert (error.location.line, error.location.column) == (line, column), error
    assert message in error.message


def test_a_syntax_error_in_a_pick_says_what_may_come(tmp_path):
    for value, column, message in (
        ("min(scan.ranges[)", 25, "expected a number or a word, found ')'"),
        ("min(scan.ranges[1.5])", 25, "expected a number or a word, found '1.5]'"),
        ("min(tf.transforms[child_frame_id == ])", 45, "expected a quoted string or a number, found ']'"),
    ):
        (error,) = _analysis(tmp_path, READS + f"  value {value}\n}}\n").errors
        assert (error.location.line, error.location.column, error.message) == (7, column, message)


# ------------------------------------------------------------------ types exsce does not know
TURTLE = """\
metric m for each robot {
  reads turtle: turtlesim/msg/Pose on "/{ns}/turtle1/pose"
  value max(turtle.x) + max(turtle.thetta)
}
"""
TURTLE_MSG = "float32 x\nfloat32 y\nfloat32 theta\n\nfloat32 linear_velocity\nfloat32 angular_velocity\n"


def test_a_type_exsce_does_not_know_is_a_warning_at_its_read(tmp_path):
    analysis = _analysis(tmp_path, TURTLE)
    assert analysis.errors == []
    (warning,) = analysis.diagnostics
    assert warning.severity == "warning"
    assert (warning.location.line, warning.location.column) == (2, 3)
    assert warning.message.startswith("exsce does not know the message type turtlesim/msg/Pose: the fields of ")
    assert "in a folder EXSCE_MSG_PATH names, to check them now" in warning.message  # the library's words
    assert warning.remedied is not None  # what `exscec check` says, with its option:
    assert "exscec --msg-path DIR, or EXSCE_MSG_PATH" in warning.said(REMEDIES).message
    (metric,) = analysis.spec.metrics
    assert [(f.path.key, f.arrays, f.location.column) for f in metric.reads[0].fields] == [
        ("x", False, 13),
        ("thetta", False, 29),
    ]


def test_a_misspelt_standard_type_is_a_warning_with_a_did_you_mean(tmp_path):
    text = 'metric m for each robot {\n  reads v: std_msgs/Flaot64 on "/{ns}/v"\n  value max(v.data)\n}\n'
    analysis = _analysis(tmp_path, text)
    assert analysis.errors == []
    (warning,) = analysis.diagnostics
    assert (warning.location.line, warning.location.column, warning.severity) == (2, 3, "warning")
    assert "did you mean 'std_msgs/msg/Float64'?" in warning.message


def test_check_prints_the_warning_and_succeeds(tmp_path):
    (tmp_path / "m.exsce").write_text(TURTLE)
    done = exscec_here("check", "m.exsce", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "m.exsce:2:3: warning: exsce does not know the message type turtlesim/msg/Pose" in done.stderr
    assert "m.exsce: ok (0 scenarios)" in done.stderr


def test_ingest_checks_the_fields_against_the_bag_s_definition_at_their_places(tmp_path):
    (metric,) = _analysis(tmp_path, TURTLE).spec.metrics
    bag = parse_definition(TURTLE_MSG, "turtlesim/msg/Pose", "msg", Source("the bag"))
    tree = bag.tree("turtlesim/msg/Pose")
    (error,) = check_fields(metric, "turtlesim/Pose", tree)  # ROS 1's spelling is the same type
    assert (error.location.line, error.location.column) == (3, 29)
    assert error.message == "turtle (turtlesim/msg/Pose) has no field 'thetta'; did you mean 'theta'?"
    assert check_fields(metric, "turtlesim/msg/Other", tree) == []  # not the type it reads
    sourced = check_fields(metric, "turtlesim/msg/Pose", tree, source="the bag run.bag")
    assert sourced[0].message.endswith("(in the bag run.bag)")


def test_ingest_says_when_the_bag_makes_an_assumed_number_an_array(tmp_path):
    text = TURTLE.replace(" + max(turtle.thetta)", "")
    (metric,) = _analysis(tmp_path, text).spec.metrics
    bag = parse_definition("float32[] x\n", "turtlesim/msg/Pose", "msg", Source("the bag"))
    (error,) = check_fields(metric, "turtlesim/msg/Pose", bag.tree("turtlesim/msg/Pose"))
    assert (error.location.line, error.location.column) == (3, 13)
    assert error.message.startswith("turtle.x is an array per message by the definition of turtlesim/msg/Pose")


def test_ingest_gives_the_builder_s_own_messages(tmp_path, monkeypatch):
    """The same mistake, checked when the spec is (the user's .msg) or when the bag is read."""
    folder = tmp_path / "msgs"
    (folder / "turtlesim" / "msg").mkdir(parents=True)
    (folder / "turtlesim" / "msg" / "Pose.msg").write_text(TURTLE_MSG)
    (metric,) = _analysis(tmp_path, TURTLE).spec.metrics
    (at_ingest,) = check_fields(metric, "turtlesim/msg/Pose", user_catalogue([folder]).tree("turtlesim/msg/Pose"))
    monkeypatch.setenv("EXSCE_MSG_PATH", str(folder))
    (at_check,) = _analysis(tmp_path, TURTLE).diagnostics
    assert (at_check.severity, at_check.message, at_check.location) == (
        "error",
        at_ingest.message,
        at_ingest.location,
    )


# ------------------------------------------------------------------ the user's definitions
def _write(folder: Path, relative: str, text: str) -> Path:
    path = folder / relative
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


IDL = """\
module my_idl {
  module msg {
    struct Level {
      double value;
      sequence<double> samples;
    };
  };
};
"""


def test_user_definitions_come_from_msg_and_idl_files(tmp_path):
    _write(tmp_path, "a/robot_msgs/msg/Wheels.msg", "std_msgs/Header header\nWheel[4] wheels\n")
    _write(tmp_path, "a/robot_msgs/msg/Wheel.msg", "float64 speed\nstring name\n")
    _write(tmp_path, "a/loose_msgs/Battery.msg", "float32 percentage\n")
    _write(tmp_path, "a/idl/Level.idl", IDL)
    catalogue = user_catalogue([tmp_path / "a"])
    assert sorted(catalogue.definitions) == [
        "loose_msgs/msg/Battery",
        "my_idl/msg/Level",
        "robot_msgs/msg/Wheel",
        "robot_msgs/msg/Wheels",
    ]
    assert catalogue.source_of("robot_msgs/Wheel").text == str(tmp_path / "a/robot_msgs/msg/Wheel.msg")
    wheels = catalogue.layered(standard_catalogue()).tree("robot_msgs/msg/Wheels")
    assert set(wheels) == {"header", "wheels"} and wheels["wheels"].length == 4


def test_a_definition_that_does_not_parse_names_its_file(tmp_path):
    broken = _write(tmp_path, "robot_msgs/msg/Broken.msg", "float64[ speed\n")
    with pytest.raises(MessageTypeError) as raised:
        user_catalogue([tmp_path])
    assert str(broken) in raised.value.message


def test_the_configured_catalogue_puts_the_first_folder_first(tmp_path, monkeypatch):
    _write(tmp_path, "a/robot_msgs/msg/Thing.msg", "float64 from_a\n")
    _write(tmp_path, "b/robot_msgs/msg/Thing.msg", "float64 from_b\nfloat64 only_b\n")
    _write(tmp_path, "b/std_msgs/msg/Float64.msg", "float64 not_data\n")
    monkeypatch.setenv("EXSCE_MSG_PATH", f"{tmp_path / 'a'}:{tmp_path / 'b'}")
    catalogue = configured_catalogue()
    assert list(catalogue.tree("robot_msgs/msg/Thing")) == ["from_a"]
    assert list(catalogue.tree("std_msgs/msg/Float64")) == ["not_data"]  # the user's over the standard
    monkeypatch.delenv("EXSCE_MSG_PATH")
    assert "robot_msgs/msg/Thing" not in configured_catalogue()


def test_a_fixed_length_array_of_messages_has_its_elements_only(tmp_path, monkeypatch):
    _write(tmp_path, "msgs/robot_msgs/msg/Wheels.msg", "Wheel[4] wheels\n")
    _write(tmp_path, "msgs/robot_msgs/msg/Wheel.msg", "float64 speed\n")
    monkeypatch.setenv("EXSCE_MSG_PATH", str(tmp_path / "msgs"))
    text = 'metric m for each robot {\n  reads w: robot_msgs/Wheels on "/{ns}/wheels"\n  value max(w.wheels[4].speed)\n}\n'
    (error,) = _analysis(tmp_path, text).errors
    assert (error.location.line, error.location.column) == (3, 13)
    assert error.message == "w.wheels has 4 elements: [4] is not one of them"
    assert _analysis(tmp_path, text.replace("[4]", "[-4]")).errors == []


def test_a_broken_user_file_is_one_error_and_the_standard_types_still_check(tmp_path, monkeypatch):
    _write(tmp_path, "msgs/robot_msgs/msg/Broken.msg", "float64[ speed\n")
    monkeypatch.setenv("EXSCE_MSG_PATH", str(tmp_path / "msgs"))
    errors = _analysis(tmp_path, READS + "  value max(scan.rangez)\n}\n").errors
    assert len(errors) == 2, errors
    assert errors[0].location is None and "Broken.msg" in errors[0].message
    assert "did you mean 'ranges'?" in errors[1].message


def test_msg_path_goes_in_front_of_the_environment_s_folders(tmp_path, monkeypatch):
    _write(tmp_path, "a/turtlesim/msg/Pose.msg", TURTLE_MSG.replace("theta", "thetta"))
    _write(tmp_path, "b/turtlesim/msg/Pose.msg", TURTLE_MSG)
    (tmp_path / "m.exsce").write_text(TURTLE)
    monkeypatch.setenv("EXSCE_MSG_PATH", str(tmp_path / "b"))
    from_b = exscec_here("check", "m.exsce", cwd=tmp_path)
    assert from_b.returncode == 2 and "m.exsce:3:29: error: turtle (turtlesim/msg/Pose) has no field" in from_b.stderr
    from_a = exscec_here("--msg-path", "a", "check", "m.exsce", cwd=tmp_path)
    assert from_a.returncode == 0 and "warning" not in from_a.stderr, from_a.stderr
    helped = exscec_here("--help")
    assert "--msg-path DIR" in helped.stdout and "EXSCE_MSG_PATH" in helped.stdout


# ------------------------------------------------------------------ printed back
def test_every_path_prints_back_to_the_same_metric(tmp_path):
    value = " + ".join(f"max({written})" for written, _, _ in KINDS)
    value += ' + max(tf.transforms[child_frame_id == "a \\\\ \\"b\\" ]"].transform.translation.x)'
    value += " + max(diag.status_list[status == -2.5e-07].status)"
    (metric,) = _analysis(tmp_path, READS + f"  value {value}\n}}\n").spec.metrics
    printed = "\n".join(text for text, _ in metric_lines(metric))
    assert printed.splitlines()[-2] == f"  value {value}"
    (again,) = _analysis(tmp_path, printed + "\n").spec.metrics
    assert again == metric
    selected = metric.value.right.args[0].path.steps[1]
    assert selected == Select(("status",), -2.5e-7)


# ------------------------------------------------------------------ the live runtime
def _message() -> SimpleNamespace:
    def transform(child: str, x: float) -> SimpleNamespace:
        return SimpleNamespace(child_frame_id=child, header=SimpleNamespace(frame_id="map"),
                               transform=SimpleNamespace(translation=SimpleNamespace(x=x)))

    return SimpleNamespace(transforms=[transform("odom", 1.0), transform("base_link", 2.0)], ranges=(3.0, 4.0, 5.0))


@pytest.mark.parametrize(
    ("written", "value", "present"),
    [
        ('transforms[child_frame_id == "base_link"].transform.translation.x', 2.0, True),
        ('transforms[child_frame_id == "laser"].transform.translation.x', None, False),
        ('transforms[header.frame_id == "map"].child_frame_id', "odom", True),
        ("transforms[-1].transform.translation.x", 2.0, True),
        ("transforms[2].transform.translation.x", None, False),
        ("transforms.transform.translation.x", [1.0, 2.0], True),
        ("len(transforms)", 2, True),
        ("ranges[1]", 4.0, True),
        ("len(ranges)", 3, True),
    ],
)
def test_the_runtime_reads_paths_from_message_objects(written, value, present):
    assert monitor_runtime.attributes(written).read(_message()) == (value, present)


def test_the_runtime_keeps_a_mask_of_the_messages_with_the_picked_element():
    key = 'transforms[child_frame_id == "base_link"].transform.translation.x'
    spec = monitor_runtime.TopicSpec("tf2_msgs.msg.TFMessage", fields={key: key, "len(ranges)": "len(ranges)"})
    monitors = SimpleNamespace(core=SimpleNamespace(Topic=lambda name, t, fields: fields), REDUCERS=[])
    runtime = monitor_runtime.MonitorRuntime(monitors, [], {"/tf": spec}, [])
    runtime.on_message("/tf", 1.0, _message())
    runtime.on_message("/tf", 2.0, SimpleNamespace(transforms=[], ranges=()))
    fields = runtime.buffers["/tf"].topic(monitors.core, "/tf")
    assert fields[key][0] == 2.0 and fields[key + "#present"].tolist() == [True, False]
    assert fields["len(ranges)"].tolist() == [3.0, 0.0]
    assert runtime.problems == {}


def test_rospy_names_a_time_s_fields_its_own_way_along_any_path():
    tree = standard_catalogue().tree("tf2_msgs/msg/TFMessage")
    path = FieldPath(("transforms", Select(("header", "stamp", "sec"), 3.0), "header", "stamp", "nanosec"))
    assert attribute_path(path, tree) == "transforms[header.stamp.secs == 3].header.stamp.nsecs"
    plain = FieldPath(("transforms", Index(0), "transform", "translation", "x"))
    assert attribute_path(plain, tree) == plain.key
    assert attribute_path(FieldPath(("header", "stamp", "sec")), None) == "header.stamp.secs"  # a type unknown


def test_a_node_subscribes_with_the_keys_and_attributes_of_every_path(tmp_path):
    text = READS + (
        '  value max(tf.transforms[child_frame_id == "base_link"].header.stamp.sec)'
        " + max(tf.transforms.transform.translation.x) + max(len(diag.status_list))\n}\n"
    )
    metrics = _analysis(tmp_path, text).spec.metrics
    ros1, ros2 = (monitor_topics(metrics, [("r1", "r1")], ros) for ros in (1, 2))
    selected = 'transforms[child_frame_id == "base_link"].header.stamp.sec'
    assert ros1["/r1/tf"].fields == {
        selected: 'transforms[child_frame_id == "base_link"].header.stamp.secs',
        "transforms.transform.translation.x": "transforms.transform.translation.x",
    }
    assert ros2["/r1/tf"].fields[selected] == selected
    assert ros1["/r1/tf"].arrays == ["transforms.transform.translation.x"]
    assert ros1["/r1/status"].fields == {"len(status_list)": "len(status_list)"}


# ------------------------------------------------------------------ the editor
def test_completion_offers_the_fields_at_the_path_before_the_point():
    def labels(text: str, typed: str = "") -> dict[str, str]:
        offer = offers(text + typed, len(text + typed), len(text), False)
        assert offer is not None and offer.start == len(text)
        return {label: detail for label, _, detail in offer.items}

    assert labels(READS + "  value max(odom.pose.pose.", "po") == {
        "position": "geometry_msgs/msg/Point (geometry_msgs/msg/Pose)",
        "orientation": "geometry_msgs/msg/Quaternion (geometry_msgs/msg/Pose)",
    }
    assert set(labels(READS + "  value max(tf.transforms.")) == {"header", "child_frame_id", "transform"}
    assert set(labels(READS + "  value max(tf.transforms[-1].transform.")) == {"translation", "rotation"}
    assert set(labels(READS + "  value max(tf.transforms[header.")) == {"stamp", "frame_id"}
    assert labels(READS + "  value max(scan.")["ranges"] == "float32[] (sensor_msgs/msg/LaserScan)"
    assert labels(READS + "  value max(")["odom"] == "nav_msgs/msg/Odometry on /{ns}/odom"
    assert offers(READS + "  value max(scan.ranges[0].", 0, 0, False) is None  # a number has no fields


def test_completion_of_a_message_type_replaces_what_is_typed():
    text = "metric m for each robot {\n  reads odom: nav_msgs/msg/Od"
    offer = offers(text, len(text), len(text) - 2, True)
    assert offer is not None and offer.start == text.index("nav_msgs")
    assert ("nav_msgs/msg/Odometry", "type", "message type") in offer.items


def test_hover_shows_a_field_s_type_and_a_read_s():
    text = READS + '  value max(tf.transforms[child_frame_id == "a"].transform.translation.x)\n}\n'
    at = text.index("translation")
    assert field_hover(text, at, at + len("translation")) == (
        "**field** `tf.transforms.transform.translation`: `geometry_msgs/msg/Vector3`, of "
        "`geometry_msgs/msg/Transform`"
    )
    at = text.index("tf.transforms[")
    assert field_hover(text, at, at + 2) == "**topic** `tf`: `tf2_msgs/msg/TFMessage` on `/{ns}/tf`"
    assert field_hover(text, text.index("max"), text.index("max") + 3) is None


def test_check_says_the_unknown_type_s_remedy_with_its_option(tmp_path, monkeypatch):
    """The library says the remedy in words; `exscec check` says it with its option (issue 49)."""
    monkeypatch.delenv("EXSCE_MSG_PATH", raising=False)
    (tmp_path / "m.exsce").write_text(TURTLE)
    done = exscec_here("check", "m.exsce", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (
        "m.exsce:2:3: warning: exsce does not know the message type turtlesim/msg/Pose: the fields of "
        "turtle are checked when a bag is read, against the bag's definition (to check them now, give "
        "exsce the type's .msg or .idl file: exscec --msg-path DIR, or EXSCE_MSG_PATH)"
    ) in done.stderr
