"""Every function docs/language.md lists computes, at ingest, what it says (issue 32, item 7).

One executor run of one robot; a metric per function, signed constants and
nested arithmetic among them.  Each value is compared with the same quantity
computed here in plain Python loops over the messages as rosbags deserialises
them, over the robot's window (first action's start to last action's end).
"""

from __future__ import annotations

import bisect
import math
import statistics
from pathlib import Path
from typing import Any

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.model.expressions import CONDITION_AGGREGATES, FUNCTIONS, Aggregate, Call, walk
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate

from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"
READS = """\
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  reads pose: geometry_msgs/msg/PoseWithCovarianceStamped on "/{ns}/robot_pose"
  reads dist: std_msgs/msg/Float64 on "/{ns}/distance_travelled"
  reads feedback: waypoint_dispatcher/msg/FollowWaypointsActionFeedback on "/{ns}/waypoint_dispatcher/feedback"
  reads result: waypoint_dispatcher/msg/FollowWaypointsActionResult on "/{ns}/waypoint_dispatcher/result"
"""
X, Y = "pose.pose.pose.position.x", "pose.pose.pose.position.y"
METRICS = {
    "f_min": "min(vel.linear.x)",
    "f_max": "max(vel.angular.z)",
    "f_mean": "mean(vel.linear.x)",
    "f_sum": "sum(dist.data)",
    "f_first": f"first({X})",
    "f_last": f"last({Y})",
    "f_integral": "integral(vel.linear.x)",
    "f_change": "change(dist.data)",
    "f_path_length": f"path_length({X}, {Y})",
    "f_norm": "max(norm(vel.linear.x, vel.angular.z, -1))",
    "f_abs": "mean(abs(vel.angular.z))",
    "f_sqrt": "max(sqrt(abs(vel.angular.z)))",
    "f_speed": f"max(speed({X}, {Y}))",
    "f_derivative": "mean(derivative(dist.data))",
    "f_duration": "duration where vel.linear.x > -100",
    "f_count": "count where vel.angular.z < -0.1 rad/s",
    "f_where": "max(vel.linear.x where vel.angular.z > 0.05)",
    "signed_factor": "max(vel.linear.x * -1)",
    "parenthesised": "max(vel.linear.x + (0 - 100))",
    "nested": "max((vel.linear.x + 1) * (2 - vel.angular.z) / sqrt(abs(vel.linear.y) + 1)) - -1 * 2",
    "aligned": "mean(dist.data - vel.linear.x)",
    "windows": "elapsed / 2 + succeeded * -1",
}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("functions")
    declared = "".join(
        f"metric {name} for each robot {{\n{READS}  value {v}\n}}\n" for name, v in METRICS.items()
    )
    spec = folder / "spec.exsce"
    spec.write_text(
        "".join(
            f'import "{BUILDING}/{f}"\n'
            for f in ("environment.exsce", "robots.exsce", "tasks/deliveries.exsce")
        )
        + declared
        + "scenario one in brsu_building_c_with_doors {\n  robots {\n    tiago1: tiago starts at classroom_c025-w001\n"
        "  }\n  mission one_mission parallel {\n    tiago1 does delivery_a\n  }\n}\n"
    )
    loaded = load_spec(spec)
    bag = next(iter(simulate(loaded.scenario(), folder, runs=1, seed=6))).bag
    return loaded, bag, analyse_bag(bag, loaded.scenario())


