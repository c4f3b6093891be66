"""``exscec generate ros1-monitor`` and ``ros2-monitor``: a runtime monitor node for one scenario.

Each target writes a ROS package (``exsce_monitor_<scenario>``: catkin and rospy
for ROS 1, ament_python and rclpy for ROS 2) whose node subscribes to the
topics the metrics read, computes the metrics live and publishes the verdicts
of the scenario's oracles that the specification alone decides.  Almost all of
it is plain Python shared with exsce and tested here without ROS: the
generated monitor classes (``monitors.py``, the code ingestion runs), a copy
of the metric core and of :mod:`exsce_dsl.monitor_kit.monitor_runtime`, and a
generated ``config.py`` (robots, topics, oracles).  Only the node, a few
dozen lines of rospy or rclpy, differs between the two.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any

from exsce_dsl.codegen.output import write_files
from exsce_dsl.errors import GenerationError, MessageTypeError, SourceLocation
from exsce_dsl.lang import expectation_text, standard_metrics
from exsce_dsl.messages.user import configured_catalogue
from exsce_dsl.model import Scenario, Specification
from exsce_dsl.model.acceptance import BasicRelation
from exsce_dsl.model.conventions import DISPATCHER_FEEDBACK, DISPATCHER_RESULT, METHOD
from exsce_dsl.model.expressions import Field, walk
from exsce_dsl.model.messages import (
    FEEDBACK,
    RESULT,
    FieldPath,
    Fields,
    MessageArray,
    Node,
    Select,
    Step,
    canonical_type,
)
from exsce_dsl.model.metrics import ComputedFor, MetricDefinition, TopicRead, expand_topic
from exsce_dsl.model.names import ROS_TOPIC_RULE, is_ros_topic
from exsce_dsl.monitor_code import monitor_source
from exsce_dsl.oracles import PlannedOracle, plan_oracles
from exsce_dsl.prov.identifiers import oracle_name
from exsce_dsl.resources import package_file
from exsce_dsl.templating import python_name, python_string, render

FEEDBACK_TOPIC, RESULT_TOPIC = DISPATCHER_FEEDBACK, DISPATCHER_RESULT
"""The dispatcher's topics, where ingestion takes each robot's windows and successes from."""
VERDICT_TOPIC = "/exsce/verdicts"
_ROS_PACKAGE = re.compile(r"[a-z][a-z0-9]*(?:_[a-z0-9]+)*")
"""REP 144: lowercase letters, digits and single underscores, starting with a letter."""
_ROSPY_TIME = {"sec": "secs", "nanosec": "nsecs"}
"""rospy's names of the fields of a time or a duration, which ROS 2 (and exsce's paths) name
otherwise."""
_COPIED = ("monitor_core.py", "monitor_runtime.py")
_POSE_AXES = ("x", "y", "z")
_POSE_AT = ("pose", "pose", "position")
"""Where the method's pose (``PoseWithCovarianceStamped``) holds a position."""


@dataclass
class TopicEntry:
    """One subscription of the node: its message type and what the runtime takes from it."""

    msgtype: str
    role: str = "data"
    robot: str | None = None
    fields: dict[str, str] = field(default_factory=dict)
    arrays: list[str] = field(default_factory=list)
    signals: list[str] = field(default_factory=list)
    """The robot's signals (``/r1/~pose``) the monitors read from this topic, by those names."""

    @property
    def python_type(self) -> str:
        """``geometry_msgs/msg/Twist`` → ``geometry_msgs.msg.Twist`` (the same in rospy and rclpy)."""
        package, _, name = canonical_type(self.msgtype).partition("/msg/")
        return ".".join(python_name(part) for part in (package, "msg", name))

    @property
    def package(self) -> str:
        return self.python_type.split(".")[0]


@dataclass(frozen=True)
class LiveOracle:
    """An oracle as ``config.py`` holds it; ``reason`` says why one is not judged live."""

    oracle: str
    criterion: str
    clause: str
    robot: str | None
    metric: str
    relation: str = ""
    limit: float | None = None
    value: float | None = None
    tolerance: float | None = None
    reason: str = ""


def package_name(scenario_id: str, location: SourceLocation | None = None) -> str:
    """``exsce_monitor_<id>``, lowercase, '-' as '_'; an error (at ``location``, the scenario's)
    if that is no ROS package name."""
    name = f"exsce_monitor_{scenario_id.lower().replace('-', '_')}"
    if not _ROS_PACKAGE.fullmatch(name):
        raise GenerationError(
            f"scenario id '{scenario_id}' cannot name a ROS package: '{name}' must be lowercase letters, "
            "digits and single underscores (REP 144); rename the scenario",
            location,
        )
    return name


