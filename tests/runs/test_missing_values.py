"""Missing, never 0 (issue 32, item 2): a value computed from a missing value is missing.

Executor bags are copied with some topics dropped or moved in time (their log
times put 928 s after the epoch, as a simulator's clock would, while the rest
stays on the wall clock); what lost its data must have no value, and the run's
problems must say why, naming both time ranges where a window does not overlap
a series.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest
from rosbags.rosbag1 import Reader as Ros1Reader
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate

from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"
Change = Callable[[str, int], int | None]
"""(topic, log time in ns) → the time to write the message at, or None to drop it."""


def rewrite(source: Path, target: Path, change: Change) -> Path:
    """Copy a ROS 1 bag, each message at the time ``change`` gives (or dropped)."""
    store = get_typestore(Stores.ROS1_NOETIC)
    kept: list[tuple[str, str, str, str, int, bytes]] = []
    with Ros1Reader(source) as reader:
        for conn, timestamp, raw in reader.messages():
            when = change(conn.topic, timestamp)
            if when is not None:
                kept.append((conn.topic, conn.msgtype, conn.msgdef.data, conn.digest, when, bytes(raw)))
    with Ros1Writer(target) as writer:
        conns = {}
        for topic, msgtype, msgdef, digest, when, raw in sorted(kept, key=lambda m: m[4]):
            if topic not in conns:
                conns[topic] = writer.add_connection(
                    topic, msgtype, msgdef=msgdef, md5sum=digest, typestore=store
                )
            writer.write(conns[topic], when, raw)
    return target


@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(BUILDING / "scenario_c.exsce").scenario()


@pytest.fixture(scope="module")
def run_c(scenario_c, tmp_path_factory):
    out = tmp_path_factory.mktemp("missing")
    return next(iter(simulate(scenario_c, out, runs=1, seed=8))).bag


def _values(analysed, metric: str, robot: str | None) -> list:
    return [
        v
        for v in analysed.run.metrics
        if v.metric == metric and (v.robot == robot or (v.action is not None and v.action.robot == robot))
    ]


def test_a_window_that_misses_a_series_gives_no_value_and_names_both_time_ranges(scenario_c, run_c, tmp_path):
    moved = ("/tiago1/distance_travelled", "/tiago1/nav_vel")
    first: dict[str, int] = {}

    def on_sim_clock(topic: str, t: int) -> int:
        if topic not in moved:
            return t
        first.setdefault(topic, t)
        return 928_000_000_000 + t - first[topic]

    bag = rewrite(run_c, tmp_path / "sim_clock.bag", on_sim_clock)
    analysed = analyse_bag(bag, scenario_c)
    full = analyse_bag(run_c, scenario_c)
    for metric in ("distance_travelled", "max_velocity", "fast_driving_time", "mean_turn_rate"):
        assert _values(full, metric, "tiago1"), metric  # the full bag has them
        assert _values(analysed, metric, "tiago1") == [], metric  # never 0
        assert _values(analysed, metric, "tiago2"), metric
    violations = {
        (v.robot, v.safety_metric) for v in analysed.run.metrics if v.metric == "violation_duration"
    }
    assert ("tiago1", "max_velocity") not in violations
    assert ("tiago2", "max_velocity") in violations and ("tiago1", "distance_to_obstacles") in violations
    assert not any(h.metric == "max_velocity" and h.robot == "tiago1" for h in analysed.run.hotspots)
    window = r"the window 17\d{8}\.\d{3}\.\.17\d{8}\.\d{3} s does not overlap "
    series = r" \(928\.000\.\.1\d{3}\.\d{3} s\)"
    for told, topic in (
        ("distance_travelled of 'tiago1' is missing: ", "/tiago1/distance_travelled"),
        ("max_velocity of 'tiago1' and its violation duration are missing: ", "/tiago1/nav_vel"),
    ):
        (problem,) = [p for p in analysed.problems if p.startswith(told)]
        assert re.fullmatch(re.escape(told) + window + re.escape(topic) + series, problem), problem
    (segments,) = [
        p for p in analysed.problems if p.startswith("fast_driving_time of 'tiago1' is missing for")
    ]
    assert segments.startswith(
        "fast_driving_time of 'tiago1' is missing for 3 of 3 path segments (the first: "
    )


THREE = f"""\
import "{BUILDING}/environment.exsce"
import "{BUILDING}/robots.exsce"
import "{BUILDING}/tasks/deliveries.exsce"

scenario three in brsu_building_c_with_doors {{
  robots {{
    tiago1: tiago starts at classroom_c025-w001
    tiago2: tiago starts at classroom_c025-w002
    tiago3: tiago starts at classroom_c069-w001
  }}
  mission three_mission parallel {{
    tiago1 does delivery_a
    tiago2 does delivery_b
    tiago3 does delivery_c
  }}
}}
"""


def test_a_mission_value_over_pairs_is_missing_when_one_pair_lacks_its_data(tmp_path):
    (tmp_path / "three.exsce").write_text(THREE)
    scenario = load_spec(tmp_path / "three.exsce").scenario()
    full_bag = next(iter(simulate(scenario, tmp_path, runs=1, seed=2))).bag
    full = analyse_bag(full_bag, scenario)
    assert _values(full, "distance_between_robots", None)
    bag = rewrite(
        full_bag, tmp_path / "no_pose.bag", lambda topic, t: None if topic == "/tiago3/robot_pose" else t
    )
    analysed = analyse_bag(bag, scenario)
    # the two pairs of tiago1 and tiago2 have values, but tiago3 might have been the closest
    assert _values(analysed, "distance_between_robots", None) == []
    assert not [v for v in analysed.run.metrics if v.safety_metric == "distance_between_robots"]
    assert not [h for h in analysed.run.hotspots if h.metric == "distance_between_robots"]
    (told,) = [p for p in analysed.problems if p.startswith("distance_between_robots of the mission")]
    assert "tiago1 and tiago3 (no /tiago3/robot_pose)" in told and "tiago2 and tiago3" in told
    assert "tiago1 and tiago2" not in told
    assert _values(analysed, "max_velocity", "tiago3")  # its other data is still there
