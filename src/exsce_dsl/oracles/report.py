"""Verdicts for people (an aligned table), for programs (JSON) and for CI systems (JUnit XML)."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from collections.abc import Sequence

from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.tables import aligned

_MARK = {Outcome.PASSED: "pass", Outcome.FAILED: "FAIL", Outcome.INCONCLUSIVE: "inconclusive"}


def _number(value: float | None) -> str:
    return "" if value is None else f"{value:.4g}"


def expectation(v: Verdict) -> str:
    """What ``v`` expected, as people read it: ``<= 1``, ``161.2 ± 10``, ``50.54 + 59.78 ± 16.55``
    ('' when nothing was expected).  The verdict table, JUnit reports and the HTML report show it."""
    if v.limit is not None:
        return f"{'<=' if v.relation == 'below_max' else '>='} {_number(v.limit)}"
    if v.expected is None:
        return ""
    text = _number(v.expected)
    if v.delta:
        text += f" {'+' if v.relation == 'increasing' else '-'} {_number(v.delta)}"
    if v.tolerance:
        text += f" ± {_number(v.tolerance)}"
    return text


def verdict_table(verdicts: Sequence[Verdict]) -> str:
    """One line per verdict: run, oracle, relation, observed, expected, margin, outcome."""
    header = ("run", "oracle", "relation", "observed", "expected", "margin", "verdict", "from runs")
    rows = [header] + [
        (
            v.run[:8],
            v.oracle,
            v.relation,
            _number(v.observed),
            expectation(v),
            _number(v.margin),
            _MARK[v.outcome] + (f": {v.reason}" if v.outcome is Outcome.INCONCLUSIVE else ""),
            str(len(v.sources)) if v.sources else "",
        )
        for v in verdicts
    ]
    return "\n".join(aligned(rows))


def verdicts_json(verdicts: Sequence[Verdict]) -> str:
    return json.dumps(
        [
            {
                "run": v.run,
                "scenario": v.scenario,
                "criterion": v.criterion,
                "oracle": v.oracle,
                "metric": v.metric,
                "robot": v.robot,
                "relation": v.relation,
                "window": v.window,
                "verdict": v.outcome.value,
                "observed": v.observed,
                "expected": v.expected,
                "limit": v.limit,
                "delta": v.delta,
                "tolerance": v.tolerance,
                "margin": v.margin,
                "runs": list(v.sources),
                "reason": v.reason,
                "shortfalls": [kind.value for kind in v.shortfalls],
            }
            for v in verdicts
        ],
        indent=2,
    )


def junit_xml(verdicts: Sequence[Verdict]) -> str:
    """A JUnit report: a test suite per run, a test case per oracle (failed: ``<failure>``;
    inconclusive: ``<skipped message="inconclusive: REASON">``, a test that could not be judged,
    which CI systems show apart from both passes and failures)."""
    suites = ET.Element("testsuites", name="exsce verify")
    by_run: dict[str, list[Verdict]] = {}
    for verdict in verdicts:
        by_run.setdefault(verdict.run, []).append(verdict)
    for run, judged in by_run.items():
        suite = ET.SubElement(suites, "testsuite", name=f"{judged[0].scenario} run {run}")
        _counts(suite, judged)
        for v in judged:
            case = ET.SubElement(
                suite, "testcase", classname=f"{v.scenario}.{v.criterion or 'oracles'}", name=v.description
            )
            details = (
                f"observed {_number(v.observed) or 'nothing'}, expected {expectation(v) or 'nothing'}"
                + (f", margin {_number(v.margin)}" if v.margin is not None else "")
                + (f"; {v.reason}" if v.reason else "")
            )
            if v.outcome is Outcome.FAILED:
                ET.SubElement(case, "failure", message=v.reason or "failed", type=v.relation).text = details
            elif v.outcome is Outcome.INCONCLUSIVE:
                ET.SubElement(case, "skipped", message=f"inconclusive: {v.reason}").text = details
    _counts(suites, verdicts)
    ET.indent(suites)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(suites, encoding="unicode") + "\n"


def _counts(element: ET.Element, verdicts: Sequence[Verdict]) -> None:
    """JUnit's counts on a suite (or all of them): tests, failures, skipped (inconclusive), and
    errors, which a verdict never is (an error is the tool's, and stops it)."""
    element.set("tests", str(len(verdicts)))
    element.set("failures", str(sum(v.outcome is Outcome.FAILED for v in verdicts)))
    element.set("errors", "0")
    element.set("skipped", str(sum(v.outcome is Outcome.INCONCLUSIVE for v in verdicts)))
