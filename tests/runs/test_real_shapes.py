"""Bags of the shapes real users bring (issue 32, "Test material"), with a specification whose
robot type names neither a convention nor a clock: each shape in ROS 1, ROS 2 sqlite3 and MCAP,
ingested through the library and once through the real ``exscec``; the values equal those
computed here from rosbags' deserialisation of the same bags (relative error < 1e-4), and a
metric whose data does not overlap its window is missing, never 0.

The shapes (:mod:`tests.support.real_shapes` writes them): a Jackal outdoors (odometry on
``/jackal_velocity_controller/odom``, ``/cmd_vel``, no goals, no TF), a KITTI-like sequence (ground
truth and two visual odometries, PoseStamped on relative names, ``ORB-SLAM`` among them), a robot
with TF only, one PoseStamped stream under a namespace stamped in simulated time beside wall-clock
log times (no ``/clock``), a drone climbing; and the executor's Nav2 robot at the root, with its
goals and with them removed.  Where a plan's waypoints are on the recorded path, the robot is
segmented by arrival (docs/bags.md's rule, recomputed here), and its whole-run values still cover
its whole recording (an arrival cuts segments, never the run: issue 47); where they are not
(``survey``: a pose 50 m away), it has no segments and its metrics are of its whole recording.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Reader as Ros1Reader
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import Reader as Ros2Reader
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.runs import MetricScope
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag
from exsce_dsl.sim.run import simulate

from tests.support.bag_factory import typestore_for, write_bag
from tests.support.cli import exscec_here
from tests.support.real_shapes import SHAPES

FORMATS = ("ros1", "sqlite3", "mcap")
EXECUTOR_FORMATS = {"ros1": "ros1", "sqlite3": "ros2", "mcap": "mcap"}
PLAN = ((8.0, 0.0), (8.0, 6.0))
"""The ``loop`` task's waypoints, ``field-1`` and ``field-2``."""
TOLERANCE = 0.35
"""The default arrival tolerance (m)."""
STILL = 0.01
"""Metres within which a robot has not yet set off (docs/bags.md, arrival)."""

SPEC = """
environment farm {
  area field {
    pose field-start at (0.0, 0.0)
    pose field-1 at (8.0, 0.0)
    pose field-2 at (8.0, 6.0)
    pose field-far at (40.0, 40.0)
  }
}

task loop {
  visit field-1, field-2
}

task survey {
  visit field-far
}

robot type rover {
  base diff_drive
ROBOT_TYPE}
METRICS
scenario SHAPE in farm {
  robots {
    bot: rover namespace "NAMESPACE" starts at field-start
  }
  mission SHAPE_mission sequential {
    bot does TASK
  }
}
"""


def _metric(name: str, read: str, value: str, unit: str = "m") -> str:
    return f"metric {name} for each robot {{\n  unit {unit}\n  reads {read}\n  value {value}\n}}\n"


PLANAR_PATH = _metric("planar_path", "pose: robot pose", "path_length(pose.x, pose.y)")
ODOMETRY_READ = 'odom: nav_msgs/msg/Odometry on "/jackal_velocity_controller/odom"'
STREAMS = {"gt_path": "groundtruth", "orb_path": "ORB-SLAM", "dso_path": "DSO"}
KITTI_METRICS = "".join(
    _metric(
        name,
        f'g: geometry_msgs/msg/PoseStamped on "{topic}"',
        "path_length(g.pose.position.x, g.pose.position.y)",
    )
    for name, topic in STREAMS.items()
)

SPECS: dict[str, tuple[str, str, str, str]] = {
    # shape: namespace, task, robot type lines, metrics
    "jackal": (
        "",
        "survey",
        "",
        _metric(
            "odom_path", ODOMETRY_READ, "path_length(odom.pose.pose.position.x, odom.pose.pose.position.y)"
        )
        + _metric("odom_top_speed", ODOMETRY_READ, "max(odom.twist.twist.linear.x)", "m/s"),
    ),
    "kitti": ("", "survey", 'pose on "groundtruth"', KITTI_METRICS),
    "tf_only": ("", "loop", "", PLANAR_PATH),
    "namespaced": (
        "scout",
        "loop",
        "",
        _metric("top_speed_reported", 's: std_msgs/msg/Float32 on "/{ns}/speed"', "max(s.data)", "m/s")
        + 'metric battery_readings for each robot {\n  reads b: std_msgs/msg/Float32 on "/{ns}/battery"\n'
        "  value count where b.data > 0\n}\n",
    ),
    "drone": ("", "survey", "", PLANAR_PATH),
    "nav2": ("", "loop", "", ""),
}
METHOD_ONLY = ("waypoint_dispatcher", "nav_vel", "robot_pose", "/distance_travelled", "~", "{ns}")
"""What a problem of these robots must not name: the method's topics the standard metrics are
declared over, and the names signals are served under inside ingestion."""


