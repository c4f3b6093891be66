"""Issue 47, item 4: every value says what it used.  ``exscec explain RUN METRIC`` prints, for each
value of a stored run's metric, its sources, its window (start, end, why) and the samples of each
source it used of those in its window, counted here independently with rosbags and numpy; the
run's PROV holds it for every value (SPARQL, and the run shapes); a missing value says why; a run
or metric the store lacks is exit 2 with a clear message."""

from __future__ import annotations

import csv
import datetime as dt
import io
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.model.coverage import CoverageGap, Shortfall
from exsce_dsl.model.runs import Accounting, MetricScope, MetricValue, SourceCount
from exsce_dsl.prov.run import compile_run
from exsce_dsl.rdf.prov_o import to_quads
from exsce_dsl.rdf.shacl import validate
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.coverage import with_findings
from exsce_dsl.runs.metrics.accounting import on_wall_clock
from exsce_dsl.runs.spec_draft import draft_spec

from tests.support.bag_factory import (
    LASER_SCAN,
    ODOMETRY,
    START_NS,
    Topic,
    header,
    odometry_at,
    typestore_for,
    write_bag,
)
from tests.support.cli import exscec_here
from tests.support.paths import ROOT

HUSKY = ROOT / "tests" / "fixtures" / "realbags" / "robot_localization" / "test1.bag"
ODOM = "/husky_velocity_controller/odom"
ROBOT = "husky_velocity_controller"
DATE = re.compile(r"(\d{4}-\d\d-\d\dT[\d:.]+Z) to (\d{4}-\d\d-\d\dT[\d:.]+Z)")


def _stamps(bag: Path, topic: str) -> np.ndarray:
    """The header stamps (s) of every message of ``topic``, by rosbags, in log-time order."""
    with AnyReader([bag], default_typestore=typestore_for("ros1")) as r:
        found = [
            m.header.stamp.sec + m.header.stamp.nanosec * 1e-9
            for c, _, raw in r.messages([c for c in r.connections if c.topic == topic])
            for m in [r.deserialize(raw, c.msgtype)]
        ]
    return np.sort(np.array(found))


def _blocks(text: str) -> dict[str, str]:
    """Explain's output, one block per value, keyed by its first line up to the colon."""
    found: dict[str, str] = {}
    key = ""
    for line in text.splitlines()[1:]:
        if line.startswith("  ") and not line.startswith("    "):
            key = line.strip().split(":")[0]
            found[key] = ""
        found[key] += line + "\n"
    return found


def _window(block: str) -> tuple[float, float]:
    """A block's window as seconds since the epoch (from its dates)."""
    found = DATE.search(block)
    assert found is not None, block
    first, last = (dt.datetime.fromisoformat(d.replace("Z", "+00:00")).timestamp() for d in found.groups())
    return first, last


def _inside(stamps: np.ndarray, window: tuple[float, float]) -> int:
    """Samples in the window (its dates are to the microsecond: a boundary sample stays in)."""
    return int(
        np.searchsorted(stamps, window[1] + 1e-6, "right") - np.searchsorted(stamps, window[0] - 1e-6, "left")
    )


@pytest.fixture(scope="module")
def husky_store(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, str, Path]:
    """robot_localization's Husky ingested with its drafted spec: (store, run uuid, spec)."""
    folder = tmp_path_factory.mktemp("husky")
    spec = folder / "husky.exsce"
    draft_spec(HUSKY, spec)
    store = str(folder / "store")
    done = exscec_here("ingest", str(HUSKY), "--scenario", str(spec), "--store", store)
    assert done.returncode == 0, done.stderr
    listed = exscec_here("runs", "-f", "csv", "--store", store)
    (row,) = list(csv.DictReader(io.StringIO(listed.stdout)))
    return store, row["run"], spec


