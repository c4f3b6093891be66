"""Issue 47, item 1: a whole-run window is the recording (or the recorded goals' span, or what the
spec says), never an arrival.  A robot without recorded goals whose pose passes its last planned
waypoint long before the recording ends is segmented by arrival, and its segments end at the
arrivals; its whole-run values (``distance_travelled``, ``task_duration``, ``mission_duration``)
cover every message of the recording.  References come from rosbags' deserialisation and numpy.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.model.runs import MetricScope
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag
from exsce_dsl.runs.spec_draft import draft_spec

from tests.support.bag_factory import (
    ODOMETRY,
    START_NS,
    Topic,
    odometry_at,
    typestore_for,
    write_bag,
)
from tests.support.paths import ROOT

REALBAGS = ROOT / "tests" / "fixtures" / "realbags"
HUSKY = REALBAGS / "robot_localization" / "test1.bag"
HUSKY_ODOM = "/husky_velocity_controller/odom"
TOLERANCE = 0.35
"""The default arrival tolerance (m)."""

CORNERS = np.array([(0.0, 0.0), (8.0, 0.0), (8.0, 6.0), (0.0, 6.0), (0.0, 12.0), (10.0, 12.0)])
"""The drive: through ``yard-1`` (8, 0) and ``yard-2`` (8, 6), the last planned waypoint, reached
after 14 s of 60, then on for three more legs."""
SPEED = 1.0
HZ = 20.0
REST = 2.0
"""Seconds standing at the start, and at the end."""

SPEC = """
environment yard {
  area ground {
    pose yard-start at (0.0, 0.0)
    pose yard-1 at (8.0, 0.0)
    pose yard-2 at (8.0, 6.0)
  }
}

task loop {
  visit yard-1, yard-2
}

robot type rover {
  base diff_drive
}

scenario early in yard {
  robots {
    bot: rover namespace "" starts at yard-start
  }
  mission early_mission sequential {
    bot does loop
  }
}
"""


def _drive(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where the robot is at times ``t``: standing, the legs at :data:`SPEED`, standing."""
    legs = np.hypot(*np.diff(CORNERS, axis=0).T) / SPEED
    frames = np.concatenate([[0.0], REST + np.concatenate([[0.0], np.cumsum(legs)]), [2 * REST + legs.sum()]])
    at = np.vstack([CORNERS[:1], CORNERS, CORNERS[-1:]])
    return np.interp(t, frames, at[:, 0]), np.interp(t, frames, at[:, 1])




def _early_bag(folder: Path, fmt: str) -> Path:
    store = typestore_for(fmt)
    legs = float(np.sum(np.hypot(*np.diff(CORNERS, axis=0).T))) / SPEED
    t = np.arange(int(round((2 * REST + legs) * HZ)) + 1) / HZ
    x, y = _drive(t)
    messages = []
    for i, s in enumerate(t):
        ns = START_NS + int(round(s * 1e9))
        messages.append((ns, odometry_at(store, i, ns, float(x[i]), float(y[i]))))
    path = folder / (f"early_{fmt}.bag" if fmt == "ros1" else f"early_{fmt}")
    write_bag(path, fmt, [Topic("/odom", ODOMETRY, messages)], store)
    return path