def spec_text(shape: str) -> str:
    namespace, task, robot_type, metrics = SPECS[shape]
    lines = "".join(f"  {line}\n" for line in robot_type.splitlines())
    return (
        SPEC.replace("ROBOT_TYPE", lines)
        .replace("METRICS", metrics)
        .replace("SHAPE", shape)
        .replace("NAMESPACE", namespace)
        .replace("TASK", task)
    )


# ------------------------------------------------------------------ the bags


def ext(connection: Any) -> Any:
    """A connection's format-specific facts (ROS 1's caller id, ROS 2's QoS)."""
    return connection.ext


def _copy_without_goals(source: Path, target: Path, fmt: str) -> None:
    """``source`` copied byte for byte without its navigation goals (actions and the plan)."""

    def kept(topic: str) -> bool:
        return "_action" not in topic and topic not in ("/plan", "/goal_pose")

    if fmt == "ros1":
        with Ros1Reader(source) as reader, Ros1Writer(target) as writer:
            out = {
                c.id: writer.add_connection(
                    c.topic, c.msgtype, msgdef=c.msgdef.data, md5sum=c.digest, callerid=ext(c).callerid
                )
                for c in reader.connections
                if kept(c.topic)
            }
            for c, t, raw in reader.messages([c for c in reader.connections if kept(c.topic)]):
                writer.write(out[c.id], t, raw)
        return
    plugin = StoragePlugin.MCAP if fmt == "mcap" else StoragePlugin.SQLITE3
    with Ros2Reader(source) as reader2, Ros2Writer(target, version=9, storage_plugin=plugin) as writer2:
        out2 = {
            c.id: writer2.add_connection(
                c.topic,
                c.msgtype,
                msgdef=c.msgdef.data,
                rihs01=c.digest,
                serialization_format=ext(c).serialization_format,
                offered_qos_profiles=ext(c).offered_qos_profiles,
            )
            for c in reader2.connections
            if kept(c.topic)
        }
        for c, t, raw in reader2.messages([c for c in reader2.connections if kept(c.topic)]):
            writer2.write(out2[c.id], t, raw)


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("real_shapes")


@pytest.fixture(scope="module")
def scenarios(folder: Path) -> dict[str, tuple[Path, Scenario]]:
    found = {}
    for shape in SPECS:
        path = folder / f"{shape}.exsce"
        path.write_text(spec_text(shape))
        found[shape] = (path, load_spec(path).scenario())
    return found


@pytest.fixture(scope="module")
def bags(folder: Path, scenarios: dict[str, tuple[Path, Scenario]]) -> dict[tuple[str, str], Path]:
    """(shape, format) → its bag; ``nav2`` is the executor's run, ``nav2_no_goals`` its copy."""
    found = {}
    for fmt in FORMATS:
        for shape, topics in SHAPES.items():
            store = typestore_for(fmt)
            # named apart from the scenario (which it need not be since bag bundles are named by their run)
            path = folder / fmt / (f"{shape}_{fmt}.bag" if fmt == "ros1" else f"{shape}_{fmt}")
            path.parent.mkdir(exist_ok=True)
            write_bag(path, fmt, topics(store), store)
            found[(shape, fmt)] = path
        (run,) = simulate(
            scenarios["nav2"][1], folder / fmt / "nav2", fmt=EXECUTOR_FORMATS[fmt], seed=2, convention="nav2"
        )
        # the executor names a run's ROS 2 and MCAP bags alike, and a store keeps one bag of a name
        found[("nav2", fmt)] = run.bag.rename(
            folder / fmt / (f"nav2_{fmt}.bag" if fmt == "ros1" else f"nav2_{fmt}")
        )
        target = folder / fmt / ("nav2_no_goals_ros1.bag" if fmt == "ros1" else f"nav2_no_goals_{fmt}")
        _copy_without_goals(found[("nav2", fmt)], target, fmt)
        found[("nav2_no_goals", fmt)] = target
    return found


def _spec_of(shape: str) -> str:
    return "nav2" if shape == "nav2_no_goals" else shape