def test_explain_prints_the_sources_window_and_every_sample_of_a_real_husky(
    husky_store: tuple[str, str, Path],
) -> None:
    store, run, _ = husky_store
    done = exscec_here("explain", run[:8], "distance_travelled", "--robot", ROBOT, "--store", store)
    assert done.returncode == 0, done.stderr
    stamps = _stamps(HUSKY, ODOM)
    n = len(stamps)
    assert n == 3952
    whole = _blocks(done.stdout)[f"robot {ROBOT}"]
    assert f"sources: {ODOM}\n" in whole
    assert f"{ODOM}: {n} of {n} samples in the window" in whole
    assert "why: the recording (the spec's window whole recording)" in whole
    start, end = _window(whole)
    assert start <= stamps[0] + 1e-6 and end >= stamps[-1] - 1e-6
    assert end - start == pytest.approx(stamps[-1] - stamps[0], abs=0.01)
    assert "annotations: none" in whole


def test_a_segment_value_s_window_is_its_segment(husky_store: tuple[str, str, Path]) -> None:
    store, run, _ = husky_store
    done = exscec_here("explain", run, "distance_travelled", "--store", store)
    assert done.returncode == 0, done.stderr
    times = exscec_here("query", "action_times", "-p", f"run={run}", "-f", "csv", "--store", store)
    actions = {r["action"].rsplit("/", 1)[1]: r for r in csv.DictReader(io.StringIO(times.stdout))}
    assert len(actions) == 2
    stamps = _stamps(HUSKY, ODOM)
    blocks = _blocks(done.stdout)
    for name, action in actions.items():
        block = blocks[f"segment {name}"]
        assert f"{action['start']} to {action['end']}" in block
        assert "why: path segment to waypoint" in block
        n = _inside(stamps, _window(block))
        assert 0 < n < len(stamps)
        assert f"{ODOM}: {n} of {n} samples in the window" in block


def test_explain_of_one_segment_prints_that_segment_only(husky_store: tuple[str, str, Path]) -> None:
    store, run, _ = husky_store
    done = exscec_here("explain", run, "max_velocity", "--segment", "w_002", "--store", store)
    assert done.returncode == 0, done.stderr
    assert list(_blocks(done.stdout)) == [f"segment {ROBOT}-task_01-subtask_001-w_002"]


def test_every_stored_value_has_its_accounting(husky_store: tuple[str, str, Path]) -> None:
    store, _, _ = husky_store
    lacking = exscec_here(
        "sparql",
        "SELECT ?value WHERE { GRAPH ?g { ?value a exsce:output_metric } "
        "FILTER NOT EXISTS { GRAPH ?g { ?value exsce:window_reason ?why ; exsce:window_from ?from ; "
        "exsce:window_to ?to } } }",
        "-f",
        "csv",
        "--store",
        store,
    )
    assert lacking.returncode == 0, lacking.stderr
    assert lacking.stdout.splitlines() == ["value"]
    counted = exscec_here(
        "sparql",
        "SELECT ?value ?used ?all WHERE { GRAPH ?g { ?count exsce:counted_for ?value ; "
        "exsce:samples_used ?used ; exsce:samples_in_window ?all ; exsce:topic_name ?topic } }",
        "-f",
        "csv",
        "--store",
        store,
    )
    rows = list(csv.DictReader(io.StringIO(counted.stdout)))
    values = {r["value"].rsplit("/", 1)[1] for r in rows}
    assert f"{ROBOT}-distance_travelled" in values and f"{ROBOT}-max_velocity" in values
    assert all(
        int(r["used"]) == int(r["all"]) == 3952 for r in rows if r["value"].endswith(f"/{ROBOT}-max_velocity")
    )


def test_a_run_with_accounting_conforms_to_the_run_shapes(husky_store: tuple[str, str, Path]) -> None:
    _, _, spec = husky_store
    scenario = load_spec(spec).scenario()
    run = analyse_bag(HUSKY, scenario).run
    assert all(v.accounting is not None for v in run.metrics)
    assert validate(to_quads(compile_run(run, scenario)), ["runs"]) == []


