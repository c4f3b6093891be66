"""Trials on hand-made verdicts: Wilson intervals against scipy's, outcomes on counts chosen so that
the interval falls on each side of the threshold, and the trial's JUnit read back with ElementTree.

The reference numbers come from ``scipy.stats.binomtest(k, n).proportion_ci(method="wilson")``,
and the runs needed from scanning ``n`` with it: never from the code under test.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest
from scipy.stats import binomtest

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.trials import TrialOutcome
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.oracles.trial_report import pass_rate_table, trial_junit_xml
from exsce_dsl.oracles.trials import (
    clause_trial,
    clause_trials,
    lowest_pass_rate_first,
    runs_to_fail,
    runs_to_pass,
    trial,
    wilson_interval,
)


def _wilson(k: int, n: int, confidence: float) -> tuple[float, float]:
    ci = binomtest(k, n).proportion_ci(confidence_level=confidence, method="wilson")
    return float(ci.low), float(ci.high)


def _verdicts(
    passed: int, failed: int, inconclusive: int = 0, oracle: str = "r1-max_velocity", **fields: object
) -> list[Verdict]:
    outcomes = [Outcome.PASSED] * passed + [Outcome.FAILED] * failed + [Outcome.INCONCLUSIVE] * inconclusive
    common: dict[str, object] = {
        "scenario": "yard_run", "criterion": "moves safely", "oracle": oracle, "metric": "max_velocity",
        "robot": "r1", "relation": "below_max", "limit": 1.0,
    } | fields  # fmt: skip
    return [
        Verdict(
            run=f"run-{i:02d}",
            outcome=o,
            reason="no /r1/scan in the bag" if o is Outcome.INCONCLUSIVE else "",
            **common,  # type: ignore[arg-type]
        )
        for i, o in enumerate(outcomes)
    ]


@pytest.mark.parametrize("confidence", [0.8, 0.9, 0.95, 0.99])
@pytest.mark.parametrize(("k", "n"), [(0, 1), (1, 1), (0, 5), (3, 5), (5, 5), (7, 20), (19, 20), (50, 51)])
def test_the_wilson_interval_is_scipys(k: int, n: int, confidence: float) -> None:
    low, high = wilson_interval(k, n, confidence)
    want_low, want_high = _wilson(k, n, confidence)
    assert low == pytest.approx(want_low, abs=1e-12)
    assert high == pytest.approx(want_high, abs=1e-12)


@pytest.mark.parametrize(("required", "confidence"), [(0.5, 0.9), (0.8, 0.95), (0.9, 0.95), (0.95, 0.99)])
def test_runs_needed_are_the_first_n_whose_interval_clears_the_threshold(
    required: float, confidence: float
) -> None:
    needed_pass = next(n for n in range(1, 2000) if _wilson(n, n, confidence)[0] >= required)
    needed_fail = next(n for n in range(1, 2000) if _wilson(0, n, confidence)[1] < required)
    assert runs_to_pass(required, confidence) == needed_pass
    assert runs_to_fail(required, confidence) == needed_fail
    if (required, confidence) == (0.8, 0.95):
        assert needed_pass == 16  # the number the docs give for the defaults


@pytest.mark.parametrize(
    ("passed", "failed", "outcome"),
    [
        (16, 0, TrialOutcome.PASSED),  # lower bound 16/(16+1.96²) = 0.806 >= 0.8
        (15, 0, TrialOutcome.INCONCLUSIVE),  # 0.796: one run short
        (0, 1, TrialOutcome.FAILED),  # upper bound 1.96²/(1+1.96²) = 0.793 < 0.8
        (4, 2, TrialOutcome.FLAKY),
        (30, 20, TrialOutcome.FAILED),  # 0.6, upper bound 0.72
        (97, 3, TrialOutcome.PASSED),  # 0.97, lower bound 0.915
        (15, 1, TrialOutcome.FLAKY),  # one failure in 16: lower bound 0.72
    ],
)
def test_outcomes_on_hand_made_counts(passed: int, failed: int, outcome: TrialOutcome) -> None:
    low, high = _wilson(passed, passed + failed, 0.95)
    by_rule = (
        TrialOutcome.PASSED if low >= 0.8 else TrialOutcome.FAILED if high < 0.8
        else TrialOutcome.FLAKY if passed and failed else TrialOutcome.INCONCLUSIVE
    )  # fmt: skip
    assert by_rule is outcome  # the hand-made expectation agrees with scipy's interval
    clause = clause_trial(_verdicts(passed, failed))
    assert clause.outcome is outcome
    assert (clause.passed, clause.failed, clause.inconclusive) == (passed, failed, 0)
    assert clause.pass_rate == pytest.approx(passed / (passed + failed))
    assert (clause.low, clause.high) == pytest.approx((low, high))


def test_too_few_passing_runs_say_how_many_would_do() -> None:
    clause = clause_trial(_verdicts(6, 0))
    assert clause.outcome is TrialOutcome.INCONCLUSIVE
    assert clause.runs_needed == 16
    assert "16 passing runs show a pass rate of 0.8 at 95 %" in clause.reason
    # at a low threshold one failing run is not enough to fail: 35 are (scipy: 1.96²·0.9/0.1 = 34.6)
    low_bar = clause_trial(_verdicts(0, 1), required_pass_rate=0.1)
    assert low_bar.outcome is TrialOutcome.INCONCLUSIVE
    assert low_bar.runs_needed == 35 and "35 failing runs" in low_bar.reason


def test_inconclusive_runs_are_counted_apart_and_left_out_of_the_rate() -> None:
    clause = clause_trial(_verdicts(16, 0, inconclusive=3))
    assert (clause.passed, clause.failed, clause.inconclusive) == (16, 0, 3)
    assert clause.outcome is TrialOutcome.PASSED
    none_judged = clause_trial(_verdicts(0, 0, inconclusive=2))
    assert none_judged.outcome is TrialOutcome.INCONCLUSIVE
    assert none_judged.pass_rate is None and none_judged.low is None
    assert none_judged.reason == "no run could be judged (no /r1/scan in the bag)"


def test_a_clause_is_its_oracle_relation_base_and_window() -> None:
    verdicts = [
        *_verdicts(3, 0),
        *_verdicts(0, 2, window="during patrol_1"),
        *_verdicts(1, 1, oracle="r1-distance_travelled", relation="increasing", against="yard_base"),
        *_verdicts(1, 0, oracle="r1-distance_travelled", relation="invariant"),
    ]
    clauses = clause_trials(verdicts)
    assert [
        (c.key.oracle, c.key.relation, c.key.against, c.key.window, c.passed, c.failed) for c in clauses
    ] == [
        ("r1-max_velocity", "below_max", None, None, 3, 0),
        ("r1-max_velocity", "below_max", None, "during patrol_1", 0, 2),
        ("r1-distance_travelled", "increasing", "yard_base", None, 1, 1),
        ("r1-distance_travelled", "invariant", None, None, 1, 0),
    ]
    ordered = lowest_pass_rate_first(clauses)
    assert [c.pass_rate for c in ordered] == [0.0, 0.5, 1.0, 1.0]
    assert ordered[2].judged == 1  # of two clauses at 1.0, the one with fewer runs (the lower bound) first


@pytest.mark.parametrize(("required", "confidence"), [(0.0, 0.95), (1.0, 0.95), (0.8, 1.0), (0.8, 0.0)])
def test_rates_outside_zero_to_one_are_bad_input(required: float, confidence: float) -> None:
    with pytest.raises(ExsceError, match="between 0 and 1"):
        clause_trial(_verdicts(1, 0), required, confidence)


def test_the_trial_junit_has_a_case_per_clause_with_pass_rates_and_outcomes() -> None:
    verdicts = [
        *_verdicts(16, 0),
        *_verdicts(4, 2, oracle="r1-task_duration", metric="task_duration", relation="invariant"),
        *_verdicts(0, 3, oracle="r2-max_velocity", robot="r2"),
        *_verdicts(2, 0, oracle="r2-distance_travelled", metric="distance_travelled", robot="r2"),
    ]
    judged = trial("yard_run", [f"run-{i:02d}" for i in range(16)], verdicts)
    assert judged.outcome is TrialOutcome.FAILED
    root = ET.fromstring(trial_junit_xml(judged.clauses, len(judged.runs)))
    assert (root.get("tests"), root.get("failures"), root.get("skipped")) == ("4", "2", "1")
    (suite,) = root.findall("testsuite")
    assert suite.get("name") == "yard_run trial of 16 runs"
    cases = {c.get("name"): c for c in suite.findall("testcase")}
    assert list(cases) == [
        "r1 max_velocity below_max",
        "r1 task_duration invariant",
        "r2 max_velocity below_max",
        "r2 distance_travelled below_max",
    ]
    flaky = cases["r1 task_duration invariant"]
    props = {p.get("name"): p.get("value") for p in flaky.iter("property")}
    low, high = _wilson(4, 6, 0.95)
    assert props["pass_rate"] == f"{4 / 6:.4f}" and props["interval"] == f"[{low:.4f}, {high:.4f}]"
    assert (props["runs"], props["passed"], props["failed"], props["inconclusive"]) == ("6", "4", "2", "0")
    assert flaky.find("failure").get("type") == "flaky"  # type: ignore[union-attr]
    assert cases["r2 max_velocity below_max"].find("failure").get("type") == "failed"  # type: ignore[union-attr]
    skipped = cases["r2 distance_travelled below_max"].find("skipped")
    assert skipped is not None and skipped.get("message", "").startswith("inconclusive: too few runs")
    passed = cases["r1 max_velocity below_max"]
    assert passed.find("failure") is None and passed.find("skipped") is None
    table = pass_rate_table(judged.clauses).splitlines()
    assert table[0].split() == [
        "clause",
        "passed",
        "failed",
        "inconclusive",
        "pass",
        "rate",
        "95",
        "%",
        "interval",
        "outcome",
    ]
    assert table[2].split()[-1] == "flaky" and table[4].endswith("inconclusive: 16 passing runs needed")