@pytest.fixture(scope="module")
def analysed(
    bags: dict[tuple[str, str], Path], scenarios: dict[str, tuple[Path, Scenario]]
) -> dict[tuple[str, str], AnalysedRun]:
    return {key: analyse_bag(bag, scenarios[_spec_of(key[0])][1]) for key, bag in bags.items()}


# ------------------------------------------------------------------ references, from rosbags


def read(bag: Path, topic: str) -> list[tuple[float, float, Any]]:
    """(log time s, header stamp s or log time, message) of the bag's ``topic`` as spelt there."""
    fmt = "ros1" if bag.suffix == ".bag" else "sqlite3"
    with AnyReader([bag], default_typestore=typestore_for(fmt)) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        assert conns, f"{bag} has no {topic}"
        found = []
        for c, t, raw in reader.messages(conns):
            message = reader.deserialize(raw, c.msgtype)
            head = getattr(message, "header", None)
            stamp = head.stamp.sec + head.stamp.nanosec * 1e-9 if head is not None else t / 1e9
            found.append((t / 1e9, stamp, message))
    return found


def path_length(x: np.ndarray, y: np.ndarray, z: np.ndarray | None = None) -> float:
    steps = [np.diff(x), np.diff(y)] + ([np.diff(z)] if z is not None else [])
    return float(np.sum(np.sqrt(sum(np.square(s) for s in steps))))


def positions(messages: list[tuple[float, float, Any]], pose: Callable[[Any], Any]) -> dict[str, np.ndarray]:
    return {
        "t": np.array([s for _, s, _ in messages]),
        **{a: np.array([getattr(pose(m).position, a) for _, _, m in messages]) for a in "xyz"},
    }


def arrival_window(t: np.ndarray, x: np.ndarray, y: np.ndarray) -> tuple[int, int]:
    """docs/bags.md's arrival rule: from the last sample still at the first pose before the robot went
    farther than the tolerance, to the first sample within it of each planned waypoint in turn."""
    away = np.hypot(x - x[0], y - y[0])
    departure = int(np.flatnonzero(away > TOLERANCE)[0])
    index = int(np.flatnonzero(away[:departure] <= STILL)[-1])
    start = index
    for wx, wy in PLAN:
        index += int(np.flatnonzero(np.hypot(x[index:] - wx, y[index:] - wy) <= TOLERANCE)[0])
    return start, index


def chord_speed(t: np.ndarray, x: np.ndarray, y: np.ndarray) -> float:
    """The largest speed of positions over 0.5 s about each sample (docs/language.md's ``speed``), held at
    the ends."""
    before, after = np.clip(t - 0.25, t[0], t[-1]), np.clip(t + 0.25, t[0], t[-1])
    moved = np.hypot(
        np.interp(after, t, x) - np.interp(before, t, x), np.interp(after, t, y) - np.interp(before, t, y)
    )
    return float(np.max(moved / (after - before)))


ReferenceValues = tuple[dict[str, float], set[str]]
"""Whole-run values of the robot by metric, and the metrics that must be missing (and said)."""


def pose_velocity(
    expected: dict[str, float], missing: set[str], pose: dict[str, np.ndarray], window: slice
) -> None:
    """max_velocity of a robot with a pose only: the poses' speed (docs/language.md's ``speed``), never 0."""
    t, x, y = pose["t"][window], pose["x"][window], pose["y"][window]
    expected["max_velocity"] = chord_speed(t, x, y)
    missing.discard("max_velocity")


def jackal(bag: Path) -> ReferenceValues:
    odom = read(bag, "/jackal_velocity_controller/odom")
    cmd = read(bag, "/cmd_vel")
    xy = positions(odom, lambda m: m.pose.pose)
    times = [t for t, _, _ in odom + cmd]
    length = path_length(xy["x"], xy["y"])
    return {
        "distance_travelled": length,
        "odom_path": length,
        "max_velocity": max(float(np.hypot(m.linear.x, m.linear.y)) for _, _, m in cmd),
        "odom_top_speed": max(m.twist.twist.linear.x for _, _, m in odom),
        "task_duration": max(times) - min(times),
    }, {"waypoints_visited", "distance_to_obstacles"}


def kitti(bag: Path) -> ReferenceValues:
    streams = {name: positions(read(bag, topic), lambda m: m.pose) for name, topic in STREAMS.items()}
    expected = {name: path_length(p["x"], p["y"]) for name, p in streams.items()}
    truth = streams["gt_path"]
    expected["distance_travelled"] = expected["gt_path"]
    expected["task_duration"] = float(truth["t"][-1] - truth["t"][0])
    missing = {"waypoints_visited", "distance_to_obstacles", "max_velocity"}
    pose_velocity(expected, missing, truth, slice(None))
    return expected, missing