def test_a_missing_value_says_why(husky_store: tuple[str, str, Path]) -> None:
    store, run, _ = husky_store
    done = exscec_here("explain", run, "distance_to_obstacles", "--robot", ROBOT, "--store", store)
    assert done.returncode == 0, done.stderr
    assert "missing:\n    no scan (none detected in the bag): distance_to_obstacles of" in done.stdout


def test_explain_of_an_unknown_run_or_metric_exits_2(husky_store: tuple[str, str, Path]) -> None:
    store, run, _ = husky_store
    unknown_run = exscec_here("explain", "0000", "distance_travelled", "--store", store)
    assert unknown_run.returncode == 2
    assert "the store holds no run 0000" in unknown_run.stderr and "Traceback" not in unknown_run.stderr
    unknown_metric = exscec_here("explain", run[:8], "distance_travel", "--store", store)
    assert unknown_metric.returncode == 2
    assert f"run {run} has no value of metric 'distance_travel'" in unknown_metric.stderr
    assert "did you mean 'distance_travelled'?" in unknown_metric.stderr
    unknown_robot = exscec_here(
        "explain", run[:8], "distance_travelled", "--robot", "husky", "--store", store
    )
    assert unknown_robot.returncode == 2 and f"its robots: {ROBOT}" in unknown_robot.stderr


# -- a value that used fewer samples than its window holds says why ---------------------------

SPEC = """
environment yard {
  area ground {
    pose yard-start at (0.0, 0.0)
    pose yard-1 at (8.0, 0.0)
  }
}

task out {
  visit yard-1
}

robot type rover {
  base diff_drive
}

scenario blind in yard {
  robots {
    bot: rover namespace "" starts at yard-start
  }
  mission blind_mission sequential {
    bot does out
  }
}
"""
BLIND_EVERY = 4
"""Every fourth scan sees nothing within its range (all beams at infinity)."""




def _scan(store: Any, index: int, time_ns: int) -> Any:
    blind = index % BLIND_EVERY == 0
    ranges = np.full(9, np.inf if blind else 2.0 + 0.01 * index, dtype=np.float32)
    return store.types[LASER_SCAN](
        header=header(store, time_ns, "base_laser_link", index),
        angle_min=-1.0,
        angle_max=1.0,
        angle_increment=0.25,
        time_increment=0.0,
        scan_time=0.1,
        range_min=0.05,
        range_max=30.0,
        ranges=ranges,
        intensities=np.zeros(0, dtype=np.float32),
    )


def _blind_bag(folder: Path) -> Path:
    """10 s driving along x at 1 m/s, odometry at 20 Hz, a scan at 10 Hz, some of it blind."""
    store = typestore_for("ros1")
    odometry = [(START_NS + i * 50_000_000, i) for i in range(201)]
    scans = [(START_NS + i * 100_000_000 + 1_000_000, i) for i in range(100)]
    topics = [
        Topic("/odom", ODOMETRY, [(ns, odometry_at(store, i, ns, i * 0.05)) for ns, i in odometry]),
        Topic("/scan", LASER_SCAN, [(ns, _scan(store, i, ns)) for ns, i in scans]),
    ]
    path = folder / "blind.bag"
    write_bag(path, "ros1", topics, store)
    return path


def _scan_ranges(bag: Path) -> list[np.ndarray]:
    with AnyReader([bag], default_typestore=typestore_for("ros1")) as r:
        return [
            np.asarray(m.ranges, dtype=np.float64)
            for c, _, raw in r.messages([c for c in r.connections if c.topic == "/scan"])
            for m in [r.deserialize(raw, c.msgtype)]
        ]


