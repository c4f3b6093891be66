"""Nothing that lost its data comes out as a number (issue 32, item 2), as a property.

Hypothesis drops random topics of an executor run of scenario_c (each robot's
velocity, pose, laser, distance and dispatcher result), and moves some onto
another clock.  For every built-in metric and a few of the user's, the inputs
are written out here by hand, per alternative (``otherwise``); a velocity or a
distance the bag lacks is estimated from the robot's pose, when it has one.  A
metric none of whose alternatives has all its inputs, or that reads a topic no
window overlaps, must have no value (nor violation duration, nor hotspot), and
the run's problems must name it; a metric whose first alternative kept its
topics must have the full bag's values; one read from an estimated velocity says
so.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_missing_values import rewrite

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate

from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"
ROBOTS = ("tiago1", "tiago2")
DROPPABLE = ("nav_vel", "robot_pose", "scan", "distance_travelled", "waypoint_dispatcher/result")

USER_METRICS = """
metric pose_speed for each robot per segment {
  unit m/s
  reads pose: geometry_msgs/msg/PoseWithCovarianceStamped on "/{ns}/robot_pose"
  value max(speed(pose.pose.pose.position.x, pose.pose.pose.position.y))
}
metric scan_and_speed for each robot {
  reads scan: sensor_msgs/msg/LaserScan on "/{ns}/scan"
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  value min(scan.range_max) - -max(vel.linear.x)
}
metric travelled_or_fastest for each robot {
  reads dist: std_msgs/msg/Float64 on "/{ns}/distance_travelled"
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  value change(dist.data)
  otherwise max(vel.linear.x)
}
metric speed_gap for each pair of robots (a, b) {
  unit m/s
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  value max(a.vel.linear.x - b.vel.linear.x)
}
"""

# Each metric's alternatives, each the topics (under /<robot>/) it reads; None: dispatcher windows only.
ROBOT_INPUTS: dict[str, list[list[str]]] = {
    "waypoints_visited": [["waypoint_dispatcher/result"]],
    "distance_travelled": [["distance_travelled"], ["robot_pose"]],
    "distance_to_obstacles": [["scan"]],
    "max_velocity": [["nav_vel"]],
    "fast_driving_time": [["nav_vel"]],
    "mean_turn_rate": [["nav_vel"]],
    "pose_speed": [["robot_pose"]],
    "scan_and_speed": [["scan", "nav_vel"]],
    "travelled_or_fastest": [["distance_travelled"], ["nav_vel"]],
}
PAIR_INPUTS = {"distance_between_robots": "robot_pose", "speed_gap": "nav_vel"}
SAFETY = {"distance_to_obstacles", "max_velocity", "distance_between_robots"}


@pytest.fixture(scope="module")
def full_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dropped")
    spec = folder / "scenario_c.exsce"
    spec.write_text((BUILDING / "scenario_c.exsce").read_text().replace('import "', f'import "{BUILDING}/'))
    (folder / "more.exsce").write_text(USER_METRICS)
    spec.write_text(f'import "more.exsce"\n{spec.read_text()}')
    scenario = load_spec(spec).scenario()
    bag = next(iter(simulate(scenario, folder, runs=1, seed=9))).bag
    return folder, scenario, bag, analyse_bag(bag, scenario)


def _key(v) -> tuple:
    return (v.metric, v.scope, v.robot, v.action, v.safety_metric)


def _of(v, metric: str, robot: str | None) -> bool:
    """Whether ``v`` is (or is the violation duration of) ``metric`` of ``robot`` (None: the mission's)."""
    owner = v.robot if v.action is None else v.action.robot
    return (v.metric == metric or v.safety_metric == metric) and owner == robot


def _changed(gone: set[str], moved: set[str]):
    first: dict[str, int] = {}

    def change(topic: str, t: int) -> int | None:
        if topic in gone:
            return None
        if topic in moved:  # onto a simulator's clock, 928 s after the epoch
            return 928_000_000_000 + t - first.setdefault(topic, t)
        return t

    return change


ESTIMATED_FROM = {"nav_vel": "robot_pose", "distance_travelled": "robot_pose"}
"""What a dropped topic is estimated from (a robot's speed and distance along its pose)."""


def _source(robot: str, topic: str, gone: set[str], elsewhere: set[str]) -> str | None:
    """Where ``/robot/topic`` comes from in the changed bag: ``recorded``, ``moved`` to another
    clock, ``estimated`` from another topic, or nowhere (None)."""
    name = f"/{robot}/{topic}"
    if name in elsewhere:
        return "moved"
    if name not in gone:
        return "recorded"
    source = ESTIMATED_FROM.get(topic)
    return "estimated" if source is not None and f"/{robot}/{source}" not in gone else None


ROBOT_TOPICS = st.tuples(st.sampled_from(ROBOTS), st.sampled_from(DROPPABLE))
UNSTAMPED = st.tuples(st.sampled_from(ROBOTS), st.sampled_from(("nav_vel", "distance_travelled")))


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(dropped=st.sets(ROBOT_TOPICS, max_size=4), moved=st.sets(UNSTAMPED, max_size=2))
def test_a_metric_that_lost_its_data_has_no_value_and_the_problems_say_so(full_run, dropped, moved):
    """Dropped topics, and topics whose log times are on another clock (messages without a
    stamp, so that nothing can put them back on the run's timeline): no window overlaps them."""
    folder, scenario, full_bag, full = full_run
    gone = {f"/{robot}/{name}" for robot, name in dropped}
    elsewhere = {f"/{robot}/{name}" for robot, name in moved} - gone
    (folder / "changed.bag").unlink(missing_ok=True)
    bag = rewrite(full_bag, folder / "changed.bag", _changed(gone, elsewhere))
    analysed = analyse_bag(bag, scenario)
    values = analysed.run.metrics
    assert all(math.isfinite(v.value) for v in values)
    before = {_key(v): v.value for v in full.run.metrics}
    lost: list[tuple[str, str | None]] = []
    for metric, alternatives in ROBOT_INPUTS.items():
        for robot in ROBOTS:
            sources = [[_source(robot, topic, gone, elsewhere) for topic in alt] for alt in alternatives]
            # 'otherwise' when the value's topics are absent (and cannot be estimated)
            chosen = next((k for k, found in enumerate(sources) if None not in found), None)
            mine = [v for v in values if _of(v, metric, robot)]
            if chosen is None or "moved" in sources[chosen]:
                lost.append((metric, robot))
                assert mine == [], (metric, robot, mine)
                assert not [h for h in analysed.run.hotspots if h.metric == metric and h.robot == robot]
            elif chosen == 0 and set(sources[0]) == {"recorded"}:
                assert {_key(v): v.value for v in mine} == {
                    k: x for k, x in before.items() if k in map(_key, mine)
                }
                assert len(mine) == len([v for v in full.run.metrics if _of(v, metric, robot)]), (
                    metric,
                    robot,
                )
            elif "nav_vel" in alternatives[chosen] and sources[chosen][
                alternatives[chosen].index("nav_vel")
            ] == ("estimated"):
                assert all(v.estimated_from == "pose" for v in mine), (metric, robot, mine)
    for metric, topic in PAIR_INPUTS.items():
        mine = [v for v in values if _of(v, metric, None)]
        found = {_source(robot, topic, gone, elsewhere) for robot in ROBOTS}
        if None in found or "moved" in found:
            lost.append((metric, None))
            assert mine == [], (metric, mine)
            assert not [h for h in analysed.run.hotspots if h.metric == metric]
        elif found == {"recorded"}:
            assert {_key(v): v.value for v in mine} == {
                _key(v): v.value for v in full.run.metrics if _of(v, metric, None)
            }
    for metric, robot in lost:
        who = f"'{robot}'" if robot else "the mission"
        assert any(metric in p and who in p for p in analysed.problems), (metric, robot, analysed.problems)
