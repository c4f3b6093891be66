"""Identifier rules of exsce's PROV: the namespaces of one project, local names, the escaping
of names from outside, and prefix names.

Identifiers follow the published models, with two deliberate differences
where the published rule loses information:

* pose and orientation ids write each angle with two decimals only when that
  is exact, and otherwise with Python's shortest round-trip form
  (:func:`format_angle`), so that two different poses never share an id;
* task ids are the DSL task ids (``task:delivery_a``), not the task file's
  basename (``task:delivery_a.yaml``), which collides across environments;
* a robot whose namespace is not its id (``root_robot`` at the root, ``r1`` in
  ``/lab/r1``) is named by its id and a digest of what its bundle says
  (:func:`robot_name`), so two scenarios may each have a robot of that id.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from urllib.parse import unquote_to_bytes

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.geometry import Orientation, Pose
from exsce_dsl.model.robots import Robot
from exsce_dsl.prov.identifiers.terms import (
    ANGLE,
    COORD,
    DEFAULT_NAMESPACE,
    ENV,
    EXSCE,
    GEOM,
    HOTSPOT,
    METRIC,
    MISSION,
    ORACLE,
    ORIENTATION,
    POINT,
    POSE,
    PROV_NAMESPACE,
    ROBOT,
    ROBOT_SCHEMA,
    ROS,
    ROS_WIKI,
    RUN,
    SEGMENT,
    STANDARD_PREFIXES,
    TASK,
    TOPIC,
    Term,
)


@dataclass(frozen=True)
class Namespaces:
    """The namespace IRIs of one project, all but the fixed ones under ``base``."""

    base: str = DEFAULT_NAMESPACE

    def __post_init__(self) -> None:
        if not re.fullmatch(r"[A-Za-z][A-Za-z0-9+.\-]*:[^\s<>\"{}|\\^`]*[/#]", self.base):
            raise ExsceError(f"namespace '{self.base}' is not an absolute IRI ending in '/' or '#'")

    @property
    def fixed(self) -> dict[str, str]:
        """Prefix name → IRI of every fixed namespace, in the published order."""
        base = self.base
        return {
            EXSCE: base,
            MISSION: f"{base}missions/",
            ENV: f"{base}environments/",
            ROBOT: f"{base}robots/",
            TASK: f"{base}tasks/",
            POSE: f"{base}tasks/waypoints/",
            POINT: f"{base}tasks/points/",
            ORIENTATION: f"{base}tasks/orientation/",
            ORACLE: f"{base}oracles/",
            GEOM: ROBOT_SCHEMA,
            COORD: f"{ROBOT_SCHEMA}coordinates/",
            ANGLE: f"{ROBOT_SCHEMA}rotation/",
            ROS: ROS_WIKI,
            RUN: f"{base}runs/",
            TOPIC: f"{base}topics/",
            HOTSPOT: f"{base}hotspots/",
            SEGMENT: f"{base}segments/",
            METRIC: f"{base}metrics/",
        }

    def iri(self, term: Term) -> str:
        """The full IRI of a term of a fixed (or the prov) namespace."""
        if term.prefix == "prov":
            return PROV_NAMESPACE + term.local
        return self.fixed[term.prefix] + term.local

    # Per-element namespaces: the names an element's parts live in.

    def of_scenario(self, scenario_id: str) -> str:
        return f"{self.base}{scenario_id}/"

    def of_mission(self, mission_id: str) -> str:
        return f"{self.base}missions/{mission_id}/"

    def of_environment(self, environment_id: str) -> str:
        return f"{self.base}environments/{environment_id}/"

    def of_robot(self, robot_id: str) -> str:
        return f"{self.base}robots/{robot_id}/"

    def of_subtask(self, task_id: str, index: int) -> str:
        return f"{self.base}tasks/{subtask_name(task_id, index)}/"

    def of_run(self, run_uuid: str) -> str:
        """The namespace of a run's parts: ``<base>runs/run_<uuid>/``."""
        return f"{self.base}runs/{run_local_name(run_uuid)}/"


# Local names.  Each function returns the part after the prefix.