def composed_tf(bag: Path) -> dict[str, np.ndarray]:
    """map → base_link composed by hand from rosbags' transforms: map → odom interpolated at the
    stamps of odom → base_link (its rotation is one yaw throughout)."""
    edges: dict[tuple[str, str], list[tuple[float, float, float, float]]] = {}
    for _, _, message in read(bag, "/tf"):
        for tr in message.transforms:
            q = tr.transform.rotation
            yaw = 2 * np.arctan2(q.z, q.w)
            stamp = tr.header.stamp.sec + tr.header.stamp.nanosec * 1e-9
            edges.setdefault((tr.header.frame_id, tr.child_frame_id), []).append(
                (stamp, tr.transform.translation.x, tr.transform.translation.y, yaw)
            )
    fixed = np.array(sorted(edges[("map", "odom")]))
    body = np.array(sorted(edges[("odom", "base_link")]))
    assert np.ptp(fixed[:, 3]) < 1e-12, "the correction turns: this hand composition does not apply"
    t = body[:, 0]
    mx, my, yaw = np.interp(t, fixed[:, 0], fixed[:, 1]), np.interp(t, fixed[:, 0], fixed[:, 2]), fixed[0, 3]
    x = mx + np.cos(yaw) * body[:, 1] - np.sin(yaw) * body[:, 2]
    y = my + np.sin(yaw) * body[:, 1] + np.cos(yaw) * body[:, 2]
    return {"t": t, "x": x, "y": y}


def by_arrival(pose: dict[str, np.ndarray]) -> tuple[dict[str, float], slice]:
    """Whole-run values of a robot segmented by arrival: over its whole recording (the arrivals cut
    its segments only), both waypoints reached."""
    start, end = arrival_window(pose["t"], pose["x"], pose["y"])
    assert end < len(pose["t"]) - 1, "the last waypoint is reached before the recording ends"
    window = slice(None)
    start, end = 0, len(pose["t"]) - 1
    return {
        "distance_travelled": path_length(pose["x"][window], pose["y"][window]),
        "task_duration": float(pose["t"][end] - pose["t"][start]),
        "waypoints_visited": 2.0,
    }, window


def tf_only(bag: Path) -> ReferenceValues:
    pose = composed_tf(bag)
    expected, window = by_arrival(pose)
    expected["planar_path"] = expected["distance_travelled"]
    missing = {"distance_to_obstacles", "max_velocity"}
    pose_velocity(expected, missing, pose, window)
    return expected, missing


def namespaced(bag: Path) -> ReferenceValues:
    messages = read(bag, "/scout/pose")
    pose = positions(messages, lambda m: m.pose)
    expected, window = by_arrival(pose)
    offset = float(np.median([log - stamp for log, stamp, _ in messages]))
    speeds = read(bag, "/scout/speed")
    start, end = pose["t"][window][[0, -1]]
    assert all(start <= log - offset <= end for log, _, _ in speeds), (
        "the reported speeds are all in the window"
    )
    expected["top_speed_reported"] = max(m.data for _, _, m in speeds)
    # the whole run is the recording: the readings before the robot set off count
    expected["battery_readings"] = float(sum(m.data > 0 for _, _, m in read(bag, "/scout/battery")))
    missing = {"distance_to_obstacles", "max_velocity"}
    pose_velocity(expected, missing, pose, window)
    return expected, missing


def drone(bag: Path) -> ReferenceValues:
    pose = positions(read(bag, "/mavros/local_position/pose"), lambda m: m.pose)
    length = path_length(pose["x"], pose["y"])  # in the plane until robot types say 'motion 3d'
    expected = {
        "distance_travelled": length,
        "planar_path": length,
        "task_duration": float(np.ptp(pose["t"])),
    }
    missing = {"waypoints_visited", "distance_to_obstacles", "max_velocity"}
    pose_velocity(expected, missing, pose, slice(None))
    return expected, missing


EXECUTING, SUCCEEDED = 2, 4  # action_msgs/msg/GoalStatus


def goals_window(bag: Path) -> tuple[float, float]:
    """From the first goal EXECUTING to the last SUCCEEDED, in log time (the executor's stamps)."""
    statuses = read(bag, "/navigate_to_pose/_action/status")
    started = min(t for t, _, m in statuses if any(s.status == EXECUTING for s in m.status_list))
    done = [t for t, _, m in statuses if any(s.status == SUCCEEDED for s in m.status_list)]
    return started, max(done)