def monitor_topics(
    metrics: Sequence[MetricDefinition], robots: Sequence[tuple[str, str]], ros: int
) -> dict[str, TopicEntry]:
    """Topic → subscription, for every field a metric reads of each robot, and the dispatcher's."""
    topics: dict[str, TopicEntry] = {}
    trees: dict[str, Fields | None] = {}

    def add(topic: str, entry: TopicEntry, by: str, where: SourceLocation | None = None) -> TopicEntry:
        if not is_ros_topic(topic):
            said = f"'{topic}' (read by {by}) is not a ROS topic name ({ROS_TOPIC_RULE})"
            raise GenerationError(said, where)
        found = topics.setdefault(topic, entry)
        if (found.role, found.robot) != (entry.role, entry.robot):
            raise GenerationError(
                f"topic {topic} is read both as {found.role} of {found.robot or 'a metric'} and as "
                f"{entry.role} of {entry.robot or 'a metric'}: do two robots share a namespace?"
            )
        if found.msgtype != entry.msgtype:
            raise GenerationError(
                f"topic {topic} is read as {entry.msgtype} by {by}, but as {found.msgtype} "
                "elsewhere: a node subscribes to a topic with one type"
            )
        return found

    for robot, ns in robots:
        dispatcher = ((FEEDBACK_TOPIC, FEEDBACK, "feedback"), (RESULT_TOPIC, RESULT, "result"))
        for pattern, msgtype, role in dispatcher:
            add(expand_topic(pattern, ns), TopicEntry(msgtype, role, robot), "the dispatcher")
        for metric in metrics:
            reads = {r.name: r for r in metric.reads}
            expressions = [e for e in (metric.value, metric.fallback) if e is not None]
            for node in [n for e in expressions for n in walk(e)]:
                if not isinstance(node, Field):
                    continue
                read = reads[node.read]
                topic, msgtype, path = read.topic_of(ns), canonical_type(read.msgtype), node.path
                if read.signal:  # live: the method's topic for the signal (its convention's)
                    topic, msgtype, path = _method_signal(metric, read, path, ns)
                entry = add(topic, TopicEntry(msgtype), f"metric {metric.name}", read.location)
                if read.signal:
                    entry.signals = sorted({*entry.signals, read.topic_of(ns)})
                if entry.msgtype not in trees:
                    trees[entry.msgtype] = _tree(entry.msgtype)
                key = node.path.key
                entry.fields[key] = attribute_path(path, trees[entry.msgtype]) if ros == 1 else path.key
                if node.arrays and key not in entry.arrays:
                    entry.arrays.append(key)
    for entry in topics.values():
        entry.fields = dict(sorted(entry.fields.items()))
        entry.arrays.sort()
    return dict(sorted(topics.items()))


def _method_signal(
    metric: MetricDefinition, read: TopicRead, path: FieldPath, namespace: str
) -> tuple[str, str, FieldPath]:
    """Where a live monitor reads a robot's signal: the topic and type of the method's convention
    (:data:`~exsce_dsl.model.conventions.METHOD`, which the robots a monitor watches publish), and
    the field of its message that holds ``path``; a pose's yaw is no field of it: an error."""
    (source,) = getattr(METHOD, str(read.signal))
    msgtype = canonical_type(source.msgtype or "")
    if read.signal != "pose":
        return expand_topic(source.topic, namespace), msgtype, path
    if path.picks or len(path.steps) != 1 or path.steps[0] not in _POSE_AXES:
        raise GenerationError(
            f"metric '{metric.name}' reads the robot's pose.{path.key}: live monitors read a pose's "
            f"position ({', '.join('pose.' + a for a in _POSE_AXES)}) from {msgtype}; its yaw is "
            "computed at ingest only",
            read.location,
        )
    return expand_topic(source.topic, namespace), msgtype, FieldPath((*_POSE_AT, *path.steps), path.length)


