"""The run's window (``window whole recording``), 3-D motion (``motion 3d``), arrival in 3-D and a
speed estimated from the pose of a robot that records nothing else.

The drone's bag is written here with rosbags: one PoseStamped stream, no goals, no velocity.  It
hovers on the pad, climbs 10 m straight up at 1 m/s, flies 10 m along x at 2 m/s and hovers, so
its path is 20 m in x-y-z and 10 m in x-y, its top speed 2 m/s, and it reaches the waypoint 10 m
above the pad only when it has climbed (in the plane it stands on it from the start).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.errors import BagError
from exsce_dsl.lang import format_spec_document, load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag
from exsce_dsl.sim.run import simulate

from tests.support.bag_factory import POSE_STAMPED, Topic, header, point, quaternion, typestore_for, write_bag

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "brsu_building_c"
START_NS = 1_767_312_000_000_000_000
HZ = 20

DRONE_SPEC = """
environment field {
  area pad {
    pose pad-ground at (0, 0)
  }
  area air {
    pose air-top at (0, 0, 10)
    pose air-far at (10, 0, 10)
  }
}

robot type quad {
  base quadrotor
  MOTION
}

task climb_and_fly {
  visit air-top
  visit air-far
}

scenario survey in field {
  robots {
    drone1: quad namespace "drone1" starts at pad-ground
  }
  mission m parallel {
    drone1 does climb_and_fly
  }
}
"""


def _drone_track() -> list[tuple[float, float, float, float]]:
    """(t, x, y, z) at 20 Hz: 2 s on the pad, 10 s climbing at 1 m/s, 5 s at 2 m/s along x, 2 s still."""
    found = []
    for i in range(int(19 * HZ) + 1):
        t = i / HZ
        z = min(max(t - 2.0, 0.0), 10.0)
        x = min(max(t - 12.0, 0.0) * 2.0, 10.0)
        found.append((t, x, 0.0, z))
    return found


def _path(window: tuple[float, float], axes: int) -> float:
    """The track's path length between two times (seconds after the start), in its first ``axes``
    of x, y, z, summed by hand over the samples inside."""
    inside = [p for p in _drone_track() if window[0] - 1e-6 <= p[0] <= window[1] + 1e-6]
    coordinates = np.array([(x, y, z)[:axes] for _, x, y, z in inside])
    return float(np.sqrt(np.square(np.diff(coordinates, axis=0)).sum(axis=1)).sum())


def _drone_bag(folder: Path, fmt: str) -> Path:
    store = typestore_for(fmt)
    messages = []
    for i, (t, x, y, z) in enumerate(_drone_track()):
        time_ns = START_NS + int(round(t * 1e9))
        pose = store.types["geometry_msgs/msg/Pose"](
            position=point(store, (x, y, z)), orientation=quaternion(store, 0.0)
        )
        messages.append(
            (time_ns, store.types[POSE_STAMPED](header=header(store, time_ns, "map", i), pose=pose))
        )
    name = folder / ("drone.bag" if fmt == "ros1" else f"drone-{fmt}")
    return write_bag(name, fmt, [Topic("/drone1/pose", POSE_STAMPED, messages)], store).path


def _scenario(folder: Path, motion: str) -> Scenario:
    spec = folder / f"survey-{motion or 'planar'}.exsce"
    spec.write_text(DRONE_SPEC.replace("MOTION", motion), encoding="utf-8")
    return load_spec(spec).scenario("survey")


def _whole(run: AnalysedRun, metric: str, robot: str) -> float:
    [value] = [v for v in run.run.metrics if (v.metric, v.robot, v.action) == (metric, robot, None)]
    return value.value


@pytest.mark.parametrize("fmt", ["ros1", "mcap"])
def test_a_drone_in_3d_arrives_when_it_has_climbed_and_its_path_is_3d(fmt: str, tmp_path: Path) -> None:
    bag = _drone_bag(tmp_path, fmt)
    flying = analyse_bag(bag, _scenario(tmp_path, "motion 3d"))
    actions = sorted(flying.run.actions(), key=lambda a: a.id.waypoint)
    top, far = actions
    assert top.end is not None and far.end is not None and top.start is not None
    start = START_NS * 1e-9
    # at the top once within 0.35 m of it: 9.65 m up, 2 s + 9.65 s after the start (20 Hz: 11.65 s)
    assert top.end.timestamp() - start == pytest.approx(11.65, abs=1 / HZ)
    assert far.end.timestamp() - start == pytest.approx(12.0 + 9.65 / 2.0, abs=1 / HZ)
    # the whole run is its recording (arrivals cut segments, never the run), along the track in x-y-z
    window = (0.0, _drone_track()[-1][0])
    assert _whole(flying, "distance_travelled", "drone1") == pytest.approx(_path(window, 3), rel=1e-9)
    assert _path(window, 3) == pytest.approx(20.0, rel=1e-9)
    speed = [
        v for v in flying.run.metrics if (v.metric, v.robot, v.action) == ("max_velocity", "drone1", None)
    ]
    assert speed and speed[0].value == pytest.approx(2.0, rel=1e-3)
    assert speed[0].estimated_from == "pose"
    assert any("its speed is estimated from its pose" in p for p in flying.problems)


def test_planar_motion_measures_in_the_plane_but_a_height_given_is_still_compared(tmp_path: Path) -> None:
    bag = _drone_bag(tmp_path, "ros1")
    planar = analyse_bag(bag, _scenario(tmp_path, ""))
    top = min(planar.run.actions(), key=lambda a: a.id.waypoint)
    assert top.end is not None
    # the waypoint gives a height (10 m): compared even for a planar robot, so not reached at once
    assert top.end.timestamp() - START_NS * 1e-9 == pytest.approx(11.65, abs=1 / HZ)
    far = max(planar.run.actions(), key=lambda a: a.id.waypoint)
    assert top.start is not None and far.end is not None
    # the whole run is its recording, not its arrivals: the 10 m flown in the plane
    window = (0.0, _drone_track()[-1][0])
    assert _whole(planar, "distance_travelled", "drone1") == pytest.approx(_path(window, 2), rel=1e-9)
    assert _path(window, 2) == pytest.approx(10.0, rel=1e-9)
    assert far.end.timestamp() - START_NS * 1e-9 < window[1] - 1.0


def test_window_whole_recording_covers_all_of_the_robots_signals(tmp_path: Path) -> None:
    """scenario_c with tiago's type saying ``window whole recording``: its whole-run distance is
    the distance_travelled topic's last value less its first over the whole bag (rosbags), where
    by default it is from the first goal's start to the last goal's end (less)."""
    folder = tmp_path / "brsu"
    shutil.copytree(EXAMPLE, folder)
    robots = folder / "robots.exsce"
    robots.write_text(
        robots.read_text().replace("  torso yes\n}", "  torso yes\n  window whole recording\n}", 1),
        encoding="utf-8",
    )
    default = load_spec(EXAMPLE / "scenario_c.exsce").scenario("scenario_c")
    recording = load_spec(folder / "scenario_c.exsce").scenario("scenario_c")
    assert (
        recording.robot("tiago1") is not None
        and recording.robot("tiago1").signals.window.value == "whole recording"
    )
    (run,) = simulate(default, tmp_path / "runs", seed=2)
    by_goals, whole = analyse_bag(run.bag, default), analyse_bag(run.bag, recording)
    with AnyReader([run.bag]) as reader:
        connections = [c for c in reader.connections if c.topic == "/tiago1/distance_travelled"]
        data = [
            reader.deserialize(raw, c.msgtype).data for c, _, raw in reader.messages(connections=connections)
        ]
    assert _whole(whole, "distance_travelled", "tiago1") == pytest.approx(max(data) - min(data), rel=1e-6)
    assert _whole(by_goals, "distance_travelled", "tiago1") <= _whole(whole, "distance_travelled", "tiago1")
    assert np.isclose(
        sum(
            v.value
            for v in by_goals.run.metrics
            if v.metric == "distance_travelled" and v.robot == "tiago1" and v.action
        ),
        _whole(by_goals, "distance_travelled", "tiago1"),
        rtol=1e-6,
    )


def test_the_formatter_keeps_motion_and_window(tmp_path: Path) -> None:
    spec = tmp_path / "types.exsce"
    spec.write_text(
        "robot type quad {\n  base quadrotor\n  motion 3d\n}\n\n"
        'robot type rover {\n  pose on "/{ns}/gps_pose"\n  window whole recording\n}\n',
        encoding="utf-8",
    )
    text = format_spec_document(load_spec(spec))
    assert "motion 3d" in text and "window whole recording" in text and "convention" not in text
    again = tmp_path / "again.exsce"
    again.write_text(text, encoding="utf-8")
    types = {t.id: t for t in load_spec(again).robot_types}
    assert types["quad"].motion == "3d"
    rover = types["rover"].declared_signals
    assert rover is not None and not rover.named and rover.said == {"pose", "window"}


def test_a_robot_with_tasks_and_nothing_to_place_it_is_refused_with_the_bags_pose_like_topics(
    tmp_path: Path,
) -> None:
    """The drone's pose recorded under another name than its namespace, and only its battery under
    it: no goals and no signal of drone1; the error names the robot and lists the pose-like topics
    there are.  (A robot with a velocity or a scan but no pose is not refused: those metrics are
    computed over the whole recording, the others are missing.)"""
    store = typestore_for("mcap")
    track = _drone_track()[:40]
    poses, battery = [], []
    for i, (t, x, y, z) in enumerate(track):
        time_ns = START_NS + int(round(t * 1e9))
        pose = store.types["geometry_msgs/msg/Pose"](
            position=point(store, (x, y, z)), orientation=quaternion(store, 0.0)
        )
        poses.append((time_ns, store.types[POSE_STAMPED](header=header(store, time_ns, "map", i), pose=pose)))
        battery.append((time_ns, store.types["std_msgs/msg/Float64"](data=0.9)))
    topics = [
        Topic("/other_drone/pose", POSE_STAMPED, poses),
        Topic("/drone1/battery", "std_msgs/msg/Float64", battery),
    ]
    bag = write_bag(tmp_path / "elsewhere", "mcap", topics, store).path
    with pytest.raises(
        BagError,
        match=r"robot 'drone1' has no navigation goals and no pose .*/other_drone/pose \(geometry_msgs/msg/PoseStamped\)",
    ):
        analyse_bag(bag, _scenario(tmp_path, "motion 3d"))


def test_a_user_metric_reads_more_of_the_methods_pose_topic_than_the_signal_does(tmp_path: Path) -> None:
    """Every robot's signals are served under the method's names; a metric that reads another
    field of the very topic its pose comes from (the covariance of /tiago1/robot_pose) still gets
    it: the largest x variance the bag holds, as rosbags reads it."""
    folder = tmp_path / "brsu"
    shutil.copytree(EXAMPLE, folder)
    spec = folder / "scenario_c.exsce"
    spec.write_text(
        spec.read_text()
        + """
metric pose_variance for each robot {
  "largest x variance of the localised pose"
  unit m
  reads pose: geometry_msgs/msg/PoseWithCovarianceStamped on "/{ns}/robot_pose"
  value max(pose.pose.covariance[0])
}
""",
        encoding="utf-8",
    )
    scenario = load_spec(spec).scenario("scenario_c")
    (run,) = simulate(scenario, tmp_path / "runs", seed=3)
    analysed = analyse_bag(run.bag, scenario)
    tiago1 = [a for a in analysed.run.actions() if a.id.robot == "tiago1"]
    start, end = min(a.start for a in tiago1 if a.start), max(a.end for a in tiago1 if a.end)
    with AnyReader([run.bag]) as reader:
        connections = [c for c in reader.connections if c.topic == "/tiago1/robot_pose"]
        variances = [
            reader.deserialize(raw, c.msgtype).pose.covariance[0]
            for c, t, raw in reader.messages(connections=connections)
            if start.timestamp() - 1e-6 <= t * 1e-9 <= end.timestamp() + 1e-6
        ]
    assert _whole(analysed, "pose_variance", "tiago1") == pytest.approx(max(variances), rel=1e-9)
    assert max(variances) > 0
