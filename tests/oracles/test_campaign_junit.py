"""A campaign as JUnit XML: written to a real store, read back, one test case per trial."""

from __future__ import annotations

import datetime
import xml.etree.ElementTree as ET
from dataclasses import replace

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.model.campaign import CampaignPlan, CampaignRecord, CampaignTrial, Shrinking
from exsce_dsl.model.runs import Bag, Run
from exsce_dsl.oracles.campaign_junit import campaign_junit_xml, run_seconds, steps_text
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.campaign import compile_campaign, compile_shrinking, compile_trial
from exsce_dsl.prov.run import compile_run
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries.campaigns import campaign_record
from exsce_dsl.store.writing import add_prov
from exsce_dsl.transform.derivation import derive

from tests.support.campaign_samples import DURATION, REMOVE, REVERSE, SHRINKINGS, sample_trials
from tests.support.paths import EXAMPLES

STARTED = datetime.datetime(2025, 3, 1, 12, 0, tzinfo=datetime.timezone.utc)
PLAN = CampaignPlan(
    "c_explore",
    "scenario_c",
    12,
    7,
    3,
    2,
    (),
    'simulator --fault "slow-area:<c069>" & more',
    "random",
    True,
    10.0,
)


def _trials() -> list[CampaignTrial]:
    return list(
        sample_trials((("run1a", "run1b", "run1c"), ("run2a", "run2b", "run2c"), ("run3a", "run3b", "run3c")))
    )


def _shrinkings() -> list[Shrinking]:
    return list(SHRINKINGS)


@pytest.fixture(scope="module")
def stored() -> tuple[CampaignRecord, dict[str, float]]:
    """The campaign written to a store with the runs of trial 1 (20 s, 25 s and 30.5 s long), read
    back, and how long those runs took by the store."""
    base = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c")
    derived = derive(base, [REMOVE], "c_explore_0001").scenario
    with open_store("memory:") as store:
        add_prov(store, compile_scenario(base))
        add_prov(store, compile_scenario(derived))
        for uuid, seconds in (("run1a", 20.0), ("run1b", 25.0), ("run1c", 30.5)):
            end = STARTED + datetime.timedelta(seconds=seconds)
            add_prov(
                store,
                compile_run(Run(uuid, derived.id, STARTED, end, Bag(f"{uuid}.bag", ()), (), ()), derived),
            )
        add_prov(store, compile_campaign(PLAN, STARTED))
        for trial in _trials():
            add_prov(store, compile_trial(trial))
        for shrinking in _shrinkings():
            add_prov(store, compile_shrinking(shrinking))
        record = campaign_record(store, "c_explore")
        assert record is not None
        return record, run_seconds(store, record)


def _suite(xml: str) -> ET.Element:
    root = ET.fromstring(xml)
    assert root.tag == "testsuites" and len(root) == 1
    return root[0]


def test_the_campaign_is_one_suite_with_a_case_per_trial_in_order(
    stored: tuple[CampaignRecord, dict[str, float]],
) -> None:
    record, _ = stored
    suite = _suite(campaign_junit_xml(record))
    assert suite.tag == "testsuite" and suite.get("name") == "campaign c_explore"
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors"), suite.get("skipped")) == (
        "4",
        "2",
        "0",
        "1",
    )
    assert suite.get("timestamp") == "2025-03-01T12:00:00+00:00"
    cases = suite.findall("testcase")
    assert {c.get("classname") for c in cases} == {"c_explore"}
    assert [c.get("name") for c in cases] == [
        "trial 1: remove_robot(robot=tiago2, reassign=tiago1)",
        "trial 2: reverse_waypoint_order(task=delivery_a)",
        "trial 3: reverse_waypoint_order(task=delivery_a) → remove_robot(robot=tiago2, reassign=tiago1)",
        "trial 4: reverse_waypoint_order(task=delivery_a)",
    ]
    outcomes = [[child.tag for child in c] for c in cases]
    assert outcomes == [["failure"], [], ["failure"], ["skipped"]]
    properties = {p.get("name"): p.get("value") for p in suite.iter("property")}
    assert (
        properties["executor"] == PLAN.executor and properties["seed"] == "7" and properties["budget"] == "12"
    )


