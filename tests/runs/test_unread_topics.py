"""A topic the specification names that the bag lacks (issue 33, item 3): the bag's closest topics
count a relative name, another namespace and a typo as close, and navigation actions are checked
against the actions the bag records. Real bags: a KITTI-like one with relative names, written
with rosbags, and the executor's Nav2 run; the bag's topics are listed again by rosbags."""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.errors import BagError
from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate
from exsce_dsl.suggest import closest_several

from tests.support.bag_factory import typestore_for, write_bag
from tests.support.paths import EXAMPLES
from tests.support.real_shapes import kitti

BUILDING = EXAMPLES / "brsu_building_c"
FARM = """\
environment farm {
  area field {
    pose field-start at (0.0, 0.0)
    pose field-far at (40.0, 40.0)
  }
}
task survey {
  visit field-far
}
robot type rover {
  base diff_drive
  pose on "/ground_truth"
}
scenario kitti in farm {
  robots {
    bot: rover namespace "" starts at field-start
  }
  mission kitti_mission sequential {
    bot does survey
  }
}
"""
NAV2 = f"""\
import "{BUILDING}/environment.exsce"
import "{BUILDING}/tasks/deliveries.exsce"

robot type rover {{
  base pmb2
  torso no
  convention nav2
  navigation nav2 on "/navigate_to_pos"
}}

metric commanded_top_speed for each robot {{
  unit m/s
  reads v: geometry_msgs/msg/Twist on "/robot1/cmd_vel"
  value max(v.linear.x)
}}

scenario drive in brsu_building_c_with_doors {{
  robots {{
    bot: rover namespace "" starts at classroom_c025-w001
  }}
  mission drive_mission sequential {{
    bot does delivery_a
  }}
}}
"""


def topics_of(bag: Path, msgtype: str) -> list[str]:
    with AnyReader([bag]) as reader:
        return sorted(c.topic for c in reader.connections if c.msgtype == msgtype)


def test_a_relative_name_in_the_bag_is_the_closest_to_an_absolute_one(tmp_path: Path) -> None:
    """KITTI's ``groundtruth`` (relative, as its node published it) for the spec's ``/ground_truth``:
    no pose, so no run, and the error says which topic to write."""
    store = typestore_for("ros1")
    bag = tmp_path / "kitti.bag"
    write_bag(bag, "ros1", kitti(store), store)
    (tmp_path / "kitti.exsce").write_text(FARM)
    with pytest.raises(BagError) as raised:
        analyse_bag(bag, load_spec(tmp_path / "kitti.exsce").scenario())
    said = str(raised.value)
    poses = topics_of(bag, "geometry_msgs/msg/PoseStamped")
    assert poses == ["DSO", "ORB-SLAM", "groundtruth"]
    assert (
        "topic /ground_truth, read for the pose of 'bot', is not in this bag; did you mean groundtruth? "
        f"(the bag's pose topics: {', '.join(poses)})"
    ) in said, said


@pytest.fixture(scope="module")
def nav2_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    folder = tmp_path_factory.mktemp("unread")
    (folder / "drive.exsce").write_text(NAV2)
    scenario = load_spec(folder / "drive.exsce").scenario()
    (run,) = simulate(scenario, folder / "runs", fmt="ros1", seed=4, convention="nav2")
    return run.bag, analyse_bag(run.bag, scenario).problems


def test_a_topic_in_another_namespace_is_the_closest(nav2_run: tuple[Path, list[str]]) -> None:
    bag, problems = nav2_run
    twists = topics_of(bag, "geometry_msgs/msg/Twist")
    assert twists == ["/cmd_vel"]
    (said,) = [p for p in problems if p.startswith("topic /robot1/cmd_vel") and "did you mean" in p]
    assert said == (
        "topic /robot1/cmd_vel, read for metric commanded_top_speed, is not in this bag; did you mean "
        "/cmd_vel? (the bag's geometry_msgs/msg/Twist topics: /cmd_vel)"
    )


def test_a_misspelt_navigation_action_is_checked_against_the_bags_actions(
    nav2_run: tuple[Path, list[str]],
) -> None:
    bag, problems = nav2_run
    statuses = topics_of(bag, "action_msgs/msg/GoalStatusArray")
    assert statuses == ["/navigate_to_pose/_action/status"]
    (said,) = [p for p in problems if "/navigate_to_pos," in p]
    assert said == (
        "action /navigate_to_pos, read for the navigation of 'bot', is not in this bag; did you mean "
        "/navigate_to_pose? (the bag's navigation action topics: /navigate_to_pose)"
    )


@pytest.mark.parametrize(
    ("name", "candidates", "expected"),
    [
        ("distance_travelld", ["distance_to_obstacles", "distance_travelled", "max_velocity"], ["distance_travelled"]),
        ("zzz", ["distance_travelled", "max_velocity"], []),
        ("/ground_truth", ["/groundtruth", "/ground_truth_raw", "/odom"], ["/groundtruth", "/ground_truth_raw"]),
    ],
)  # fmt: skip
def test_closest_several_keeps_only_those_nearly_as_close_as_the_closest(
    name: str, candidates: list[str], expected: list[str]
) -> None:
    assert closest_several(name, candidates) == expected