def in_window(bag: Path, start: float, end: float) -> dict[str, float]:
    """distance along /odom and the largest /cmd_vel between ``start`` and ``end`` (log times)."""

    def inside(topic: str) -> list[Any]:
        return [m for t, _, m in read(bag, topic) if start - 1e-6 <= t <= end + 1e-6]

    odom = np.array([[m.pose.pose.position.x, m.pose.pose.position.y] for m in inside("/odom")])
    return {
        "distance_travelled": path_length(odom[:, 0], odom[:, 1]),
        "max_velocity": max(float(np.hypot(m.linear.x, m.linear.y)) for m in inside("/cmd_vel")),
        "waypoints_visited": 2.0,
    }


def nav2(bag: Path) -> ReferenceValues:
    return in_window(bag, *goals_window(bag)), set()


REFERENCES: dict[str, Callable[[Path], ReferenceValues]] = {
    "jackal": jackal,
    "kitti": kitti,
    "tf_only": tf_only,
    "namespaced": namespaced,
    "drone": drone,
    "nav2": nav2,
}
CASES = [(shape, fmt) for shape in REFERENCES for fmt in FORMATS]


def whole_run(run: AnalysedRun) -> dict[str, float]:
    return {
        v.metric: v.value
        for v in run.run.metrics
        if v.scope is MetricScope.ROBOT and v.robot == "bot" and v.safety_metric is None
    }


def agree(found: dict[str, float], expected: dict[str, float], where: str, bag: Path | None = None) -> None:
    for metric, value in expected.items():
        assert metric in found, f"{where}: {metric} is missing"
        assert found[metric] == pytest.approx(value, rel=1e-4, abs=1e-9), f"{where}: {metric}"
        assert value > 0, f"{where}: the reference {metric} is 0: the test proves nothing"


# ------------------------------------------------------------------ the library


@pytest.mark.parametrize(("shape", "fmt"), CASES)
def test_a_real_shape_gives_rosbags_values(
    shape: str, fmt: str, bags: dict[tuple[str, str], Path], analysed: dict[tuple[str, str], AnalysedRun]
) -> None:
    expected, missing = REFERENCES[shape](bags[(shape, fmt)])
    run = analysed[(shape, fmt)]
    found = whole_run(run)
    agree(found, expected, f"{shape} {fmt}", bags[(shape, fmt)])
    for metric in missing:
        assert metric not in found, f"{metric} = {found.get(metric)}: its data is not in the bag"
        assert any(f"{metric} of 'bot'" in p for p in run.problems), (metric, run.problems)
    detected = run.picked()
    assert detected and "convention" in detected[0], detected


@pytest.mark.parametrize(("shape", "fmt"), CASES)
def test_problems_name_only_the_topics_the_robots_convention_reads(
    shape: str, fmt: str, analysed: dict[tuple[str, str], AnalysedRun]
) -> None:
    """compute.py's problems named the metric's declared topics (``/waypoint_dispatcher/result``,
    ``/scan``, ``/nav_vel``) for a robot whose signals are elsewhere."""
    problems = analysed[(shape, fmt)].problems
    for problem in problems:
        assert not any(word in problem for word in METHOD_ONLY), problem


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_detected_robot_without_goals_or_scan_is_told_so(
    fmt: str, analysed: dict[tuple[str, str], AnalysedRun]
) -> None:
    problems = analysed[("jackal", fmt)].problems
    assert "no scan (none detected in the bag): distance_to_obstacles of 'bot'" in "\n".join(problems)
    assert any(
        p.startswith("no path segments (no navigation goals") and "waypoints_visited" in p for p in problems
    )


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_window_that_misses_a_topic_gives_no_value_not_0(
    fmt: str, analysed: dict[tuple[str, str], AnalysedRun]
) -> None:
    """/scout/battery was recorded only before the robot set off: the whole run (its recording)
    counts its readings, while each path segment (from setting off, cut by arrivals) misses it and
    has no count at all (it would be 0); the coverage finding says the topic ends early."""
    run = analysed[("namespaced", fmt)]
    segments = [v for v in run.run.metrics if v.scope is MetricScope.SEGMENT and v.robot == "bot"]
    assert len([v for v in segments if v.metric == "task_duration"]) == 2
    assert not [v for v in segments if v.metric == "battery_readings"]
    assert whole_run(run)["battery_readings"] > 0
    (said,) = [p for p in run.problems if p.startswith("coverage: no data: /scout/battery ends")]
    assert run.timeline is not None and run.timeline.simulated


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_nav2_robot_without_its_goals_is_segmented_by_arrival(
    fmt: str, bags: dict[tuple[str, str], Path], analysed: dict[tuple[str, str], AnalysedRun]
) -> None:
    """The executor's Nav2 bag without its goal topics: the robot is detected without goals, its
    segments come from arriving at the planned waypoints, inside the goals' window, and its
    whole-run values are those of rosbags' /odom and /cmd_vel over the whole recording (an
    arrival cuts segments, never the run: issue 47)."""
    bag = bags[("nav2_no_goals", fmt)]
    run = analysed[("nav2_no_goals", fmt)]
    (task,) = run.run.tasks
    assert task.segmented_by == "arrival at the planned waypoints"
    began, ended = task.actions[0].start, task.actions[-1].end
    assert began is not None and ended is not None
    start, end = began.timestamp(), ended.timestamp()
    first, last = goals_window(bags[("nav2", fmt)])
    assert first - 1.0 <= start < end <= last + 1.0, (start, end, first, last)
    agree(whole_run(run), in_window(bag, -np.inf, np.inf), f"nav2 without goals {fmt}")
    assert "none (no navigation goals)" in run.picked()[0]
    with_goals = whole_run(analysed[("nav2", fmt)])["distance_travelled"]
    assert whole_run(run)["distance_travelled"] != with_goals


