"""Issue 47, item 2: several TF publishers are not a clock reset.

On a real Nav2 bag ``/tf`` carries ``odom → base_footprint`` from the controller, stamped at about
log time, and ``map → odom`` from AMCL, post-dated by its ``transform_tolerance`` (stamps up to
~1.7 s ahead of log time), the two interleaved: the stamps of "/tf" go back by 1.7 s dozens of
times a second, and that is no reset.  TF is judged per edge (parent → child), every other topic
per connection; a reset is ``/clock`` going back, or every stamped source going back together.
The bags are written here with rosbags; the references come from rosbags' deserialisation and
numpy, over every sample.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.model.coverage import Shortfall
from exsce_dsl.model.runs import MetricScope
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag

from tests.support.bag_factory import (
    ODOMETRY,
    START_NS,
    TF_MESSAGE,
    Topic,
    odometry_at,
    typestore_for,
    write_bag,
)
from tests.support.real_shapes import transform_stamped

CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
DURATION = 30.0
"""Seconds of recording: the robot stands 3 s, drives an L of 8 m and 6 m, stands to the end."""
POST_DATED = 1.7
"""Seconds AMCL's map → odom stamps are ahead of their log times (its transform tolerance)."""
MAP_TO_ODOM = (1.5, -0.5, 0.3)
"""x, y, yaw of AMCL's correction (constant: the map path is the odometry path, moved)."""

SPEC = """
environment yard {
  area ground {
    pose yard-start at (1.5, -0.5)
    pose yard-far at (40.0, 40.0)
  }
}

task far {
  visit yard-far
}

robot type rover {
  base diff_drive
  pose from tf map -> base_link
}

metric planar_path for each robot {
  unit m
  reads pose: robot pose
  value path_length(pose.x, pose.y)
}

metric odom_path for each robot {
  unit m
  reads odom: nav_msgs/msg/Odometry on "/odom"
  value path_length(odom.pose.pose.position.x, odom.pose.pose.position.y)
}

scenario tfs in yard {
  robots {
    bot: rover namespace "" starts at yard-start
  }
  mission tfs_mission sequential {
    bot does far
  }
}
"""