def attribute_path(path: FieldPath, tree: Fields | None) -> str:
    """The attributes that hold ``path`` in a rospy message object, written as the path's key:
    rospy names a time's fields ``secs`` and ``nsecs``.  Without the type's fields (a type
    only the robot knows), a ``stamp``'s are taken for a time's."""
    node: Node | None = tree
    steps: list[Step] = []
    previous = ""
    for step in path.steps:
        if isinstance(step, str):
            renamed, node = _rospy_name(step, node, previous)
            steps.append(renamed)
            previous = step
            continue
        node = node.element if isinstance(node, MessageArray) else None
        if isinstance(step, Select):
            names: list[str] = []
            inner: Node | None = node
            before = ""
            for name in step.field:
                renamed, inner = _rospy_name(name, inner, before)
                names.append(renamed)
                before = name
            step = Select(tuple(names), step.value)
        steps.append(step)
    return FieldPath(tuple(steps), path.length).key


def _rospy_name(name: str, node: Node | None, previous: str) -> tuple[str, Node | None]:
    """rospy's name of field ``name`` of ``node`` (or of each of its elements), and the field."""
    if isinstance(node, MessageArray):
        node = node.element
    if isinstance(node, dict):
        time = set(node) == set(_ROSPY_TIME)
        return (_ROSPY_TIME.get(name, name) if time else name), node.get(name)
    return (_ROSPY_TIME.get(name, name) if previous == "stamp" else name), None


def _tree(msgtype: str) -> Fields | None:
    try:
        return configured_catalogue().tree(msgtype)
    except MessageTypeError:
        return None


def live_oracles(
    spec: Specification, scenario: Scenario, metrics: Sequence[MetricDefinition]
) -> tuple[list[LiveOracle], list[LiveOracle]]:
    """The scenario's oracles the node judges (fixed limits, invariants around a fixed value within
    an absolute or % tolerance), and the others with the reason they are not judged live."""
    acceptance = spec.acceptance_of(scenario.id)
    if acceptance is None:
        return [], []
    robot_metrics = {m.name for m in metrics if m.subject is ComputedFor.ROBOT}
    mission_metrics = {m.name for m in metrics if m.subject is not ComputedFor.ROBOT}
    monitored = {r.id for r in scenario.robots if r.start_pose is not None}
    judged: list[LiveOracle] = []
    others: list[LiveOracle] = []
    for planned in plan_oracles(acceptance, scenario):
        e = planned.expectation
        name = oracle_name(planned.metric, planned.robot)
        oracle = LiveOracle(
            name if planned.window is None else f"{name}-{planned.window.text().replace(' ', '-')}",
            planned.criterion,
            expectation_text(e),
            planned.robot,
            planned.metric,
            e.relation.value,
        )
        reason = _not_live(planned, robot_metrics, mission_metrics, monitored)
        if reason:
            others.append(dataclasses.replace(oracle, reason=reason))
        elif e.limit is not None:
            judged.append(dataclasses.replace(oracle, limit=e.limit.value))
        else:
            assert e.value is not None
            tolerance = None if e.tolerance is None else e.tolerance.value
            if e.tolerance is not None and e.tolerance.unit == "%":
                tolerance = e.tolerance.value / 100.0 * abs(e.value.value)
            judged.append(dataclasses.replace(oracle, value=e.value.value, tolerance=tolerance))
    return judged, others


def _not_live(
    planned: PlannedOracle, robot_metrics: set[str], mission_metrics: set[str], monitored: set[str]
) -> str:
    e = planned.expectation
    if planned.window is not None:
        return f"it looks at part of a run ({planned.window.text()}): only whole runs are judged live"
    if e.relation in (BasicRelation.INCREASING, BasicRelation.DECREASING):
        return f"relation {e.relation.value}: only limits and invariants around a fixed value are judged live"
    fixed_value = e.value is not None and (e.tolerance is None or e.tolerance.unit != "std")
    if e.limit is None and not fixed_value:
        return "its expected value or tolerance comes from stored baseline runs: `exscec verify` judges it"
    known = mission_metrics if planned.robot is None else robot_metrics
    if planned.metric not in known:
        return f"{planned.metric} is computed at ingest only, not by the monitor classes"
    if planned.robot is not None and planned.robot not in monitored:
        return f"robot '{planned.robot}' has no start pose: exsce computes no metrics for it"
    return ""


