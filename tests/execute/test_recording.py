"""What a run records, written out by hand per convention: scenario_c in the method's topics (and in
every convention when its type names none), a move_base fleet with a type's own lines and a
metric of its own, a Nav2 robot at the root with a relative topic."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute.recording import ALWAYS, recorded_topics
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.runs.coverage import PROV_TOPIC

from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"
IMPORTS = f'import "{BUILDING}/environment.exsce"\nimport "{BUILDING}/tasks/deliveries.exsce"\n'
EVERY_RUN = ["/clock", "/exsce/prov", "/tf", "/tf_static"]


def spec(tmp_path: Path, text: str) -> Scenario:
    path = tmp_path / "spec.exsce"
    path.write_text(IMPORTS + text, encoding="utf-8")
    return load_spec(path).scenarios[0]


def scenario_c() -> Scenario:
    return load_spec(BUILDING / "scenario_c.exsce").scenarios[0]


def method_topics(ns: str) -> list[str]:
    """The method's robot: robot_pose, nav_vel, scan, distance_travelled and its dispatcher."""
    leaves = ["distance_travelled", "nav_vel", "robot_pose", "scan"]
    leaves += ["waypoint_dispatcher/feedback", "waypoint_dispatcher/result"]
    return [f"/{ns}/{leaf}" for leaf in leaves]


def move_base_topics(ns: str) -> list[str]:
    """move_base's robot: pose from its TF (else amcl_pose, else odom), velocity on cmd_vel (else
    odom), scan, distance along odom, and move_base's goal, status and result."""
    leaves = ["amcl_pose", "cmd_vel", "move_base/goal", "move_base/result", "move_base/status"]
    leaves += ["odom", "scan", "tf", "tf_static"]
    return [f"/{ns}/{leaf}" for leaf in leaves]


def nav2_topics(ns: str) -> list[str]:
    """Nav2's robot: the same signals as move_base's, goals from its three actions' status (and
    follow_waypoints' feedback), targets from the planner's plan."""
    leaves = ["amcl_pose", "cmd_vel", "follow_waypoints/_action/feedback", "follow_waypoints/_action/status"]
    leaves += ["navigate_through_poses/_action/status", "navigate_to_pose/_action/status", "odom", "plan"]
    leaves += ["scan", "tf", "tf_static"]
    return [f"/{ns}/{leaf}" for leaf in leaves]


def test_every_run_records_tf_the_clock_and_the_prov() -> None:
    assert sorted(ALWAYS) == EVERY_RUN and PROV_TOPIC == "/exsce/prov"


def test_scenario_c_in_the_methods_convention() -> None:
    # its own metrics (fast_driving_time, mean_turn_rate) read the velocity signal: /{ns}/nav_vel
    expected = sorted(EVERY_RUN + method_topics("tiago1") + method_topics("tiago2"))
    assert recorded_topics(scenario_c(), "method") == expected


def test_scenario_c_on_move_base_does_not_record_what_ingestion_serves_from_signals() -> None:
    # the metrics read the signals (velocity, pose, distance) from cmd_vel, TF, odom: no nav_vel
    expected = sorted(EVERY_RUN + move_base_topics("tiago1") + move_base_topics("tiago2"))
    assert recorded_topics(scenario_c(), "move_base") == expected


def test_a_type_that_names_no_convention_records_every_convention() -> None:
    robots = ["tiago1", "tiago2"]
    every = [t for ns in robots for t in method_topics(ns) + move_base_topics(ns) + nav2_topics(ns)]
    found = recorded_topics(scenario_c())
    assert found == sorted(set(EVERY_RUN + every))
    assert len(found) == len(set(found)) == 4 + 2 * 19


def test_a_move_base_fleet_with_its_own_lines_and_metrics(tmp_path: Path) -> None:
    scenario = spec(
        tmp_path,
        """
robot type mb {
  base pmb2
  torso no
  convention move_base
}

robot type mb_filtered {
  base pmb2
  torso no
  convention move_base
  pose from tf map -> base_footprint
  scan on "/{ns}/scan_filtered"
}

metric battery_low for each robot {
  "lowest battery level"
  unit m
  reads level: std_msgs/msg/Float64 on "/{ns}/battery_level"
  value min(level.data)
}

metric mean_turn_rate for each robot {
  "mean absolute angular velocity"
  unit rad/s
  reads vel: robot velocity
  value mean(abs(vel.angular.z))
}

scenario on_move_base in brsu_building_c_with_doors {
  robots {
    robot1: mb starts at classroom_c025-w001
    robot2: mb_filtered namespace "fleet/robot2" starts at classroom_c025-w002
  }
  mission on_move_base_mission parallel {
    robot1 does delivery_a
    robot2 does delivery_b
  }
}
""",
    )
    robot1 = move_base_topics("robot1") + ["/robot1/battery_level"]
    robot2 = [  # its pose from TF only (no amcl_pose), its own scan topic
        "/fleet/robot2/battery_level",
        "/fleet/robot2/cmd_vel",
        "/fleet/robot2/move_base/goal",
        "/fleet/robot2/move_base/result",
        "/fleet/robot2/move_base/status",
        "/fleet/robot2/odom",
        "/fleet/robot2/scan_filtered",
        "/fleet/robot2/tf",
        "/fleet/robot2/tf_static",
    ]
    assert recorded_topics(scenario) == sorted(EVERY_RUN + robot1 + robot2)
    assert recorded_topics(scenario, "method") == recorded_topics(scenario)  # it names its own


def test_a_nav2_robot_at_the_root_with_a_relative_topic(tmp_path: Path) -> None:
    scenario = spec(
        tmp_path,
        """
robot type rover {
  base pmb2
  torso no
  convention nav2
  navigation nav2 on "/{ns}/navigate_to_pose"
}

metric truth_speed for each robot {
  "mean speed, ground truth"
  unit m/s
  reads odom: nav_msgs/msg/Odometry on "groundtruth"
  value mean(abs(odom.twist.twist.linear.x))
}

scenario at_root in brsu_building_c_with_doors {
  robots {
    bot: rover namespace "" starts at classroom_c025-w001
  }
  mission at_root_mission sequential {
    bot does delivery_a
  }
}
""",
    )
    robot = ["/amcl_pose", "/cmd_vel", "/groundtruth", "/navigate_to_pose/_action/status", "/odom", "/plan"]
    robot += ["/scan"]  # and its TF on /tf, /tf_static, recorded in every run
    assert recorded_topics(scenario) == sorted(EVERY_RUN + robot)


def test_a_type_own_line_holds_in_every_convention_it_may_be_detected_in(tmp_path: Path) -> None:
    scenario = spec(
        tmp_path,
        """
robot type raw {
  base pmb2
  torso no
  scan on "/{ns}/scan_raw"
}

scenario undecided in brsu_building_c_with_doors {
  robots {
    tiago1: raw starts at classroom_c025-w001
  }
  mission undecided_mission sequential {
    tiago1 does delivery_a
  }
}
""",
    )
    on_move_base = [t for t in move_base_topics("tiago1") if t != "/tiago1/scan"] + ["/tiago1/scan_raw"]
    assert recorded_topics(scenario, "move_base") == sorted(EVERY_RUN + on_move_base)
    every = set(recorded_topics(scenario))
    assert "/tiago1/scan" not in every and {"/tiago1/scan_raw", "/tiago1/robot_pose", "/tiago1/plan"} <= every


def test_an_unknown_convention_is_refused() -> None:
    with pytest.raises(ExsceError, match="unknown convention 'ros2'; use one of method, nav2, move_base"):
        recorded_topics(scenario_c(), "ros2")