def _drive(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x, y, yaw in the odometry frame at times ``t`` (seconds from the start)."""
    frames = np.array([0.0, 3.0, 11.0, 17.0, DURATION])
    x = np.interp(t, frames, [0.0, 0.0, 8.0, 8.0, 8.0])
    y = np.interp(t, frames, [0.0, 0.0, 0.0, 6.0, 6.0])
    return x, y, np.where(t < 11.0, 0.0, np.pi / 2)




def _clock(store: Any, seconds: float) -> Any:
    sec = int(np.floor(seconds))
    time = store.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=int(round((seconds - sec) * 1e9)))
    return store.types[CLOCK_TYPE](clock=time)


def _log_ns(seconds: float) -> int:
    return START_NS + int(round(seconds * 1e9))


def tf_bag(folder: Path, fmt: str, reset_at: float | None = None, with_clock: bool = True) -> Path:
    """``/tf`` (odom → base_link at 50 Hz stamped at log time, map → odom at 10 Hz stamped
    :data:`POST_DATED` s after it) and ``/odom`` at 50 Hz; with ``reset_at``: stamps in simulated
    time from 100 s, every one going back 20 s at that second (a simulation reset), and
    ``/clock`` too (``with_clock``)."""
    store = typestore_for(fmt)
    tf: list[tuple[int, Any]] = []
    odom: list[tuple[int, Any]] = []
    clock: list[tuple[int, Any]] = []

    def stamp(seconds: float) -> int:
        if reset_at is None:
            return _log_ns(seconds)
        sim = 100.0 + seconds - (20.0 if seconds >= reset_at else 0.0)
        return int(round(sim * 1e9))

    fast = np.arange(int(DURATION * 50) + 1) / 50
    x, y, yaw = _drive(fast)
    for i, s in enumerate(fast):
        moved = transform_stamped(store, stamp(s), "odom", "base_link", x[i], y[i], yaw[i])
        tf.append((_log_ns(s), store.types[TF_MESSAGE](transforms=[moved])))
        odom.append((_log_ns(s), odometry_at(store, i, stamp(s), x[i], y[i], yaw[i])))
    for s in np.arange(int(DURATION * 10) + 1) / 10:
        moved = transform_stamped(store, stamp(s) + int(POST_DATED * 1e9), "map", "odom", *MAP_TO_ODOM)
        tf.append((_log_ns(s), store.types[TF_MESSAGE](transforms=[moved])))
        if reset_at is not None and with_clock:
            clock.append((_log_ns(s), _clock(store, stamp(s) * 1e-9)))
    tf.sort(key=lambda m: m[0])
    topics = [Topic("/tf", TF_MESSAGE, tf), Topic("/odom", ODOMETRY, odom)]
    if clock:
        topics.append(Topic("/clock", CLOCK_TYPE, clock))
    name = ("reset" if with_clock else "reset_no_clock") if reset_at is not None else "tf"
    path = folder / (f"{name}_{fmt}.bag" if fmt == "ros1" else f"{name}_{fmt}")
    write_bag(path, fmt, topics, store)
    return path


def _read(bag: Path) -> dict[str, list[Any]]:
    with AnyReader(
        [bag], default_typestore=typestore_for("ros1" if bag.suffix == ".bag" else "sqlite3")
    ) as r:
        found: dict[str, list[Any]] = {}
        for c, _, raw in r.messages():
            found.setdefault(c.topic, []).append(r.deserialize(raw, c.msgtype))
    return found


def _steps(x: np.ndarray, y: np.ndarray) -> float:
    return float(np.sum(np.hypot(np.diff(x), np.diff(y))))


def references(bag: Path) -> dict[str, float]:
    """The odometry's path over every /odom message, and the map path of base_link: every
    odom → base_link transform of /tf composed with AMCL's map → odom (constant here)."""
    messages = _read(bag)
    odom = np.array([(m.pose.pose.position.x, m.pose.pose.position.y) for m in messages["/odom"]])
    body, fixed = [], []
    for message in messages["/tf"]:
        for tr in message.transforms:
            v = tr.transform.translation
            q = tr.transform.rotation
            row = (v.x, v.y, 2 * np.arctan2(q.z, q.w))
            (body if (tr.header.frame_id, tr.child_frame_id) == ("odom", "base_link") else fixed).append(row)
    assert np.ptp(np.array(fixed), axis=0).max() < 1e-12, "map → odom is constant in this bag"
    mx, my, myaw = fixed[0]
    b = np.array(body)
    px = mx + np.cos(myaw) * b[:, 0] - np.sin(myaw) * b[:, 1]
    py = my + np.sin(myaw) * b[:, 0] + np.cos(myaw) * b[:, 1]
    return {"odom_path": _steps(odom[:, 0], odom[:, 1]), "planar_path": _steps(px, py)}


def _whole(run: AnalysedRun) -> dict[str, float]:
    return {
        v.metric: v.value
        for v in run.run.metrics
        if v.scope is MetricScope.ROBOT and v.robot == "bot" and v.safety_metric is None
    }


@pytest.mark.parametrize("fmt", ["ros1", "mcap"])
def test_tf_publishers_post_dating_are_not_a_reset(fmt: str, tmp_path: Path) -> None:
    spec = tmp_path / "tfs.exsce"
    spec.write_text(SPEC)
    bag = tf_bag(tmp_path, fmt)
    run = analyse_bag(bag, load_spec(spec).scenario())
    expected = references(bag)
    assert expected["odom_path"] == pytest.approx(14.0, rel=1e-9)
    found = _whole(run)
    for metric, value in expected.items():
        assert found.get(metric) == pytest.approx(value, rel=1e-6), (metric, run.problems)
    said = "\n".join(run.problems)
    assert "went back" not in said and "reset" not in said, said
    assert "go back" not in said, said
    assert run.timeline is not None and not run.timeline.jumps
    assert not [g for g in run.run.coverage if g.kind is Shortfall.CLOCK_JUMP]


@pytest.mark.parametrize(("fmt", "with_clock"), [("ros1", True), ("mcap", True), ("ros1", False)])
def test_a_true_reset_is_still_found(fmt: str, with_clock: bool, tmp_path: Path) -> None:
    """Every stamp (and /clock, where recorded) going back 20 s together, 18 s into the
    recording: a reset, whether /clock says so or every stamped source."""
    spec = tmp_path / "tfs.exsce"
    spec.write_text(SPEC)
    bag = tf_bag(tmp_path, fmt, reset_at=18.0, with_clock=with_clock)
    run = analyse_bag(bag, load_spec(spec).scenario())
    assert run.timeline is not None and run.timeline.jumps
    assert any(j.back == pytest.approx(20.0, abs=0.2) for j in run.timeline.jumps), run.timeline.jumps
    jumps = [g for g in run.run.coverage if g.kind is Shortfall.CLOCK_JUMP]
    assert jumps and "went back" in jumps[0].reason
    if not with_clock:
        assert "every stamped source (/odom, /tf (map → odom), /tf (odom → base_link))" in jumps[0].reason
    found = _whole(run)
    assert found["odom_path"] == pytest.approx(references(bag)["odom_path"], rel=1e-6), run.problems