def format_angle(value: float) -> str:
    """An angle as it appears in pose and orientation ids.

    Two decimals where that is exact (``0.0 → 0.00``, ``2.27 → 2.27``), as the
    method writes them; otherwise the shortest form that reads back as the same
    float (``0.925 → 0.925``), where the method rounded and merged poses.
    """
    value = float(value)
    if value == 0.0:
        value = 0.0  # no separate id for -0.0
    if round(value, 2) == value:
        return f"{value:.2f}"
    return repr(value)


def orientation_name(orientation: Orientation) -> str:
    """``R<roll>_P<pitch>_Y<yaw>``, the local name in ``orientation:``."""
    return (
        f"R{format_angle(orientation.roll)}"
        f"_P{format_angle(orientation.pitch)}"
        f"_Y{format_angle(orientation.yaw)}"
    )


def pose_name(pose: Pose) -> str:
    """``<pose id>-R.._P.._Y..``, the local name in ``pose:``."""
    return f"{pose.id}-{orientation_name(pose.orientation)}"


def point_name(pose: Pose) -> str:
    """The local name in ``point:``: the pose id (its position, whatever its heading)."""
    return pose.id


def subtask_name(task_id: str, index: int) -> str:
    """``<task>-subtask_NNN`` (1-based), in ``task:``; also its own namespace's name."""
    return f"{task_id}-subtask_{index:03d}"


def subtask_role(index: int) -> str:
    return f"subtask_{index:03d}"


def waypoint_relation_name(index: int) -> str:
    """``w_NNN`` (1-based), in the subtask's namespace: the waypoint derivation's id."""
    return f"w_{index:03d}"


def allocation_name(robot_id: str, index: int) -> str:
    """``<robot>-task_NN`` (1-based per robot), in the mission's namespace."""
    return f"{robot_id}-task_{index:02d}"


def start_pose_relation_name(robot_id: str) -> str:
    """``<robot>-start-pose``, in the scenario's namespace."""
    return f"{robot_id}-start-pose"


def map_entity_name(map_name: str) -> str:
    """``<map>_map``, in the environment's namespace."""
    return f"{map_name}_map"


def obstacle_pose_relation_name(obstacle_id: str) -> str:
    """``<obstacle>-pose``, in the environment's namespace."""
    return f"{obstacle_id}-pose"


def robot_name(robot: Robot) -> str:
    """The local name of ``robot`` in ``robot:`` and its namespace of parts.

    The method names a robot by its id alone (``robot:tiago1``, namespace ``tiago1``): a
    robot is known by the namespace its topics are under, and that is its id.  So is a robot
    here whose namespace is its id (``/`` aside).  Any other robot (``root_robot`` at the
    root, ``r1`` in ``/lab/r1``) is ``<id>.<8 hex digits>``: the sha256 of its namespace, type
    and hardware, so scenarios that give one id to different robots never share a robot, and
    those that declare the same robot do.  Ids hold no ``.``, so the id is the part before it.
    """
    if robot.namespace.strip("/") == robot.id:
        return robot.id
    said = "\n".join((robot.namespace, robot.type.id, robot.type.base or "", str(robot.type.torso)))
    return f"{robot.id}.{hashlib.sha256(said.encode('utf-8')).hexdigest()[:8]}"


def robot_id_of_name(local: str) -> str:
    """The robot id in a local name :func:`robot_name` made."""
    return local.split(".", 1)[0]


def bundle_name(element_id: str) -> str:
    """``<id>_bundle``: the bundle of a scenario, environment, area, robot or task."""
    return f"{element_id}_bundle"


# Checked names, and the names of runs and their parts.

_SAFE_NAME = re.compile(r"[A-Za-z0-9_](?:[A-Za-z0-9_.\-]*[A-Za-z0-9_\-])?")


def is_name(name: str) -> bool:
    """Whether ``name`` can be a local name and a part of an IRI as it is."""
    return _SAFE_NAME.fullmatch(name) is not None


def check_name(name: str, what: str) -> str:
    """``name`` if it can be a local name and a part of an IRI as it is; else an ExsceError."""
    if not _SAFE_NAME.fullmatch(name):
        raise ExsceError(
            f"{what} '{name}' cannot be part of an identifier; use letters, digits, '_', '-' and '.'"
        )
    return name


