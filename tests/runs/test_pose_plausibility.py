"""A pose no robot could make yields no distance and no speed, with the reason (issue 47, item 4).

A TurtleBot's root ``/location`` (PoseStamped, one connection, empty frame id) alternated at
27 Hz between two localisation estimates up to 3.8 m apart: exsce read 8,403 m for a 7-11 m drive
and 7.1 m/s for a robot whose ``/velocity`` never exceeded 0.31 m/s, and failed its safety
criterion, without a warning.  The bags here are written with rosbags in the shapes of that one
(two tracks, a teleport, a clean drive); references come from rosbags' reading and numpy.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.errors import IncompleteRunError
from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag
from exsce_dsl.runs.bag_info import bag_info_of

from tests.support.bag_factory import (
    POSE_STAMPED,
    START_NS,
    TWIST_STAMPED,
    Topic,
    header,
    point,
    quaternion,
    typestore_for,
    vector3,
    write_bag,
)
from tests.support.cli import exscec_here
from tests.support.yard_spec import FAR_YARD

SPEC = FAR_YARD + """
metric location_path for each robot {
  unit m
  reads loc: geometry_msgs/msg/PoseStamped on "/{ns}/location"
  value path_length(loc.pose.position.x, loc.pose.position.y)
}
scenario rooted in yard {
  robots {
    tb: bot namespace "" starts at start
  }
  mission go_far sequential {
    tb does go
  }
}
acceptance for rooted {
  scenario "moves safely" {
    when go_far runs
    then each robot max_velocity stays below 1.0 m/s
  }
}
"""
HZ = 27.0
SECONDS = 30.0
GAP = 3.8
"""The largest distance between the two tracks (m)."""
FORMATS = {"ros1": "interleaved.bag", "mcap": "interleaved"}


def _drive() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times (ns from the start), the robot's x and its speed: 0.2 to 0.31 m/s along x."""
    rng = np.random.default_rng(47)
    t = np.arange(int(SECONDS * HZ)) / HZ
    speed = 0.2 + 0.11 * rng.random(len(t))
    x = np.concatenate([[0.0], np.cumsum(speed[:-1] * np.diff(t))])
    return (t * 1e9).astype(np.int64), x, speed


