"""``exscec bag info``: what a bag holds, checked against rosbags' own reading of the bag.

Issue 33's first command, started here: the executor's Nav2 run restamped onto a simulated clock
(stamps of a simulation, log time of the wall clock) and its method run.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.bag_info import bag_info_of
from exsce_dsl.sim.run import simulate

from tests.support.bag_factory import typestore_for, write_bag
from tests.support.cli import exscec_here
from tests.support.clock_bags import restamp
from tests.support.real_shapes import SHAPES

SPEC = Path(__file__).resolve().parents[2] / "examples" / "brsu_building_c" / "scenario_c.exsce"


@pytest.fixture(scope="module")
def bags(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("bags")
    scenario = load_spec(SPEC).scenario("scenario_c")
    (nav2,) = simulate(scenario, folder / "nav2", fmt="mcap", seed=5, convention="nav2")
    (method,) = simulate(scenario, folder / "method", seed=5)
    return {"simulated": restamp(nav2.bag, folder / "simulated", "mcap", clock_hz=50.0), "method": method.bag}


def _counted(bag: Path) -> dict[str, int]:
    """Messages per topic, counted one by one through rosbags."""
    counts: dict[str, int] = {}
    with AnyReader([bag]) as reader:
        for connection, _, _ in reader.messages():
            counts[connection.topic] = counts.get(connection.topic, 0) + 1
    return counts


def test_a_simulated_nav2_bag_says_its_topics_clocks_tf_goals_and_conventions(bags: dict[str, Path]) -> None:
    info = bag_info_of(bags["simulated"])
    topics = {t.name: t for t in info.topics}
    assert {name: t.messages for name, t in topics.items()} == _counted(bags["simulated"])
    assert info.timeline.startswith("simulated time")
    assert topics["/tiago1/odom"].clock == "simulated" and topics["/tiago1/odom"].offset > 1e9
    assert topics["/tiago1/cmd_vel"].clock == "log time"
    assert topics["/tiago1/odom"].rate == pytest.approx(50.0, rel=0.02)
    assert ("map", "odom", False) in info.tf_edges and ("odom", "base_link", False) in info.tf_edges
    # scenario_c: tiago1 visits delivery_a's two waypoints and its home; every goal succeeded
    assert info.goals["/tiago1/navigate_to_pose/_action/status"] == {"SUCCEEDED": 3}
    assert info.conventions == (
        "namespace 'tiago1': convention nav2 (from /tiago1/navigate_to_pose/_action/status)",
        "namespace 'tiago2': convention nav2 (from /tiago2/navigate_to_pose/_action/status)",
    )


def test_the_command_prints_a_table_and_json(bags: dict[str, Path], tmp_path: Path) -> None:
    table = exscec_here("bag", "info", str(bags["method"]), cwd=tmp_path)
    assert table.returncode == 0, table.stderr
    assert "timeline  wall clock" in table.stdout
    assert "namespace 'tiago1': convention method (from /tiago1/waypoint_dispatcher/feedback)" in table.stdout
    listed = exscec_here(
        "bag", "info", "-f", "json", str(bags["method"]), str(bags["simulated"]), cwd=tmp_path
    )
    assert listed.returncode == 0, listed.stderr
    method, simulated = json.loads(listed.stdout)
    assert method["format"] == "ROS 1" and simulated["format"] == "ROS 2 (MCAP)"
    assert {t["name"]: t["messages"] for t in method["topics"]} == _counted(bags["method"])


def test_a_file_that_is_no_bag_is_named_with_the_reason(tmp_path: Path) -> None:
    junk = tmp_path / "junk.bag"
    junk.write_bytes(b"not a bag at all")
    found = exscec_here("bag", "info", str(junk), cwd=tmp_path)
    assert found.returncode == 2 and "junk.bag" in found.stderr and "Traceback" not in found.stderr


def test_each_tf_edge_has_its_rate_and_static_ones_none(tmp_path: Path) -> None:
    store = typestore_for("mcap")
    bag = tmp_path / "tf_only"
    write_bag(bag, "mcap", SHAPES["tf_only"](store), store)
    info = bag_info_of(bag)
    # the shape publishes map -> odom at 10 Hz and odom -> base_link at 30 Hz, the laser mount once
    assert dict(info.tf_rates) == pytest.approx({("map", "odom"): 10.0, ("odom", "base_link"): 30.0})
    assert ("base_link", "base_laser_link", True) in info.tf_edges
    assert {t.definition for t in info.topics} == {"the bag"}  # rosbags' writers always keep them
    table = exscec_here("bag", "info", str(bag), cwd=tmp_path).stdout
    assert "map -> odom (10.0 Hz)" in table and "base_link -> base_laser_link (static)" in table