def run_local_name(run_uuid: str) -> str:
    """``run_<uuid>``, in ``run:``: the run activity; ``run_<uuid>_bundle`` is its bundle."""
    return f"run_{check_name(run_uuid, 'run uuid')}"


def run_prefix(run_uuid: str) -> str:
    """The preferred prefix name of a run's namespace: ``run_`` and the uuid's first eight characters."""
    return f"run_{run_uuid[:8]}"


def task_execution_name(robot_id: str, allocation: int) -> str:
    """``<robot>-task_NN``, in the run's namespace: the robot's NN-th task (1-based)."""
    return allocation_name(robot_id, allocation)


def action_name(robot_id: str, allocation: int, subtask: int, waypoint: int) -> str:
    """``<robot>-task_NN-subtask_NNN-w_NNN``, in the run's namespace: one waypoint goal."""
    task = allocation_name(robot_id, allocation)
    return f"{task}-{subtask_role(subtask)}-{waypoint_relation_name(waypoint)}"


# A name from outside (a bag's topic, a bag file's name) becomes a local name by escaping:
# what a PROV-N local name and an IRI path segment both allow stays, anything else is
# percent-encoded (UTF-8), so that any name has an identifier and the identifier gives the
# name back.  '/' stays in topics; '.' and '-' cannot start a local name, a '.' cannot end one
# nor start a path segment (``a/./b`` would lose a level when an IRI is resolved).
_KEPT = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-.")
_RELATIVE = "@"
"""Starts the local name of a topic not written ``/name``: ``groundtruth`` is ``topic:@groundtruth``."""


def escape_name(name: str, keep_slash: bool = False) -> str:
    """``name`` as a local name and a path segment (``/`` kept with ``keep_slash``); see
    :func:`unescape_name`."""
    out: list[str] = []
    for i, char in enumerate(name):
        segment_start = i == 0 or name[i - 1] == "/"
        kept = char in _KEPT or (keep_slash and char == "/")
        if char == "." and (segment_start or i == len(name) - 1) or char == "-" and i == 0:
            kept = False
        out.append(char if kept else "".join(f"%{b:02X}" for b in char.encode("utf-8", "surrogatepass")))
    return "".join(out)


def unescape_name(local: str) -> str:
    """The name :func:`escape_name` made ``local`` of."""
    return unquote_to_bytes(local).decode("utf-8", "surrogatepass")


def topic_local_name(topic: str) -> str:
    """The local name in ``topic:`` of a topic, as a bag spells it, whatever its characters.

    An absolute name loses its first ``/`` (``/tiago1/nav_vel`` is ``topic:tiago1/nav_vel``,
    the IRI ``<base>topics/tiago1/nav_vel``); any other name (``groundtruth``, ``/``,
    ``//x``) starts with ``@``; characters an identifier cannot hold are percent-encoded
    (``ORB SLAM`` is ``@ORB%20SLAM``).  :func:`topic_of_name` reverses it."""
    if topic.startswith("/") and len(topic) > 1 and topic[1] != "/":
        return escape_name(topic[1:], keep_slash=True)
    return _RELATIVE + escape_name(topic, keep_slash=True)


def topic_of_name(local: str) -> str:
    """The topic whose local name in ``topic:`` is ``local`` (see :func:`topic_local_name`)."""
    if local.startswith(_RELATIVE):
        return unescape_name(local[len(_RELATIVE) :])
    return "/" + unescape_name(local)


def bag_name(file_name: str) -> str:
    """The local name of a bag, from its file's name (escaped as :func:`escape_name` says)."""
    return escape_name(file_name)


def clock_name(topic: str) -> str:
    """``clock-<topic>``, in the run's namespace: which clock the bag's ``topic`` was timed by."""
    return f"clock-{topic_local_name(topic)}"


def convention_name(robot_id: str) -> str:
    """``<robot>-convention``, in the run's namespace: the convention detected for the robot."""
    return f"{robot_id}-convention"