def _messages(store: Any, shape: str, velocity: bool) -> list[Topic]:
    """``/location`` (and ``/velocity``, the robot's own speed) of one of the shapes:
    ``tracks``: every other pose is a second estimate, 1.8 to 3.8 m from the first; ``teleport``:
    the poses jump 5 m once, mid-run; ``clean``: the drive as driven."""
    ns, x, speed = _drive()
    y = 0.2 * np.sin(x)
    if shape == "tracks":
        odd = np.arange(len(x)) % 2 == 1
        offset = 2.8 + 1.0 * np.sin(np.arange(len(x)) / 40.0)
        y = np.where(odd, y + offset, y)
    elif shape == "teleport":
        x = np.where(np.arange(len(x)) >= len(x) // 2, x + 5.0, x)
    types = store.types
    poses = [
        (
            START_NS + int(ti),
            types[POSE_STAMPED](
                header=header(store, START_NS + int(ti), "", i),
                pose=types["geometry_msgs/msg/Pose"](
                    position=point(store, (x[i], y[i], 0.0)), orientation=quaternion(store, 0.0)
                ),
            ),
        )
        for i, ti in enumerate(ns)
    ]
    topics = [Topic("/location", POSE_STAMPED, poses)]
    if velocity:
        twists = [
            (
                START_NS + int(ti) + 2_000_000,
                types[TWIST_STAMPED](
                    header=header(store, START_NS + int(ti), "base_link", i),
                    twist=types["geometry_msgs/msg/Twist"](
                        linear=vector3(store, (speed[i], 0.0, 0.0)), angular=vector3(store, (0.0, 0.0, 0.0))
                    ),
                ),
            )
            for i, ti in enumerate(ns)
        ]
        topics.append(Topic("/velocity", TWIST_STAMPED, twists))
    return topics


def _bag(folder: Path, shape: str, fmt: str = "ros1", velocity: bool = True) -> Path:
    path = folder / f"{shape}-{'v' if velocity else 'nov'}-{FORMATS[fmt]}"
    write_bag(path, fmt, _messages(typestore_for(fmt), shape, velocity))
    return path


def _spec(folder: Path) -> Path:
    spec = folder / "rooted.exsce"
    spec.write_text(SPEC)
    return spec


def _analysed(folder: Path, bag: Path) -> AnalysedRun:
    return analyse_bag(bag, load_spec(_spec(folder)).scenario())


def _read(bag: Path, topic: str) -> tuple[np.ndarray, np.ndarray]:
    """``topic``'s positions (x, y) and linear velocities (x, y), as rosbags reads them."""
    found: list[tuple[float, float]] = []
    with AnyReader([bag]) as reader:
        for connection, _, raw in reader.messages([c for c in reader.connections if c.topic == topic]):
            message = reader.deserialize(raw, connection.msgtype)
            at = message.pose.position if hasattr(message, "pose") else message.twist.linear
            found.append((at.x, at.y))
    array = np.array(found)
    return array[:, 0], array[:, 1]


def _whole(run: AnalysedRun) -> dict[str, float]:
    return {v.metric: v.value for v in run.run.metrics if v.action is None}


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_interleaved_tracks_make_no_distance(fmt: str, tmp_path: Path) -> None:
    bag = _bag(tmp_path, "tracks", fmt)
    analysed = _analysed(tmp_path, bag)
    values = _whole(analysed)
    assert "distance_travelled" not in values and "location_path" not in values, values
    # the robot's own velocity is no pose: its max velocity stands, from /velocity
    vx, vy = _read(bag, "/velocity")
    assert values["max_velocity"] == pytest.approx(float(np.hypot(vx, vy).max()), rel=1e-6)
    x, y = _read(bag, "/location")
    gap = float(np.hypot(np.diff(x), np.diff(y)).max())
    assert gap == pytest.approx(GAP, abs=0.05)
    said = [p for p in analysed.problems if "alternates between two tracks" in p]
    assert said, analysed.problems
    assert f"/location alternates between two tracks up to {gap:.1f} m apart" in said[0]
    assert f"while /velocity never exceeds {float(np.hypot(vx, vy).max()):.2f} m/s" in said[0]
    missing = [p for p in analysed.problems if "distance_travelled of 'tb'" in p]
    assert missing and "no plausible pose (/location alternates" in missing[0], analysed.problems
    assert any("location_path of 'tb'" in p and "no plausible pose" in p for p in analysed.problems)


def test_interleaved_tracks_make_no_speed_without_a_velocity(tmp_path: Path) -> None:
    """Without ``/velocity``, the speed was estimated from the poses (7.1 m/s in the issue)."""
    analysed = _analysed(tmp_path, _bag(tmp_path, "tracks", "mcap", velocity=False))
    values = _whole(analysed)
    assert "max_velocity" not in values and "distance_travelled" not in values, values
    (missing,) = [p for p in analysed.problems if "max_velocity of 'tb'" in p]
    assert "no plausible pose (/location alternates between two tracks" in missing


def test_interleaved_tracks_leave_the_safety_clause_inconclusive(tmp_path: Path) -> None:
    bag = _bag(tmp_path, "tracks", "ros1", velocity=False)
    _spec(tmp_path)
    store = str(tmp_path / "store")
    built = exscec_here("baseline", "rooted.exsce", "--store", store, cwd=tmp_path)  # the spec's limits
    assert built.returncode == 0, built.stderr
    done = exscec_here(
        "verify", str(bag), "--scenario", "rooted.exsce", "--store", store, "--json",
        cwd=tmp_path,
    )  # fmt: skip
    assert "Traceback" not in done.stderr, done.stderr
    verdicts = {v["metric"]: v for v in json.loads(done.stdout)}
    assert verdicts["max_velocity"]["verdict"] == "inconclusive", verdicts
    assert done.returncode == 3, done.stdout + done.stderr


def test_interleaved_tracks_refused_by_strict_ingest(tmp_path: Path) -> None:
    bag = _bag(tmp_path, "tracks", "ros1")
    with pytest.raises(IncompleteRunError) as raised:
        analyse_bag(bag, load_spec(_spec(tmp_path)).scenario(), strict=True)
    assert "/location alternates between two tracks up to 3.8 m apart" in raised.value.message


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_interleaved_tracks_shown_by_bag_info(fmt: str, tmp_path: Path) -> None:
    info = bag_info_of(_bag(tmp_path, "tracks", fmt))
    (said,) = info.plausibility
    assert said.startswith("/location alternates between two tracks up to 3.8 m apart"), said
    assert "while /velocity never exceeds 0.31 m/s" in said
    shown = exscec_here("bag", "info", str(info.path))
    assert "/location alternates between two tracks" in shown.stdout, shown.stdout


def test_a_teleport_makes_no_distance(tmp_path: Path) -> None:
    bag = _bag(tmp_path, "teleport")
    analysed = _analysed(tmp_path, bag)
    assert "distance_travelled" not in _whole(analysed)
    x, y = _read(bag, "/location")
    steps = np.hypot(np.diff(x), np.diff(y))
    k = int(steps.argmax())
    (said,) = [p for p in analysed.problems if "its pose makes no distance or speed" in p]
    assert f"/location teleports {steps[k]:.1f} m in {0.037:.3f} s, 15.0 s after its first pose" in said, said
    assert f"; 1 of {len(steps)} steps implies more than 1 m/s while /velocity never exceeds" in said
    assert bag_info_of(bag).plausibility


def test_a_clean_drive_whose_speed_matches_its_velocity_is_untouched(tmp_path: Path) -> None:
    bag = _bag(tmp_path, "clean")
    analysed = _analysed(tmp_path, bag)
    x, y = _read(bag, "/location")
    path = float(np.hypot(np.diff(x), np.diff(y)).sum())
    values = _whole(analysed)
    assert values["distance_travelled"] == pytest.approx(path, rel=1e-6)
    assert values["location_path"] == pytest.approx(path, rel=1e-6)
    assert not [p for p in analysed.problems if "plausible" in p or "distance or speed" in p]
    assert bag_info_of(bag).plausibility == ()


def test_interleaved_tracks_refused_by_ingest_strict_command(tmp_path: Path) -> None:
    bag = _bag(tmp_path, "tracks", "mcap")
    _spec(tmp_path)
    done = exscec_here(
        "ingest", str(bag), "--scenario", "rooted.exsce", "--store", str(tmp_path / "store"), "--strict",
        cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode != 0
    assert "no plausible pose (/location alternates between two tracks up to 3.8 m apart" in done.stderr