def test_a_failure_names_the_violated_relations_and_their_minimal_derivations(
    stored: tuple[CampaignRecord, dict[str, float]],
) -> None:
    record, _ = stored
    cases = _suite(campaign_junit_xml(record)).findall("testcase")
    first, third = (cases[i].find("failure") for i in (0, 2))
    assert first is not None and third is not None
    assert first.get("message") == (
        "violated tiago1 task_duration increasing vs scenario_c: minimal derivation "
        "remove_robot(robot=tiago2, reassign=tiago1) (scenario c_explore_0001, 1 try)"
    )
    # trial 3 violated both; distance was shrunk from it, duration from trial 1
    message = third.get("message") or ""
    assert message.startswith("violated tiago1 task_duration increasing vs scenario_c: shrunk from trial 1; ")
    assert message.endswith(
        "tiago1 distance_travelled invariant: minimal derivation remove_robot(robot=tiago2, reassign=tiago1) "
        "(scenario c_explore_s2_1, 2 tries)"
    )
    lines = (third.text or "").splitlines()
    assert lines[0] == "scenario c_explore_0003, 3 runs, 2 relations checked"
    assert len(lines) == 3 and lines[2].startswith(
        "violated tiago1 distance_travelled invariant: minimal derivation"
    )


def test_times_are_what_the_runs_took_by_the_store(stored: tuple[CampaignRecord, dict[str, float]]) -> None:
    record, durations = stored
    assert durations == {"run1a": 20.0, "run1b": 25.0, "run1c": 30.5}  # the other trials' runs are not stored
    root = ET.fromstring(campaign_junit_xml(record, durations))
    suite = root[0]
    assert [c.get("time") for c in suite.findall("testcase")] == ["75.500", "0.000", "0.000", "0.000"]
    assert suite.get("time") == root.get("time") == "75.500"
    assert ET.fromstring(campaign_junit_xml(record))[0].get("time") == "0.000"  # nothing known: nothing taken


def test_text_is_escaped_and_the_xml_parses(stored: tuple[CampaignRecord, dict[str, float]]) -> None:
    record, _ = stored
    xml = campaign_junit_xml(record)
    assert xml.startswith('<?xml version="1.0" encoding="UTF-8"?>\n')
    assert "&lt;c069&gt;" in xml and "&amp; more" in xml and "<c069>" not in xml


def test_a_campaign_without_trials_is_an_empty_suite() -> None:
    suite = _suite(campaign_junit_xml(CampaignRecord(PLAN, None, (), ())))
    assert (suite.get("tests"), suite.get("failures"), suite.get("time")) == ("0", "0", "0.000")
    assert suite.get("timestamp") is None and not suite.findall("testcase")


def test_steps_read_as_the_transformation_declares_its_arguments() -> None:
    assert steps_text([("remove_robot", {"reassign": "tiago1", "robot": "tiago2"})]) == (
        "remove_robot(robot=tiago2, reassign=tiago1)"
    )
    assert steps_text([("unknown_step", {"b": "2", "a": "1"}), REVERSE]) == (
        "unknown_step(a=1, b=2) → reverse_waypoint_order(task=delivery_a)"
    )
    assert steps_text([]) == "base scenario"


def test_a_trial_that_decided_nothing_violated_but_not_everything_is_skipped_as_inconclusive() -> None:
    """Trial 2 again, its duration relation undecided (runs cut short could have violated it):
    written to the store, read back, and a ``<skipped message="inconclusive: ...">`` case."""
    undecided = replace(_trials()[1], inconclusive=(DURATION,))
    assert undecided.outcome == "inconclusive"
    with open_store("memory:") as store:
        add_prov(store, compile_campaign(PLAN, STARTED))
        add_prov(store, compile_trial(undecided))
        add_prov(store, compile_trial(_trials()[0]))  # decided: no exsce:inconclusive
        record = campaign_record(store, "c_explore")
    assert record is not None
    first, second = sorted(record.trials, key=lambda t: t.number)
    assert second.inconclusive == (DURATION,) and second.outcome == "inconclusive"
    assert first.inconclusive == () and first.outcome == "violated"
    suite = _suite(campaign_junit_xml(record))
    assert (suite.get("tests"), suite.get("failures"), suite.get("skipped")) == ("2", "1", "1")
    skipped = suite.findall("testcase")[1].find("skipped")
    assert skipped is not None and skipped.get("message") == (
        f"inconclusive: {DURATION.text} (runs that could not judge it could have violated it)"
    )