def metric_value_name(metric: str, subject: str | None) -> str:
    """``<subject>-<metric>`` (subject: a robot or an action's name), or ``<metric>`` for the mission."""
    check_name(metric, "metric")
    return metric if subject is None else f"{subject}-{metric}"


def topics_collection_name(metric: str, robot_id: str | None) -> str:
    """``<robot>-<metric>-topics`` (``<metric>-topics`` for the mission): the topics a metric used."""
    return f"{metric_value_name(metric, robot_id)}-topics"


def coverage_name(index: int) -> str:
    """``coverage-NNN`` (1-based), in the run's namespace: one thing its recording does not cover."""
    return f"coverage-{index:03d}"


def problem_name(index: int) -> str:
    """``problem-NNN`` (1-based), in the run's namespace: one thing ingestion said of the run."""
    return f"problem-{index:03d}"


def sample_count_name(value_name: str, index: int) -> str:
    """``<value>-samples_N`` (1-based), in the run's namespace: the samples one source gave a value."""
    return f"{value_name}-samples_{index}"


def rate_name(index: int) -> str:
    """``rate-NNN`` (1-based), in the run's namespace: how densely one topic was recorded."""
    return f"rate-{index:03d}"


def hotspot_name(metric: str, robot_id: str | None, index: int) -> str:
    """``[<robot>-]<metric>-hotspot_NNN`` (1-based), in the run's namespace."""
    return f"{metric_value_name(metric, robot_id)}-hotspot_{index:03d}"


def oracle_name(metric: str, robot_id: str | None) -> str:
    """``<robot>-<metric>`` or ``<metric>`` (mission), in the judged scenario's namespace."""
    return metric_value_name(metric, robot_id)


def transformation_step_name(index: int, transformation: str) -> str:
    """``step_NN-<transformation>`` (1-based), in the new scenario's namespace."""
    return f"step_{index:02d}-{check_name(transformation, 'transformation')}"


# Prefix names.

_PREFIX_RE = re.compile(r"[A-Za-z](?:[A-Za-z0-9_.\-]*[A-Za-z0-9_\-])?")


def is_valid_prefix(name: str) -> bool:
    """True if ``name`` can be a prefix in PROV-N, PROV-XML, Turtle and SPARQL."""
    return bool(_PREFIX_RE.fullmatch(name)) and not name.lower().startswith("xml")


class PrefixTable:
    """Prefix names for the namespaces of one document.

    The fixed prefixes are taken first.  A per-element namespace asks for its
    element's id as prefix name (``tiago1:``); when that name is taken by
    another namespace (a robot called ``pose``) or cannot be a prefix, it gets
    ``<id>_<kind>`` (``pose_robot:``), then ``<id>_<kind>2`` and so on.  Prefix
    names are cosmetic: the IRIs never change.  A namespace keeps one prefix
    name in the whole document.
    """

    def __init__(self, namespaces: Namespaces) -> None:
        self._iri_of: dict[str, str] = {}
        self._prefix_of: dict[str, str] = {}
        for name in sorted(STANDARD_PREFIXES):
            self._iri_of[name] = ""
        for prefix, iri in namespaces.fixed.items():
            self._iri_of[prefix] = iri
            self._prefix_of[iri] = prefix

    def prefix(self, preferred: str, iri: str, kind: str) -> str:
        """The prefix name of ``iri``, taking ``preferred`` if it is free."""
        known = self._prefix_of.get(iri)
        if known is not None:
            return known
        for candidate in self._candidates(preferred, kind):
            if candidate not in self._iri_of and is_valid_prefix(candidate):
                self._iri_of[candidate] = iri
                self._prefix_of[iri] = candidate
                return candidate
        raise AssertionError("unreachable: the candidates never run out")

    @staticmethod
    def _candidates(preferred: str, kind: str) -> Iterator[str]:
        yield preferred
        stem = next(s for s in (f"{preferred}_{kind}", f"{kind}_{preferred}", kind) if is_valid_prefix(s))
        yield stem
        n = 2
        while True:
            yield f"{stem}{n}"
            n += 1

    def items(self) -> Mapping[str, str]:
        """Prefix name → IRI of every namespace named so far (not the standard ones)."""
        return {p: iri for p, iri in self._iri_of.items() if iri}
