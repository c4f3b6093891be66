"""The differential suite's comparison: a run's whole-run values against the reference of
tests/support/reference_path.py, and the conversion of a ROS 1 bag to ROS 2 sqlite3 and MCAP with
rosbags.

A value is compared at a relative error of 1e-6 where both compute; where the reference says the
data cannot support a number, the run must have no value and a problem naming the metric (and
the robot); a run value the reference does not expect is a mismatch too.
"""

from __future__ import annotations

import math
import re
from collections.abc import Collection, Mapping
from pathlib import Path

from rosbags.convert import convert

from exsce_dsl.model.runs import MetricScope
from exsce_dsl.runs.analyse import AnalysedRun

from tests.support.reference_path import Expected, Key

RELATIVE = 1e-6
STORAGES = ("sqlite3", "mcap")
"""The ROS 2 storages each corpus bag is converted to."""


def converted(bag: Path, folder: Path, storage: str) -> Path:
    """``bag`` (ROS 1) written as a ROS 2 bag of ``storage`` by rosbags' converter (version 8:
    the types' definitions travel with it)."""
    target = folder / f"{bag.stem}-{storage}"
    if not target.exists():
        convert([bag], target, storage, 8, None, "file", None, None, [], [], [], [])
    return target


def run_values(run: AnalysedRun) -> dict[Key, tuple[float, tuple[str, ...]]]:
    """The run's whole-run values (robot and mission scopes): (metric, robot) → value and topics;
    a violation duration as ``violation_duration/<its safety metric>``."""
    found: dict[Key, tuple[float, tuple[str, ...]]] = {}
    for v in run.run.metrics:
        if v.scope not in (MetricScope.ROBOT, MetricScope.MISSION):
            continue
        name = v.metric if v.safety_metric is None else f"{v.metric}/{v.safety_metric}"
        found[(name, v.robot if v.scope is MetricScope.ROBOT else None)] = (v.value, tuple(v.topics))
    return found


def mismatches(
    run: AnalysedRun, expected: Mapping[Key, Expected], left_out: Collection[Key] = ()
) -> list[str]:
    """Every way the run's values differ from ``expected`` (empty: they agree), but for the values
    ``left_out`` (known findings, each named where it is left out)."""
    found = {k: v for k, v in run_values(run).items() if k not in left_out}
    expected = {k: v for k, v in expected.items() if k not in left_out}
    wrong: list[str] = []
    for key, want in sorted(expected.items(), key=lambda kv: (kv[0][0], kv[0][1] or "")):
        metric, robot = key
        got = found.get(key)
        if want.value is None:
            if got is not None:
                wrong.append(f"{key}: exsce {got[0]!r}, the reference has no value")
            elif not _told(run.problems, metric.partition("/")[0], robot):
                wrong.append(f"{key}: missing without a reason naming it")
        elif got is None:
            wrong.append(f"{key}: exsce has no value, the reference {want.value!r}")
        elif not math.isclose(got[0], want.value, rel_tol=RELATIVE, abs_tol=1e-12):
            wrong.append(f"{key}: exsce {got[0]!r}, the reference {want.value!r}")
        elif want.topics and got[1] != want.topics:
            wrong.append(f"{key}: exsce read {got[1]}, the reference {want.topics}")
    wrong += [f"{key}: exsce {got[0]!r}, not expected" for key, got in found.items() if key not in expected]
    return wrong


def _told(problems: list[str], metric: str, robot: str | None) -> bool:
    return any(metric in p and (robot is None or f"'{robot}'" in p or f" {robot} " in p) for p in problems)


POSE_LINE = re.compile(r"^\s*pose (\S+) at \(([-\d.]+), ([-\d.]+)\)", re.MULTILINE)
VISIT_LINE = re.compile(r"^\s*visit (.+)$", re.MULTILINE)


def planned_waypoints(spec: str) -> tuple[tuple[float, float], ...]:
    """The waypoints a one-task specification's robot visits, in order (its ``visit`` lines)."""
    poses = {m[1]: (float(m[2]), float(m[3])) for m in POSE_LINE.finditer(spec)}
    names = [n.strip() for line in VISIT_LINE.findall(spec) for n in line.split(",")]
    return tuple(poses[n] for n in names)
