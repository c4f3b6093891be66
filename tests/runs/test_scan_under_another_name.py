"""A scan the robot publishes under another name than the method's is reduced as it is read
(regression: embag's Stage robot, ``/base_scan``, made ``exscec ingest`` exit 70 with
``KeyError: 'ranges'``).

The reader keeps no arrays of a topic it reduces; the monitors' reduction of ``ranges`` was keyed
by the served name (``/scan``) alone, so ``/base_scan`` lost its ranges and gained nothing.  The
reference is rosbags' own reading and numpy, written here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.model.runs import MetricScope
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.spec_draft import draft_spec

from tests.support.paths import ROOT

STAGE = ROOT / "tests" / "fixtures" / "realbags" / "embag" / "test.bag"


def nearest_valid_range(bag: Path, topic: str) -> float:
    """The least range inside [range_min, range_max] of every message of ``topic``."""
    nearest = np.inf
    with AnyReader([bag]) as reader:
        chosen = [c for c in reader.connections if c.topic == topic]
        for connection, _, raw in reader.messages(connections=chosen):
            scan = reader.deserialize(raw, connection.msgtype)
            ranges = np.asarray(scan.ranges, dtype=np.float64)
            valid = ranges[(ranges >= scan.range_min) & (ranges <= scan.range_max)]
            nearest = min(nearest, float(valid.min()))
    return nearest


def test_scan_under_another_name_gives_its_nearest_range(tmp_path: Path) -> None:
    draft_spec(STAGE, tmp_path / "stage.exsce")
    run = analyse_bag(STAGE, load_spec(tmp_path / "stage.exsce").scenario())
    (value,) = [
        v for v in run.run.metrics
        if v.metric == "distance_to_obstacles" and v.scope is MetricScope.ROBOT and v.safety_metric is None
    ]  # fmt: skip
    expected = nearest_valid_range(STAGE, "/base_scan")
    assert 0 < expected < 5
    assert value.value == pytest.approx(expected, rel=1e-6)
    assert value.topics == ("/base_scan",)
