"""Pass rates for people (a table), for programs (JSON, CSV) and for CI systems (JUnit XML).

One row, or one test case, per clause of a trial (or of the store's verdicts, ``exscec flaky``):
its runs passed, failed and inconclusive, its pass rate over the judged runs with the Wilson
interval, and its outcome (:mod:`exsce_dsl.oracles.trials`).
"""

from __future__ import annotations

import csv
import io
import json
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from typing import Any

from exsce_dsl.model.trials import ClauseTrial, TrialOutcome
from exsce_dsl.oracles.trials import percent
from exsce_dsl.tables import aligned

COLUMNS = (
    "scenario", "clause", "oracle", "relation", "against", "window", "passed", "failed", "inconclusive",
    "pass_rate", "low", "high", "confidence", "required_pass_rate", "outcome", "reason",
)  # fmt: skip
"""The columns of the JSON and CSV listings."""


def _rate(value: float | None) -> str:
    return "" if value is None else f"{value:.2f}"


def interval(clause: ClauseTrial) -> str:
    """``[0.61, 0.98]`` ('' when no run was judged)."""
    return "" if clause.low is None else f"[{_rate(clause.low)}, {_rate(clause.high)}]"


def outcome_cell(clause: ClauseTrial) -> str:
    """``flaky``, ``inconclusive: 16 passing runs needed``: the outcome as the table shows it."""
    text = clause.outcome.value
    if clause.outcome is TrialOutcome.INCONCLUSIVE:
        if clause.runs_needed is not None:
            agreeing = "passing" if clause.passed else "failing"
            text += f": {clause.runs_needed} {agreeing} runs needed"
        else:
            text += ": no run judged"
    return text


def pass_rate_table(clauses: Sequence[ClauseTrial], show_scenario: bool = False) -> str:
    """One line per clause: clause, passed, failed, inconclusive, pass rate, interval, outcome."""
    level = percent(clauses[0].confidence) if clauses else ""
    header = ("clause", "passed", "failed", "inconclusive", "pass rate", f"{level} interval", "outcome")
    rows = [(("scenario",) if show_scenario else ()) + header]
    for c in clauses:
        cells = (
            c.description,
            str(c.passed),
            str(c.failed),
            str(c.inconclusive),
            _rate(c.pass_rate),
            interval(c),
            outcome_cell(c),
        )
        rows.append(((c.key.scenario,) if show_scenario else ()) + cells)
    return "\n".join(aligned(rows))


def _record(c: ClauseTrial) -> dict[str, Any]:
    return {
        "scenario": c.key.scenario,
        "clause": c.description,
        "oracle": c.key.oracle,
        "relation": c.key.relation,
        "against": c.key.against,
        "window": c.key.window,
        "passed": c.passed,
        "failed": c.failed,
        "inconclusive": c.inconclusive,
        "pass_rate": c.pass_rate,
        "low": c.low,
        "high": c.high,
        "confidence": c.confidence,
        "required_pass_rate": c.required_pass_rate,
        "outcome": c.outcome.value,
        "reason": c.reason,
    }


def pass_rates_json(clauses: Sequence[ClauseTrial]) -> str:
    """A JSON list of the clauses: the :data:`COLUMNS`, and the runs counted."""
    return json.dumps([{**_record(c), "runs": list(c.runs)} for c in clauses], indent=2) + "\n"


def pass_rates_csv(clauses: Sequence[ClauseTrial]) -> str:
    """CSV with a header of :data:`COLUMNS` (numbers as Python writes them; empty for none)."""
    out = io.StringIO()
    writer = csv.DictWriter(out, COLUMNS, lineterminator="\n")
    writer.writeheader()
    for c in clauses:
        writer.writerow({k: "" if v is None else v for k, v in _record(c).items()})
    return out.getvalue()


def trial_junit_xml(clauses: Sequence[ClauseTrial], runs: int) -> str:
    """A JUnit report of a trial of ``runs`` runs: a test suite per scenario, a test case per
    clause with its pass rate, interval and runs as ``<properties>``; failed: ``<failure>``,
    flaky: ``<failure type="flaky">``, inconclusive: ``<skipped message="inconclusive: ...">``."""
    suites = ET.Element("testsuites", name="exsce trial")
    by_scenario: dict[str, list[ClauseTrial]] = {}
    for clause in clauses:
        by_scenario.setdefault(clause.key.scenario, []).append(clause)
    for scenario, mine in by_scenario.items():
        suite = ET.SubElement(
            suites,
            "testsuite",
            name=f"{scenario} trial of {runs} {'run' if runs == 1 else 'runs'}",
            tests=str(len(mine)),
            failures=str(sum(c.outcome in (TrialOutcome.FAILED, TrialOutcome.FLAKY) for c in mine)),
            errors="0",
            skipped=str(sum(c.outcome is TrialOutcome.INCONCLUSIVE for c in mine)),
        )
        for c in mine:
            _testcase(suite, c)
    suites.set("tests", str(len(clauses)))
    suites.set("failures", str(sum(c.outcome in (TrialOutcome.FAILED, TrialOutcome.FLAKY) for c in clauses)))
    suites.set("errors", "0")
    suites.set("skipped", str(sum(c.outcome is TrialOutcome.INCONCLUSIVE for c in clauses)))
    ET.indent(suites)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(suites, encoding="unicode") + "\n"


def _testcase(suite: ET.Element, c: ClauseTrial) -> None:
    case = ET.SubElement(
        suite, "testcase", classname=f"{c.key.scenario}.{c.criterion or 'oracles'}", name=c.description
    )
    properties = ET.SubElement(case, "properties")
    shown = {
        "pass_rate": "" if c.pass_rate is None else f"{c.pass_rate:.4f}",
        "interval": "" if c.low is None or c.high is None else f"[{c.low:.4f}, {c.high:.4f}]",
        "confidence": f"{c.confidence:g}",
        "required_pass_rate": f"{c.required_pass_rate:g}",
        "runs": str(c.passed + c.failed + c.inconclusive),
        "passed": str(c.passed),
        "failed": str(c.failed),
        "inconclusive": str(c.inconclusive),
    }
    for name, value in shown.items():
        ET.SubElement(properties, "property", name=name, value=value)
    if c.outcome is TrialOutcome.FAILED:
        ET.SubElement(case, "failure", message=c.reason, type="failed").text = c.reason
    elif c.outcome is TrialOutcome.FLAKY:
        ET.SubElement(case, "failure", message=c.reason, type="flaky").text = c.reason
    elif c.outcome is TrialOutcome.INCONCLUSIVE:
        ET.SubElement(case, "skipped", message=f"inconclusive: {c.reason}")
