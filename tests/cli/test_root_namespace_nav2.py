"""A Nav2 robot at the root (``namespace ""``, ``convention nav2``) through the whole method with the
real exscec (issue 32, item 4): simulate writes Nav2-convention bags (/cmd_vel, /odom, /scan,
/navigate_to_pose/_action/status...), then ingest, baseline, verify, derive --expect and report
exit 0, without a warning, and the stored values are those read from the bags with rosbags.

``exscec baseline`` failed for every built-in metric with ``'//nav_vel' is not an absolute ROS topic
name``: the oracles' topics of a robot at the root were written ``/{ns}/nav_vel`` by hand."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"
SPEC = f"""\
import "{BUILDING}/environment.exsce"
import "{BUILDING}/tasks/deliveries.exsce"

robot type rover {{
  base pmb2
  torso no
  convention nav2
}}

metric mean_speed for each robot {{
  "mean forward speed, commanded"
  unit m/s
  reads vel: geometry_msgs/msg/Twist on "cmd_vel"
  value mean(abs(vel.linear.x))
}}

scenario at_root in brsu_building_c_with_doors {{
  robots {{
    bot: rover namespace "" starts at classroom_c025-w001
  }}
  mission at_root_mission sequential {{
    bot does delivery_a
  }}
}}

acceptance for at_root {{
  scenario "moves safely" {{
    when at_root_mission runs
    then each robot max_velocity stays below 1.0 m/s
     and each robot distance_to_obstacles stays above 0.1 m
     and each robot mean_speed stays below 2 m/s
  }}
  scenario "performs as before" {{
    given at least 3 baseline runs
    when at_root_mission runs
    then each robot task_duration is invariant within 3 std
     and each robot distance_travelled is invariant within 5 %
     and each robot waypoints_visited is invariant within 0
     and mission_duration is invariant within 10 s
  }}
}}
"""
EXECUTING, SUCCEEDED = 2, 4  # action_msgs/msg/GoalStatus


def ok(*args: str) -> str:
    """exscec's stderr, after checking that it exited 0 and warned of nothing."""
    done = exscec_here(*args)
    assert done.returncode == 0, f"exscec {' '.join(args)}:\n{done.stdout}\n{done.stderr}"
    assert "warning" not in done.stderr and "Traceback" not in done.stderr, done.stderr
    return done.stdout


def by_rosbags(bag: Path) -> dict[str, float]:
    """The robot's values read from its bag with rosbags: the mission from the first goal that
    went EXECUTING to the last that SUCCEEDED (log times), speeds of /cmd_vel and the path along
    /odom in that window, the nearest valid range of /scan in it, goals SUCCEEDED."""
    with AnyReader([bag]) as reader:
        conns = {c.topic: c for c in reader.connections}
        assert {"/cmd_vel", "/odom", "/scan", "/navigate_to_pose/_action/status"} <= set(conns), conns

        def read(topic: str) -> list[tuple[float, object]]:
            c = conns[topic]
            return [(t / 1e9, reader.deserialize(raw, c.msgtype)) for _, t, raw in reader.messages([c])]

        statuses = read("/navigate_to_pose/_action/status")
        started = min(t for t, m in statuses if any(s.status == EXECUTING for s in m.status_list))
        done: dict[bytes, float] = {}
        for t, m in statuses:
            for s in m.status_list:
                if s.status == SUCCEEDED:
                    done.setdefault(bytes(s.goal_info.goal_id.uuid), t)
        ended = max(done.values())
        inside = lambda pairs: [m for t, m in pairs if started <= t <= ended]  # noqa: E731
        vel = inside(read("/cmd_vel"))
        odom = np.array([[m.pose.pose.position.x, m.pose.pose.position.y] for m in inside(read("/odom"))])
        ranges = [r for m in inside(read("/scan")) for r in m.ranges if m.range_min <= r <= m.range_max]
    return {
        "task_duration": ended - started,
        "waypoints_visited": float(len(done)),
        "max_velocity": max(float(np.hypot(m.linear.x, m.linear.y)) for m in vel),
        "mean_speed": float(np.mean([abs(m.linear.x) for m in vel])),
        "distance_travelled": float(np.sum(np.hypot(*np.diff(odom, axis=0).T))),
        "distance_to_obstacles": float(min(ranges)),
    }


def stored(run: str, metric: str) -> float:
    table = ok("query", "run_metric", "-p", f"run={run}", "-p", f"metric={metric}", "-p", "robot=bot",
               "--format", "csv")
    return float(table.splitlines()[1].split(",")[0])


def test_a_nav2_robot_at_the_root_goes_through_the_whole_method(in_tmp: Path) -> None:
    Path("at_root.exsce").write_text(SPEC)
    ok("simulate", "at_root.exsce", "--runs", "3", "-o", "runs", "--seed", "5", "--convention", "nav2")
    bags = sorted(str(p) for p in Path("runs").glob("*.bag"))
    assert len(bags) == 3
    ok("ingest", *bags, "--scenario", "at_root.exsce")
    ok("baseline", "at_root.exsce")
    # a run the baseline did not use (verifying its own runs warns: they are in its mean)
    ok("simulate", "at_root.exsce", "--runs", "1", "-o", "new", "--seed", "6", "--convention", "nav2")
    [new] = sorted(str(p) for p in Path("new").glob("*.bag"))
    verdicts = json.loads(ok("verify", new, "--scenario", "at_root.exsce", "--json"))
    assert len(verdicts) == 7 and all(v["verdict"] == "passed" for v in verdicts), verdicts
    runs = json.loads(ok("runs", "--format", "json"))["results"]["bindings"]
    for row in runs:
        expected = by_rosbags(Path(row["path"]["value"]))
        for metric in ("waypoints_visited", "max_velocity", "mean_speed", "distance_travelled",
                       "distance_to_obstacles"):
            assert stored(row["run"]["value"], metric) == pytest.approx(expected[metric], rel=1e-9), metric
        # the goals' ends are their statuses' log times; the executor publishes a transition at once
        assert stored(row["run"]["value"], "task_duration") == pytest.approx(expected["task_duration"], abs=0.05)
    ok("derive", "at_root.exsce", "--id", "at_root_rev", "-t", "reverse_waypoint_order", "--task", "delivery_a",
       "-o", "at_root_rev.exsce", "--expect", "--add-to-store")
    derived = Path("at_root_rev.exsce").read_text()
    assert 'namespace ""' in derived and "bot distance_travelled is" in derived
    ok("check", "at_root_rev.exsce")
    ok("report", "-o", "report", "--spec", "at_root.exsce")
    assert "at_root" in Path("report/index.html").read_text()