# ------------------------------------------------------------------ the real exscec


def test_the_shapes_through_exscec(
    folder: Path, bags: dict[tuple[str, str], Path], scenarios: dict[str, tuple[Path, Scenario]]
) -> None:
    """exscec ingest of each shape's three bags (a store per shape: robot ids are the store's),
    then the stored whole-run values."""
    by_path = {str(bag.resolve()): key for key, bag in bags.items()}
    for shape in REFERENCES:
        store = str(folder / f"store_{shape}")
        paths = [str(bags[(shape, fmt)]) for fmt in FORMATS]
        done = exscec_here(
            "ingest", *paths, "--scenario", str(scenarios[shape][0]), "--store", store
        )
        assert done.returncode == 0, f"{shape}:\n{done.stdout}\n{done.stderr}"
        assert "Traceback" not in done.stderr and "convention" in done.stderr, done.stderr
        listed = exscec_here("runs", "-f", "json", "--store", store)
        assert listed.returncode == 0, listed.stderr
        rows = json.loads(listed.stdout)["results"]["bindings"]
        runs = {row["run"]["value"]: Path(row["path"]["value"]) for row in rows}
        assert len(runs) == len(FORMATS)
        runs_given = [a for r in runs for a in ("-p", f"run={r}")]
        queried = exscec_here("query", "run_metric_values", *runs_given, "-f", "json", "--store", store)
        assert queried.returncode == 0, queried.stderr
        stored: dict[str, dict[str, float]] = {}
        for row in json.loads(queried.stdout)["results"]["bindings"]:
            if row.get("robot", {}).get("value", "").endswith("bot") and "safety" not in row:
                metric = row["metric"]["value"].rsplit("/", 1)[-1].rsplit(":", 1)[-1]
                stored.setdefault(row["run"]["value"], {})[metric] = float(row["value"]["value"])
        for run, path in runs.items():
            key = by_path[str(path.resolve())]
            expected, missing = REFERENCES[shape](path)
            agree(stored[run], expected, f"exscec {key}", path)
            assert not missing & stored[run].keys(), (key, stored[run])


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_drone_whose_type_says_motion_3d_travels_in_3d(
    fmt: str, folder: Path, bags: dict[tuple[str, str], Path]
) -> None:
    """``motion 3d``: the drone's distance is its path in x-y-z, as rosbags' positions give it."""
    path = folder / "drone_3d.exsce"
    path.write_text(spec_text("drone").replace("  base diff_drive\n", "  base diff_drive\n  motion 3d\n"))
    bag = bags[("drone", fmt)]
    found = whole_run(analyse_bag(bag, load_spec(path).scenario()))
    pose = positions(read(bag, "/mavros/local_position/pose"), lambda m: m.pose)
    climbed = path_length(pose["x"], pose["y"], pose["z"])
    assert climbed > path_length(pose["x"], pose["y"]) + 1.0
    assert found["distance_travelled"] == pytest.approx(climbed, rel=1e-4)