def _context(spec: Specification, scenario_id: str | None, ros: int) -> tuple[dict[str, Any], str]:
    scenario = spec.scenario(scenario_id)
    package = package_name(scenario.id, scenario.location)
    metrics = standard_metrics() + spec.metrics
    robots = [(r.id, r.namespace.strip("/")) for r in scenario.robots if r.start_pose is not None]
    judged, others = live_oracles(spec, scenario, metrics)
    topics = monitor_topics(metrics, robots, ros)
    source = Path(spec.root).name
    generator = f"exscec generate ros{ros}-monitor"
    quoted = python_string(source), python_string(scenario.id)
    header = f"Generated by exsce ({generator}) from {quoted[0]}, scenario {quoted[1]}"
    msg_packages = sorted({entry.package for entry in topics.values()} | {"std_msgs"})
    context = {
        "ros": ros,
        "package": package,
        "scenario": scenario.id,
        "source": source,
        "generator": generator,
        "header": header,
        "robots": robots,
        "topics": topics,
        "oracles": judged,
        "not_judged": others,
        "msg_packages": msg_packages,
        "verdict_topic": VERDICT_TOPIC,
    }
    return context, monitor_source(metrics, source, "from . import monitor_core as core")


def _copied() -> dict[str, str]:
    return {name: package_file("monitor_kit", name).read_text(encoding="utf-8") for name in _COPIED}


def ros1_monitor_files(spec: Specification, scenario_id: str | None) -> dict[str, str]:
    """The ROS 1 package's files (relative path → text), below a folder named after the package."""
    context, monitors = _context(spec, scenario_id, 1)
    pkg = context["package"]
    python = f"{pkg}/src/{pkg}"
    files = {
        f"{pkg}/package.xml": render("ros1_monitor/package.xml.j2", **context),
        f"{pkg}/CMakeLists.txt": render("ros1_monitor/CMakeLists.txt.j2", **context),
        f"{pkg}/setup.py": render("ros1_monitor/setup.py.j2", **context),
        f"{pkg}/README.md": render("ros1_monitor/README.md.j2", **context),
        f"{pkg}/scripts/exsce_monitor_node": render("ros1_monitor/exsce_monitor_node.j2", **context),
        f"{pkg}/launch/exsce_monitor.launch": render("ros1_monitor/exsce_monitor.launch.j2", **context),
        f"{python}/__init__.py": render("ros_monitor/__init__.py.j2", **context),
        f"{python}/config.py": render("ros_monitor/config.py.j2", **context),
        f"{python}/monitors.py": monitors,
    }
    return files | {f"{python}/{name}": text for name, text in _copied().items()}


def ros2_monitor_files(spec: Specification, scenario_id: str | None) -> dict[str, str]:
    """The ROS 2 package's files (relative path → text), below a folder named after the package."""
    context, monitors = _context(spec, scenario_id, 2)
    pkg = context["package"]
    python = f"{pkg}/{pkg}"
    files = {
        f"{pkg}/package.xml": render("ros2_monitor/package.xml.j2", **context),
        f"{pkg}/setup.py": render("ros2_monitor/setup.py.j2", **context),
        f"{pkg}/setup.cfg": render("ros2_monitor/setup.cfg.j2", **context),
        f"{pkg}/README.md": render("ros2_monitor/README.md.j2", **context),
        f"{pkg}/resource/{pkg}": "",  # ament's marker of an installed package: empty by convention
        f"{pkg}/launch/exsce_monitor.launch.py": render("ros2_monitor/exsce_monitor.launch.py.j2", **context),
        f"{python}/__init__.py": render("ros_monitor/__init__.py.j2", **context),
        f"{python}/node.py": render("ros2_monitor/node.py.j2", **context),
        f"{python}/config.py": render("ros_monitor/config.py.j2", **context),
        f"{python}/monitors.py": monitors,
    }
    return files | {f"{python}/{name}": text for name, text in _copied().items()}


def generate_ros1_monitor(
    spec: Specification, scenario_id: str | None, out_dir: Path, overwrite: bool = False
) -> list[Path]:
    """Write the ROS 1 (catkin, rospy) monitor package of the scenario below ``out_dir``."""
    files = ros1_monitor_files(spec, scenario_id)
    scripts = [name for name in files if PurePosixPath(name).parent.name == "scripts"]
    return write_files(out_dir, files, overwrite, executable=scripts)  # rosrun runs the node script itself


def generate_ros2_monitor(
    spec: Specification, scenario_id: str | None, out_dir: Path, overwrite: bool = False
) -> list[Path]:
    """Write the ROS 2 (ament_python, rclpy) monitor package of the scenario below ``out_dir``."""
    return write_files(out_dir, ros2_monitor_files(spec, scenario_id), overwrite)
