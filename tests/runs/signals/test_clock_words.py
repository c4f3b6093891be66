"""Issue 47, item 7: a bag's clocks are described with the same words by ``exscec bag info`` and
``exscec ingest -v`` (one function says them), and a bag whose *log time* is simulated time (a
recorder under ``use_sim_time``: log times from 82.8 s, with ``/clock``) is called simulated time
and its run is never dated 1970: it has no date.

Three bags written here with rosbags: that one; a wall-clock robot (log time and stamps agree);
a Gazebo robot (wall-clock log times, stamps and ``/clock`` in simulated time).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.bag_info import bag_info_of

from tests.support.bag_factory import (
    ODOMETRY,
    START_NS,
    Topic,
    odometry_at,
    typestore_for,
    write_bag,
)
from tests.support.cli import exscec_here

CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
SIM_LOG_START = 82.8
"""Seconds: the first log time of the bag whose recorder logged simulated time."""

SPEC = """
environment yard {
  area ground {
    pose yard-start at (0.0, 0.0)
    pose yard-far at (40.0, 40.0)
  }
}

task far {
  visit yard-far
}

robot type rover {
  base diff_drive
}

scenario clocks in yard {
  robots {
    bot: rover namespace "" starts at yard-start
  }
  mission clocks_mission sequential {
    bot does far
  }
}
"""

SHAPES = {
    # shape: (first log time in ns, first stamp in s (None: the log time), /clock recorded)
    "simulated_log": (int(SIM_LOG_START * 1e9), None, True),
    "wall_clock": (START_NS, None, False),
    "gazebo": (START_NS, 931.25, True),
    # a stand-in's simulation whose /clock runs as the wall clock: bag info called it simulated
    # time and ingest -v the wall clock (found on the live demo's bags)
    "clock_at_wall_time": (START_NS, None, True),
}




def clock_bag(folder: Path, shape: str, fmt: str = "ros1") -> Path:
    """12 s of odometry at 20 Hz (driving 0.5 m/s along x) and, where the shape has it, /clock
    at 10 Hz."""
    first_log, first_stamp, clock = SHAPES[shape]
    store = typestore_for(fmt)
    odom, ticks = [], []
    for i in range(241):
        s = i / 20
        log = first_log + int(round(s * 1e9))
        stamp = log if first_stamp is None else int(round((first_stamp + s) * 1e9))
        odom.append((log, odometry_at(store, i, stamp, 0.5 * s)))
        if clock and i % 2 == 0:
            sim = stamp * 1e-9
            time = store.types["builtin_interfaces/msg/Time"](
                sec=int(sim), nanosec=int(round((sim % 1) * 1e9))
            )
            ticks.append((log, store.types[CLOCK_TYPE](clock=time)))
    topics = [Topic("/odom", ODOMETRY, odom)] + ([Topic("/clock", CLOCK_TYPE, ticks)] if ticks else [])
    path = folder / (f"{shape}.bag" if fmt == "ros1" else shape)
    write_bag(path, fmt, topics, store)
    return path


def _spec(folder: Path) -> Path:
    spec = folder / "clocks.exsce"
    spec.write_text(SPEC)
    return spec


def _ingest_timeline(bag: Path, spec: Path, store: Path) -> tuple[str, str]:
    """The timeline ``exscec ingest -v`` says of ``bag``, and all it said."""
    done = exscec_here("ingest", str(bag), "--scenario", str(spec), "--store", str(store), "-v")
    assert done.returncode == 0, done.stdout + done.stderr
    said = [line.strip() for line in done.stderr.splitlines() if line.strip().startswith("timeline: ")]
    assert len(said) == 1, done.stderr
    return said[0].removeprefix("timeline: "), done.stderr


@pytest.mark.parametrize("shape", list(SHAPES))
def test_clocks_described_alike_by_bag_info_and_ingest(shape: str, tmp_path: Path) -> None:
    bag = clock_bag(tmp_path, shape)
    told, _ = _ingest_timeline(bag, _spec(tmp_path), tmp_path / "store")
    info = bag_info_of(bag)
    assert told == info.timeline
    table = exscec_here("bag", "info", str(bag))
    assert table.returncode == 0, table.stderr
    assert f"timeline  {told}" in table.stdout
    expected = {
        "simulated_log": "simulated time",
        "wall_clock": "wall clock",
        "gazebo": "simulated time",
        "clock_at_wall_time": "wall clock",
    }
    assert told.startswith(expected[shape]), told


def test_simulated_log_time_is_not_1970(tmp_path: Path) -> None:
    bag = clock_bag(tmp_path, "simulated_log")
    spec = _spec(tmp_path)
    run = analyse_bag(bag, load_spec(spec).scenario())
    assert run.timeline is not None and not run.timeline.dated
    assert not run.run.dated
    assert run.timeline.describe().startswith(
        "simulated time (the recorder logged simulated time from 82.800 s"
    )
    assert all(c.simulated for c in run.run.clocks), run.run.clocks
    # the distance is still the odometry's: 12 s at 0.5 m/s
    [distance] = [v.value for v in run.run.metrics if v.metric == "distance_travelled" and v.action is None]
    assert distance == pytest.approx(6.0, rel=1e-9)
    store = tmp_path / "store"
    told, said = _ingest_timeline(bag, spec, store)
    assert "1970" not in said and "simulated time" in told
    table = exscec_here("bag", "info", str(bag))
    assert "1970" not in table.stdout and "82.800 s (no date)" in table.stdout, table.stdout
    assert "wall clock" not in table.stdout, table.stdout
    listed = exscec_here("runs", "-f", "json", "--store", str(store))
    assert listed.returncode == 0, listed.stderr
    (row,) = json.loads(listed.stdout)["results"]["bindings"]
    assert "start" not in row and "end" not in row, row
    assert "1970" not in listed.stdout
    exported = exscec_here(
        "query", "action_times", "-p", f"run={row['run']['value']}", "-f", "json", "--store", str(store)
    )
    assert exported.returncode == 0 and "1970" not in exported.stdout, exported.stdout + exported.stderr


def test_a_wall_clock_run_keeps_its_date(tmp_path: Path) -> None:
    run = analyse_bag(clock_bag(tmp_path, "wall_clock"), load_spec(_spec(tmp_path)).scenario())
    assert run.run.dated and run.run.start.timestamp() == pytest.approx(START_NS * 1e-9)
