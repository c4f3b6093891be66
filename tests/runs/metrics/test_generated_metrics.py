"""The built-in metrics through generated monitors equal the hand-written path they replaced.

The standard library declares the method's metrics in the language; ingestion
computes them with monitors generated from it.  tests/support/reference_metrics.py is
the hand-written computation exsce used before; on the same decoded bags both
must give the same values, topics, violations and hotspots.
"""

from __future__ import annotations

import math

import pytest

from exsce_dsl.lang import builtin_metrics, load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate

from tests.support import reference_metrics as reference
from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"


@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(BUILDING / "scenario_c.exsce").scenario()


def _reference(path, scenario):
    return reference.metrics_of_bag(path, scenario)


def _keyed(values):
    """Values of the built-in metrics by what they are of (the example's own metrics are elsewhere)."""
    keyed = {}
    for v in values:
        if v.metric not in builtin_metrics():
            continue
        key = (v.metric, v.scope, v.robot, v.action, v.safety_metric)
        assert key not in keyed, f"two values for {key}"
        keyed[key] = v
    return keyed


def _assert_same(generated, expected):
    got, want = _keyed(generated.run.metrics), _keyed(expected[0])
    assert got.keys() == want.keys()
    for key, value in want.items():
        assert math.isclose(got[key].value, value.value, rel_tol=1e-12, abs_tol=1e-12), key
        assert got[key].topics == value.topics, key
        assert got[key].unit == value.unit, key
    hotspots = sorted(generated.run.hotspots, key=lambda h: (h.metric, h.robot or "", h.position.x))
    reference_hotspots = sorted(expected[1], key=lambda h: (h.metric, h.robot or "", h.position.x))
    assert len(hotspots) == len(reference_hotspots)
    for h, r in zip(hotspots, reference_hotspots, strict=True):
        assert (h.metric, h.robot, h.violations) == (r.metric, r.robot, r.violations)
        assert math.isclose(h.position.x, r.position.x) and math.isclose(h.position.y, r.position.y)
        assert math.isclose(h.duration, r.duration)


@pytest.mark.parametrize("fmt", ["ros1", "ros2"])
def test_clean_run_equals_the_hand_written_metrics(scenario_c, tmp_path, fmt):
    run = next(iter(simulate(scenario_c, tmp_path, runs=1, fmt=fmt, seed=3)))
    generated = analyse_bag(run.bag, scenario_c)
    _assert_same(generated, _reference(run.bag, scenario_c))
    segment_values = [v for v in generated.run.metrics if v.action is not None]
    assert len(segment_values) > 20  # every segment has its values: the comparison was not empty


def test_faulty_run_equals_the_hand_written_metrics_with_violations_and_hotspots(scenario_c, tmp_path):
    faults = (Fault.parse("overspeed:tiago1"), Fault.parse("near-collision"))
    run = next(iter(simulate(scenario_c, tmp_path, runs=1, fmt="ros1", seed=5, faults=faults)))
    generated = analyse_bag(run.bag, scenario_c)
    expected = _reference(run.bag, scenario_c)
    _assert_same(generated, expected)
    violations = [v for v in generated.run.metrics if v.metric == "violation_duration" and v.value > 0]
    assert {v.safety_metric for v in violations} >= {"max_velocity", "distance_between_robots"}
    assert generated.run.hotspots
