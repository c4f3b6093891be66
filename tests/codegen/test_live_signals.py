"""Live monitors read a robot's signals from the method's topics (``exscec generate ros1-monitor``).

A metric written over signals (``reads pose: robot pose``) is computed by a generated node from
the topics of the method's convention, the one the robots a live monitor watches publish: the
runtime, fed a simulated bag message by message, must give what ingestion gives for it.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from exsce_dsl.codegen.ros_monitor import generate_ros1_monitor, generate_ros2_monitor, monitor_topics
from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate

from tests.codegen.test_codegen_ros import BUILDING, PACKAGE, _import_package, fed_a_bag

SIGNAL_METRICS = """
metric live_east for each robot {
  "the largest x the robot reached"
  unit m
  reads pose: robot pose
  value max(pose.x)
}

metric live_speed for each robot per segment {
  "largest linear speed, from the velocity signal"
  unit m/s
  reads vel: robot velocity
  value max(norm(vel.linear.x, vel.linear.y))
}

metric live_obstacle for each robot per segment {
  "least laser range, from the scan signal"
  unit m
  reads laser: robot scan
  value min(laser.ranges where laser.ranges >= laser.range_min and laser.ranges <= laser.range_max)
}

metric live_distance for each robot per segment {
  "metres travelled, from the distance signal"
  unit m
  reads odometer: robot distance
  value change(odometer.data)
}
"""
LIVE = ("live_east", "live_speed", "live_obstacle", "live_distance")


def _spec(folder: Path, extra: str) -> Path:
    shutil.copytree(BUILDING, folder)
    metrics = folder / "metrics.exsce"
    metrics.write_text(metrics.read_text() + extra)
    return folder / "scenario_c.exsce"


@pytest.mark.parametrize("ros", [1, 2])
def test_a_live_monitor_computes_a_signal_metric_as_ingest_does(tmp_path: Path, ros: int) -> None:
    spec_path = _spec(tmp_path / "spec", SIGNAL_METRICS)
    spec = load_spec(spec_path)
    scenario = spec.scenario()
    (run,) = simulate(scenario, tmp_path / "bags", runs=1, seed=11, fmt=f"ros{ros}")
    analysed = analyse_bag(run.bag, scenario)
    out = tmp_path / "out"
    out.mkdir()
    (generate_ros1_monitor if ros == 1 else generate_ros2_monitor)(spec, None, out)
    package = _import_package(out / PACKAGE / "src" if ros == 1 else out / PACKAGE)
    assert package.config.TOPICS["/tiago1/robot_pose"]["signals"] == ("/tiago1/~pose",)
    assert not any("~" in topic for topic in package.config.TOPICS)  # a node subscribes to bag topics
    _, _, evaluation = fed_a_bag(package, run.bag)
    compared = 0
    for value in analysed.run.metrics:
        if value.metric in LIVE and value.action is None:
            assert evaluation.robots[value.robot][value.metric] == pytest.approx(value.value, abs=1e-6), value
            compared += 1
    assert compared == 2 * len(LIVE)


def test_a_live_monitor_maps_a_signals_fields_to_the_methods_message(tmp_path: Path) -> None:
    spec = load_spec(_spec(tmp_path / "spec", SIGNAL_METRICS))
    robots = [("tiago1", "tiago1")]
    ros1 = monitor_topics(spec.metrics, robots, 1)
    assert ros1["/tiago1/robot_pose"].fields["x"] == "pose.pose.position.x"
    assert ros1["/tiago1/nav_vel"].fields["linear.x"] == "linear.x"
    assert ros1["/tiago1/scan"].arrays == ["ranges"]
    assert ros1["/tiago1/distance_travelled"].fields == {"data": "data"}


def test_a_live_monitor_refuses_a_poses_yaw(tmp_path: Path) -> None:
    extra = "metric live_heading for each robot {\n  reads pose: robot pose\n  value max(pose.yaw)\n}\n"
    spec = load_spec(_spec(tmp_path / "spec", extra))
    with pytest.raises(ExsceError, match=r"reads the robot's pose.yaw: live monitors read a pose's position"):
        monitor_topics(spec.metrics, [("tiago1", "tiago1")], 1)