def _odometry_path(bag: Path, topic: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Log times (s), x and y of every message of ``topic``, by rosbags."""
    with AnyReader(
        [bag], default_typestore=typestore_for("ros1" if bag.suffix == ".bag" else "sqlite3")
    ) as r:
        rows = [
            (t * 1e-9, m.pose.pose.position.x, m.pose.pose.position.y)
            for c, t, raw in r.messages([c for c in r.connections if c.topic == topic])
            for m in [r.deserialize(raw, c.msgtype)]
        ]
    found = np.array(rows)
    return found[:, 0], found[:, 1], found[:, 2]


def _steps(x: np.ndarray, y: np.ndarray) -> float:
    return float(np.sum(np.hypot(np.diff(x), np.diff(y))))


def _values(run: AnalysedRun, robot: str) -> dict[tuple[str, int | None], float]:
    """(metric, waypoint or None for the whole run) → value of ``robot``, and the mission's."""
    found: dict[tuple[str, int | None], float] = {}
    for v in run.run.metrics:
        if v.safety_metric is not None:
            continue
        if v.scope is MetricScope.MISSION or (v.robot == robot and v.scope is MetricScope.ROBOT):
            found[(v.metric, None)] = v.value
        elif v.robot == robot and v.action is not None:
            found[(v.metric, v.action.waypoint)] = v.value
    return found


@pytest.mark.parametrize("fmt", ["ros1", "mcap"])
def test_whole_run_window_is_never_an_arrival(fmt: str, tmp_path: Path) -> None:
    spec = tmp_path / "early.exsce"
    spec.write_text(SPEC)
    bag = _early_bag(tmp_path, fmt)
    run = analyse_bag(bag, load_spec(spec).scenario())
    t, x, y = _odometry_path(bag, "/odom")
    values = _values(run, "bot")
    (task,) = run.run.tasks
    assert task.segmented_by == "arrival at the planned waypoints"
    # whole run: every odometry message, the recording's span
    assert values[("distance_travelled", None)] == pytest.approx(_steps(x, y), rel=1e-6)
    assert values[("mission_duration", None)] == pytest.approx(t[-1] - t[0], rel=1e-6)
    assert values[("task_duration", None)] == pytest.approx(t[-1] - t[0], rel=1e-6)
    # segments: cut at the arrivals (the first sample within the tolerance of each waypoint)
    moved = int(np.flatnonzero(np.hypot(x - x[0], y - y[0]) > TOLERANCE)[0])
    start = int(np.flatnonzero(np.hypot(x[:moved] - x[0], y[:moved] - y[0]) <= 0.01)[-1])
    cuts = [start]
    for wx, wy in [(8.0, 0.0), (8.0, 6.0)]:
        cuts.append(
            cuts[-1] + int(np.flatnonzero(np.hypot(x[cuts[-1] :] - wx, y[cuts[-1] :] - wy) <= TOLERANCE)[0])
        )
    assert t[cuts[-1]] < t[-1] - 20.0, "the last waypoint is passed early: the test proves nothing"
    segments = sorted(
        (
            v
            for v in run.run.metrics
            if v.robot == "bot" and v.action is not None and v.metric == "distance_travelled"
        ),
        key=lambda v: v.action.waypoint if v.action else 0,
    )
    assert [v.value for v in segments] == pytest.approx(
        [_steps(x[a : b + 1], y[a : b + 1]) for a, b in zip(cuts, cuts[1:], strict=False)], rel=1e-6
    )
    assert sum(v.value for v in segments) < 0.5 * values[("distance_travelled", None)]


def test_whole_run_window_of_a_real_husky_is_its_recording(tmp_path: Path) -> None:
    """robot_localization's Husky (395 s, 358.79685 m of odometry): its drafted spec with planned
    waypoints it passes in its first minute and no ``window whole recording``: the whole-run
    distance is the path of every odometry message."""
    t, x, y = _odometry_path(HUSKY, HUSKY_ODOM)
    reference = _steps(x, y)
    assert reference == pytest.approx(358.79685, abs=1e-5)
    draft_spec(HUSKY, tmp_path / "husky.exsce")
    text = (tmp_path / "husky.exsce").read_text()
    assert "  window whole recording\n" in text
    text = text.replace("  window whole recording\n", "")
    early = [int(np.searchsorted(t, t[0] + s)) for s in (30.0, 60.0)]
    for name, k in zip(("farthest", "end"), early, strict=True):
        line = next(li for li in text.splitlines() if f"pose husky_velocity_controller-{name} at" in li)
        text = text.replace(line, f"    pose husky_velocity_controller-{name} at ({x[k]:.4f}, {y[k]:.4f})")
    spec = tmp_path / "husky_early.exsce"
    spec.write_text(text)
    run = analyse_bag(HUSKY, load_spec(spec).scenario())
    (task,) = run.run.tasks
    assert task.segmented_by == "arrival at the planned waypoints"
    assert task.actions[-1].end is not None and task.actions[-1].end.timestamp() < t[0] + 120.0
    values = _values(run, "husky_velocity_controller")
    assert values[("distance_travelled", None)] == pytest.approx(reference, rel=1e-6)
    # the recording: the bag's first message (its IMU's) to its last, not the odometry's span
    with AnyReader([HUSKY]) as reader:
        logged = [time for _, time, _ in reader.messages()]
    assert values[("mission_duration", None)] == pytest.approx((max(logged) - min(logged)) * 1e-9, rel=1e-6)
