"""An exploration campaign for CI systems: JUnit XML, one test case per derivation tried.

It follows :func:`exsce_dsl.oracles.report.junit_xml`: a ``<testsuites>`` element around the
suites, built with :mod:`xml.etree.ElementTree` (which escapes every text and attribute).
The campaign is one ``<testsuite name="campaign ID">``; each trial a ``<testcase>``
(``classname`` the campaign's id, ``name`` ``trial N: STEPS``) which fails when the trial
violated a relation (the failure names the relations and the smallest derivation found that
still violates each) and is skipped when it checked none, or when it decided none of them
violated but runs it could not judge them on (cut short, not covered by their recordings)
could have (``inconclusive: RELATIONS``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence

from exsce_dsl.model.campaign import CampaignRecord, CampaignTrial, CheckedRelation, Request, Shrinking
from exsce_dsl.store import Store
from exsce_dsl.store import runs as stored_runs
from exsce_dsl.transform import TRANSFORMATIONS
from exsce_dsl.wording import counted

__all__ = ["campaign_junit_xml", "run_seconds", "step_text", "steps_text"]

ARROW = " → "
"""Between the steps of a derivation, as people read it."""


def step_text(step: Request) -> str:
    """``remove_robot(robot=tiago2, reassign=tiago1)``: the arguments in the order the
    transformation declares them (required, then optional), any others after, by name."""
    name, arguments = step
    known = TRANSFORMATIONS.get(name)
    declared = (known.required + known.optional) if known is not None else ()
    order = [k for k in declared if k in arguments] + sorted(k for k in arguments if k not in declared)
    return f"{name}({', '.join(f'{k}={arguments[k]}' for k in order)})"


def steps_text(steps: Sequence[Request]) -> str:
    """``remove_robot(robot=tiago2, reassign=tiago1) → reverse_waypoint_order(task=delivery_a)``
    (``base scenario`` for no step)."""
    return ARROW.join(step_text(s) for s in steps) or "base scenario"


def _seconds(value: float) -> str:
    return f"{value:.3f}"


def _shrunk(relation: CheckedRelation, trial: int, shrinkings: Sequence[Shrinking]) -> list[str]:
    """Where ``relation``, violated in ``trial``, was shrunk to: ``minimal derivation STEPS
    (scenario ID, N tries)`` per shrinking of it found in this trial; else which trial it was
    shrunk from, or that it was not."""
    here = [s for s in shrinkings if s.relation == relation and s.trial == trial]
    if here:
        return [
            f"minimal derivation {steps_text(s.minimal_steps)} "
            f"(scenario {s.minimal}, {len(s.tries)} {'try' if len(s.tries) == 1 else 'tries'})"
            for s in here
        ]
    elsewhere = sorted({s.trial for s in shrinkings if s.relation == relation})
    if elsewhere:
        return [f"shrunk from trial {', '.join(str(n) for n in elsewhere)}"]
    return ["not shrunk"]


def _failure(trial: CampaignTrial, shrinkings: Sequence[Shrinking]) -> tuple[str, str]:
    """A violated trial's failure: its message (each relation and where it was shrunk to) and its
    text (the same, a line per relation, after the scenario and its runs)."""
    found = [(r.text, _shrunk(r, trial.number, shrinkings)) for r in trial.violated]
    message = "violated " + "; ".join(f"{r}: {', '.join(where)}" for r, where in found)
    lines = [
        f"scenario {trial.scenario}, {counted(len(trial.runs), 'run')}, "
        f"{counted(len(trial.checked), 'relation')} checked"
    ]
    lines += [f"violated {r}: {where}" for r, shrunk in found for where in shrunk]
    return message, "\n".join(lines)


def campaign_junit_xml(record: CampaignRecord, durations: Mapping[str, float] | None = None) -> str:
    """The campaign as JUnit XML (see the module's docstring).

    A test case's ``time`` is what its runs took, from ``durations`` (run uuid → seconds, as
    :func:`run_seconds` reads them from the store; a run missing there counts 0); the suite's is
    their sum, and its ``timestamp`` when the campaign started.
    """
    took = durations or {}
    plan = record.plan
    suites = ET.Element("testsuites", name="exsce explore")
    suite = ET.SubElement(suites, "testsuite", name=f"campaign {plan.id}")
    if record.started is not None:
        suite.set("timestamp", record.started.isoformat())
    properties = ET.SubElement(suite, "properties")
    for name, value in (
        ("base", plan.base),
        ("seed", str(plan.seed)),
        ("budget", str(plan.budget)),
        ("runs_per_scenario", str(plan.runs_per_scenario)),
        ("executor", plan.executor),
    ):
        ET.SubElement(properties, "property", name=name, value=value)
    total = 0.0
    for trial in record.trials:
        seconds = sum(took.get(run, 0.0) for run in trial.runs)
        total += seconds
        case = ET.SubElement(
            suite,
            "testcase",
            classname=plan.id,
            name=f"trial {trial.number}: {steps_text(trial.steps)}",
            time=_seconds(seconds),
        )
        if trial.violated:
            message, text = _failure(trial, record.shrinkings)
            ET.SubElement(case, "failure", message=message, type="relation violated").text = text
        elif trial.inconclusive:
            undecided = "; ".join(r.text for r in trial.inconclusive)
            message = f"inconclusive: {undecided} (runs that could not judge it could have violated it)"
            ET.SubElement(case, "skipped", message=message)
        elif not trial.checked:
            ET.SubElement(case, "skipped", message="no relation was checked")
    failures = sum(bool(t.violated) for t in record.trials)
    skipped = sum(t.outcome in ("unchecked", "inconclusive") for t in record.trials)
    for element in (suites, suite):
        element.set("tests", str(len(record.trials)))
        element.set("failures", str(failures))
        element.set("errors", "0")
        element.set("time", _seconds(total))
    suite.set("skipped", str(skipped))
    ET.indent(suites)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(suites, encoding="unicode") + "\n"


def run_seconds(store: Store, record: CampaignRecord) -> dict[str, float]:
    """Run uuid → how long it took, for the runs of ``record``'s trials the store knows the start
    and end of."""
    found: dict[str, float] = {}
    for scenario in sorted({t.scenario for t in record.trials}):
        for run in stored_runs(store, scenario):
            if run.start is not None and run.end is not None:
                found[run.uuid] = (run.end - run.start).total_seconds()
    return found