def _messages(bag: Path, topic: str) -> list[tuple[float, Any]]:
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        return [(t / 1e9, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages(connections)]


def _at(times: list[float], values: list[float], when: float) -> float:
    """``values`` at ``when``, linear between messages, held before the first and after the last."""
    if when <= times[0]:
        return values[0]
    if when >= times[-1]:
        return values[-1]
    k = bisect.bisect_right(times, when)
    share = (when - times[k - 1]) / (times[k] - times[k - 1])
    return values[k - 1] + share * (values[k] - values[k - 1])


def _duration(times: list[float], held: list[bool]) -> float:
    period = statistics.median(b - a for a, b in zip(times, times[1:], strict=False))
    total = 0.0
    for k, t in enumerate(times):
        if held[k]:
            total += min(times[k + 1] - t if k + 1 < len(times) else period, 2 * period)
    return total


def _over_baseline(times: list[float], columns: list[list[float]], k: int) -> list[float]:
    """Change of each column from 0.25 s before to 0.25 s after message k, per second."""
    before, after = max(times[k] - 0.25, times[0]), min(times[k] + 0.25, times[-1])
    return [(_at(times, c, after) - _at(times, c, before)) / (after - before) for c in columns]


def _references(bag: Path, start: float, end: float) -> dict[str, float]:
    vel = _messages(bag, "/tiago1/nav_vel")
    pose = _messages(bag, "/tiago1/robot_pose")
    dist = _messages(bag, "/tiago1/distance_travelled")
    (result,) = _messages(bag, "/tiago1/waypoint_dispatcher/result")
    tv = [t for t, _ in vel if start <= t <= end]
    vx = [m.linear.x for t, m in vel if start <= t <= end]
    vy = [m.linear.y for t, m in vel if start <= t <= end]
    wz = [m.angular.z for t, m in vel if start <= t <= end]
    tp, px, py = (
        [t for t, _ in pose],
        [m.pose.pose.position.x for _, m in pose],
        [m.pose.pose.position.y for _, m in pose],
    )
    td, dd = [t for t, _ in dist], [m.data for _, m in dist]
    inside_p = [k for k, t in enumerate(tp) if start <= t <= end]
    inside_d = [k for k, t in enumerate(td) if start <= t <= end]
    tall, vall = [t for t, _ in vel], [m.linear.x for _, m in vel]
    # the right operand is interpolated at the left one's times, where both have data
    aligned = [dd[k] - _at(tall, vall, td[k]) for k in inside_d if tall[0] <= td[k] <= tall[-1]]
    succeeded = sum(s.status == s.SUCCEEDED for s in result[1].result.goal_status.status_list)
    return {
        "f_min": min(vx),
        "f_max": max(wz),
        "f_mean": sum(vx) / len(vx),
        "f_sum": sum(dd[k] for k in inside_d),
        "f_first": px[inside_p[0]],
        "f_last": py[inside_p[-1]],
        "f_integral": sum((tv[k + 1] - tv[k]) * (vx[k] + vx[k + 1]) / 2 for k in range(len(tv) - 1)),
        "f_change": _at(td, dd, end) - _at(td, dd, start),
        "f_path_length": sum(math.hypot(px[k + 1] - px[k], py[k + 1] - py[k]) for k in inside_p[:-1]),
        "f_norm": max(math.sqrt(x * x + z * z + 1) for x, z in zip(vx, wz, strict=True)),
        "f_abs": sum(abs(z) for z in wz) / len(wz),
        "f_sqrt": max(math.sqrt(abs(z)) for z in wz),
        "f_speed": max(math.hypot(*_over_baseline(tp, [px, py], k)) for k in inside_p),
        "f_derivative": sum(_over_baseline(td, [dd], k)[0] for k in inside_d) / len(inside_d),
        "f_duration": _duration(tv, [x > -100 for x in vx]),
        "f_count": sum(z < -0.1 for z in wz),
        "f_where": max(x for x, z in zip(vx, wz, strict=True) if z > 0.05),
        "signed_factor": max(-x for x in vx),
        "parenthesised": max(x - 100 for x in vx),
        "nested": max((x + 1) * (2 - z) / math.sqrt(abs(y) + 1) for x, y, z in zip(vx, vy, wz, strict=True))
        + 2,
        "aligned": sum(aligned) / len(aligned),
        "windows": (end - start) / 2 - succeeded,
    }


def test_every_function_the_readme_lists_is_exercised(run):
    spec, _, _ = run
    used = {n.func for m in spec.metrics for n in walk(m.value) if isinstance(n, (Call, Aggregate))}
    assert used == set(FUNCTIONS) | set(CONDITION_AGGREGATES)


def test_each_function_computes_what_a_loop_over_the_messages_computes(run):
    _, bag, analysed = run
    actions = [a for task in analysed.run.tasks for a in task.actions]
    start, end = min(a.start for a in actions).timestamp(), max(a.end for a in actions).timestamp()
    expected = _references(bag, start, end)
    got = {v.metric: v.value for v in analysed.run.metrics if v.metric in METRICS and v.action is None}
    assert set(got) == set(METRICS), analysed.problems
    for name, value in expected.items():
        assert got[name] == pytest.approx(value, rel=1e-9, abs=1e-9), (name, METRICS[name])


def test_speed_from_noisy_poses_follows_the_commanded_speed(run):
    """The executor's poses carry centimetre noise at 50 Hz: the speed estimate still follows the
    velocity it was commanded (within a few cm/s), where neighbour differences would not."""
    _, bag, analysed = run
    pose = _messages(bag, "/tiago1/robot_pose")
    naive = [
        math.hypot(
            b.pose.pose.position.x - a.pose.pose.position.x, b.pose.pose.position.y - a.pose.pose.position.y
        )
        / (tb - ta)
        for (ta, a), (tb, b) in zip(pose, pose[1:], strict=False)
    ]
    commanded = max(math.hypot(m.linear.x, m.linear.y) for _, m in _messages(bag, "/tiago1/nav_vel"))
    assert max(naive) > commanded + 0.3
    (value,) = [v.value for v in analysed.run.metrics if v.metric == "f_speed" and v.action is None]
    assert value == pytest.approx(commanded, abs=0.08)