def test_a_value_from_fewer_samples_than_its_window_holds_says_why(tmp_path: Path) -> None:
    spec = tmp_path / "blind.exsce"
    spec.write_text(SPEC)
    bag = _blind_bag(tmp_path)
    run = analyse_bag(bag, load_spec(spec).scenario()).run
    (value,) = [
        v for v in run.metrics if v.metric == "distance_to_obstacles" and v.scope is MetricScope.ROBOT
    ]
    ranges = _scan_ranges(bag)
    seeing = [r for r in ranges if np.any((r >= 0.05) & (r <= 30.0))]
    assert value.value == pytest.approx(min(float(r.min()) for r in seeing), rel=1e-6)
    assert value.accounting is not None
    (scan,) = value.accounting.sources
    assert scan.topics == ("/scan",)
    assert (scan.used, scan.in_window) == (len(seeing), len(ranges))
    assert scan.used < scan.in_window
    assert (
        scan.why
        == f"{len(ranges) - len(seeing)} samples without a value (NaN, or no element meeting its condition)"
    )


# -- the findings that touch a value ----------------------------------------------------------


def _value(start: float, end: float) -> MetricValue:
    counts = (SourceCount(("/served/pose",), 10, 10),)
    return MetricValue(
        "distance_travelled",
        MetricScope.ROBOT,
        1.0,
        ("/odom",),
        "bot",
        unit="m",
        accounting=Accounting(start, end, "the recording", counts),
    )


def _at(seconds: float) -> dt.datetime:
    return dt.datetime.fromtimestamp(seconds, tz=dt.timezone.utc)


def test_the_findings_that_touch_a_value_are_its_annotations() -> None:
    gaps = [
        CoverageGap(
            Shortfall.GAP,
            "a gap of 3 s in /odom",
            "bot",
            "/odom",
            ("distance_travelled",),
            _at(105),
            _at(108),
        ),
        CoverageGap(Shortfall.GAP, "a gap in /odom after the window", "bot", "/odom", (), _at(300), _at(303)),
        CoverageGap(
            Shortfall.GAP, "a gap in /scan", "bot", "/scan", ("distance_to_obstacles",), _at(105), _at(108)
        ),
        CoverageGap(Shortfall.GAP, "a gap of another robot", "other", "/odom", (), _at(105), _at(108)),
        CoverageGap(
            Shortfall.CUT_SHORT, "the recording ends while goals are active", None, None, (), _at(190), None
        ),
        CoverageGap(Shortfall.GAP, "a gap on the pose's own topic", "bot", "/tf", (), _at(150), _at(151)),
    ]
    (walled,) = on_wall_clock([_value(100.0, 200.0)], lambda t: t, {"/served/pose": ("/tf",)})
    shifted = with_findings(walled, gaps)
    assert shifted.accounting is not None
    assert shifted.accounting.sources[0].topics == ("/tf",)
    assert shifted.accounting.annotations == (
        "a gap of 3 s in /odom",
        "the recording ends while goals are active",
        "a gap on the pose's own topic",
    )
    assert (shifted.accounting.start, shifted.accounting.end) == (100.0, 200.0)


def test_the_report_shows_what_each_value_used(husky_store: tuple[str, str, Path], tmp_path: Path) -> None:
    store, run, _ = husky_store
    done = exscec_here("report", "--store", store, "-o", str(tmp_path / "report"))
    assert done.returncode == 0, done.stderr
    page = (tmp_path / "report" / f"run-{run}.html").read_text(encoding="utf-8")
    values = page[page.index("<h2>Metric values</h2>") :]
    n = len(_stamps(HUSKY, ODOM))
    row = values[values.index("<td>distance_travelled</td>") :]
    row = row[: row.index("</details>")]
    assert "what it used (window: the recording (the spec&#39;s window whole recording))" in row
    assert f"{ODOM}: {n} of {n} samples in the window" in row
    segments = page[page.index("<h3>Path segments</h3>") : page.index("<h2>Verdicts")]
    assert segments.count("why: path segment to waypoint") == 4  # distance and duration of S1, S2
