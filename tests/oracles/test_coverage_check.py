"""What a gap in a recording leaves of a verdict: the rules of oracles.coverage_check, on hand-made
verdicts and gaps (each rule, each edge), then on stored runs of the executor judged with gaps
placed from the executor's own ground truth (the time of r1's first path segment)."""

from __future__ import annotations

import datetime as dt
import json
import shutil
from dataclasses import replace
from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.model.coverage import CoverageGap, Shortfall, TopicRate
from exsce_dsl.model.metrics import Combine
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.oracles.coverage_check import Span, clause_gaps, judge_coverage, learned_rate_gaps
from exsce_dsl.oracles.judging import verify_runs
from exsce_dsl.oracles.verify import judge_runs
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import SimulatedRun, simulate
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries import runs
from exsce_dsl.store.queries.results import verdicts as stored_verdicts

from tests.support.cli import exscec_here
from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC

T0 = dt.datetime(2026, 1, 1, 12, 0, 0, tzinfo=dt.timezone.utc)


def _at(seconds: float) -> dt.datetime:
    return T0 + dt.timedelta(seconds=seconds)


def _verdict(outcome: Outcome, relation: str = "below_max", metric: str = "max_velocity", **given) -> Verdict:
    facts = {"observed": 0.8, "limit": 1.0, "margin": 0.2} if relation in ("below_max", "above_min") else {}
    if relation == "invariant":
        facts = {"observed": 35.0, "expected": 30.0, "tolerance": 3.0, "margin": -2.0}
    return Verdict(
        "run-1", "yard_run", "c", f"r1-{metric}", metric, "r1", relation, outcome, **{**facts, **given}
    )


SCAN_GAP = CoverageGap(
    Shortfall.GAP,
    "/r1/scan has a 4.2 s gap (12:00:03–12:00:07)",
    "r1",
    "/r1/scan",
    ("distance_to_obstacles",),
    _at(3),
    _at(7.2),
)
CUT = CoverageGap(Shortfall.CUT_SHORT, "the recording ends with r1's goal active", start=_at(60))


# -- the rules, on hand-made verdicts ---------------------------------------------------------


def test_a_span_overlaps_a_gap_inside_or_across_it_but_not_one_that_only_touches_it() -> None:
    window = Span(_at(5), _at(10))
    assert window.overlaps(replace(SCAN_GAP, start=_at(3), end=_at(7)))  # across its start
    assert window.overlaps(replace(SCAN_GAP, start=_at(6), end=_at(7)))  # inside
    assert window.overlaps(replace(SCAN_GAP, start=_at(9), end=None))  # open-ended, from inside
    assert not window.overlaps(replace(SCAN_GAP, start=_at(1), end=_at(5)))  # ends as it starts
    assert not window.overlaps(replace(SCAN_GAP, start=_at(10), end=_at(12)))  # starts as it ends
    assert Span().overlaps(replace(SCAN_GAP, start=_at(1000), end=_at(1001)))  # the whole run


def test_a_gap_concerns_only_its_metric_and_robot_and_a_cut_every_window() -> None:
    passed = _verdict(Outcome.PASSED, "above_min", "distance_to_obstacles")
    assert clause_gaps(passed, [SCAN_GAP], Span()) == [SCAN_GAP]
    assert clause_gaps(replace(passed, robot="r2"), [SCAN_GAP], Span()) == []  # r2's clause
    assert clause_gaps(replace(passed, robot=None), [SCAN_GAP], Span()) == [SCAN_GAP]  # the mission's
    assert clause_gaps(_verdict(Outcome.PASSED), [SCAN_GAP], Span()) == []  # max_velocity reads no scan
    later = Span(_at(20), _at(30))
    assert clause_gaps(passed, [SCAN_GAP], later) == []
    assert clause_gaps(passed, [CUT], Span(_at(0), _at(10))) == [CUT]  # the cut comes after: still


def test_a_limit_met_where_the_recording_has_a_gap_is_inconclusive_never_passed() -> None:
    judged = judge_coverage(
        _verdict(Outcome.PASSED, "above_min", "distance_to_obstacles"), [SCAN_GAP], Combine.MIN
    )
    assert judged.outcome is Outcome.INCONCLUSIVE and judged.margin is None
    assert judged.reason == (
        "/r1/scan has a 4.2 s gap (12:00:03–12:00:07): "
        "the limit held in what was recorded, which does not show the rest"
    )
    assert judged.shortfalls == (Shortfall.GAP,) and judged.observed == 0.8


def test_a_limit_broken_in_what_was_recorded_stays_failed_where_more_data_cannot_mend_it() -> None:
    broken = _verdict(Outcome.FAILED, observed=1.3, margin=-0.3, reason="1.3 is not <= 1")
    judged = judge_coverage(broken, [CUT], Combine.MAX)
    assert judged.outcome is Outcome.FAILED and judged.margin == -0.3
    assert judged.reason == "1.3 is not <= 1 in what was recorded (the recording ends with r1's goal active)"
    assert judged.shortfalls == (Shortfall.CUT_SHORT,)
    too_close = _verdict(Outcome.FAILED, "above_min", "distance_to_obstacles", observed=0.05, margin=-0.05)
    assert judge_coverage(too_close, [SCAN_GAP], Combine.MIN).outcome is Outcome.FAILED
    # a count below its minimum in a run cut short may have been reached after the cut
    too_few = _verdict(Outcome.FAILED, "above_min", "waypoints_visited", observed=2, limit=3, margin=-1)
    judged = judge_coverage(too_few, [CUT], Combine.SUM)
    assert judged.outcome is Outcome.INCONCLUSIVE and "was broken in what was recorded" in judged.reason
    unknown = judge_coverage(broken, [CUT], None)  # a metric of unknown accumulation
    assert unknown.outcome is Outcome.INCONCLUSIVE


def test_a_performance_clause_a_gap_concerns_is_inconclusive_whatever_its_value() -> None:
    for outcome in (Outcome.PASSED, Outcome.FAILED):
        judged = judge_coverage(_verdict(outcome, "invariant", "task_duration"), [CUT], Combine.SUM)
        assert judged.outcome is Outcome.INCONCLUSIVE
        assert judged.reason == "the recording ends with r1's goal active: 35 is not the whole run's value"


def test_no_gap_leaves_a_verdict_as_it_was_and_one_without_a_value_says_both_reasons() -> None:
    passed = _verdict(Outcome.PASSED)
    assert judge_coverage(passed, [], Combine.MAX) is passed
    missing = _verdict(Outcome.INCONCLUSIVE, observed=None, margin=None, reason="run run-1 has no value")
    judged = judge_coverage(missing, [CUT], Combine.MAX)
    assert judged.reason == "run run-1 has no value; the recording ends with r1's goal active"
    assert judged.shortfalls == (Shortfall.CUT_SHORT,)


def test_a_topic_recorded_below_half_its_baselines_median_rate_is_a_gap() -> None:
    clause = _verdict(Outcome.PASSED, "above_min", "distance_to_obstacles")
    runs = ("b1", "b2", "b3", "run-1")  # the run itself is left out

    def scan(rate: float, robot: str = "r1") -> TopicRate:
        return TopicRate(f"/{robot}/scan", robot, int(rate * 60), rate, ("distance_to_obstacles",))

    baseline = {"b1": [scan(10.0)], "b2": [scan(9.0)], "b3": [scan(12.0)]}  # median 10 Hz
    [gap] = learned_rate_gaps(clause, (), {**baseline, "run-1": [scan(1.0)]}, runs)
    assert gap.kind is Shortfall.LOW_RATE and gap.topic == "/r1/scan" and gap.robot == "r1"
    assert (
        gap.reason
        == "/r1/scan recorded at 1.0 Hz, the baseline's runs at 10.0 Hz (median of 3): below 50% of theirs"
    )
    assert learned_rate_gaps(clause, (), {**baseline, "run-1": [scan(5.0)]}, runs) == []  # half: not below
    assert learned_rate_gaps(clause, (), {**baseline, "run-1": [scan(4.9)]}, runs) != []
    assert learned_rate_gaps(clause, (), {**baseline, "run-1": [scan(1.0, "r2")]}, runs) == []  # r2's scan
    velocity = TopicRate("/r1/nav_vel", "r1", 60, 1.0, ("max_velocity",))
    assert learned_rate_gaps(clause, (), {**baseline, "run-1": [velocity]}, runs) == []  # not read
    unnamed = TopicRate("/r1/scan", "r1", 60, 1.0)  # names no metric: the oracle's topics decide
    assert learned_rate_gaps(clause, ("/r1/scan",), {**baseline, "run-1": [unnamed]}, runs) != []
    assert learned_rate_gaps(clause, ("/r1/odom",), {**baseline, "run-1": [unnamed]}, runs) == []
    assert learned_rate_gaps(clause, (), {"run-1": [scan(1.0)]}, runs) == []  # no rates of the baseline
    # the judged run is not its own baseline: with it, the median of 3 and 1 Hz would be 2 Hz
    assert learned_rate_gaps(clause, (), {"b1": [scan(3.0)], "run-1": [scan(1.0)]}, ("b1", "run-1")) != []


# -- on stored runs ----------------------------------------------------------------------------

WINDOWED = YARD_SPEC.replace(
    '  scenario "performs as before" {',
    """  scenario "r1 on its way" {
    when yard_mission runs
    then r1 max_velocity stays below 1.0 m/s before r1 reaches field-b
     and r1 max_velocity stays below 1.0 m/s after r1 reaches field-b
  }
  scenario "performs as before" {""",
)


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, SimulatedRun, SimulatedRun]:
    """A baseline of four clean runs; a fifth clean run and an over-speed run of r1, all stored."""
    folder = tmp_path_factory.mktemp("yard_coverage")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(WINDOWED)
    scenario = load_spec(folder / "spec.exsce").scenario()
    clean = list(simulate(scenario, folder / "runs", 5, seed=1))
    fast = next(iter(simulate(scenario, folder / "fast", 1, seed=2, faults=(Fault.parse("overspeed:r1"),))))
    spec = ("--scenario", "spec.exsce")
    done = exscec_here("ingest", *(str(r.bag) for r in clean[:4]), *spec, cwd=folder)
    assert done.returncode == 0, done.stderr
    done = exscec_here("baseline", "spec.exsce", cwd=folder)
    assert done.returncode == 0, done.stderr
    done = exscec_here("ingest", str(clean[4].bag), str(fast.bag), *spec, cwd=folder)
    assert done.returncode == 0, done.stderr
    return folder, clean[4], fast


def _judge(folder: Path, run: SimulatedRun, gaps: list[CoverageGap], **rates) -> dict[str, Verdict]:
    store = open_store(str(folder / ".exsce" / "store"))
    scenario = load_spec(folder / "spec.exsce").scenario()
    uuid = _stored(folder, run)
    verdicts = judge_runs(store, [uuid], scenario, {uuid: gaps}, rates.get("rates"))
    return {v.oracle: v for v in verdicts}


def _stored(folder: Path, run: SimulatedRun) -> str:
    """The uuid the store gave the run of ``run``'s bag."""
    [found] = [r.uuid for r in runs(open_store(str(folder / ".exsce" / "store"))) if r.bag == run.bag.name]
    return found


def _first_segment(run: SimulatedRun) -> tuple[dt.datetime, dt.datetime]:
    """When r1 drove a → b, from the executor's ground truth (seconds from the run's start)."""
    first = next(
        a for a in run.execution.actions if a.robot == "r1" and a.task_number == 1 and a.waypoint_number == 1
    )
    return run.start + dt.timedelta(seconds=first.start), run.start + dt.timedelta(seconds=first.end)


def test_a_gap_in_a_windowed_clauses_segments_makes_it_inconclusive_and_one_elsewhere_does_not(yard) -> None:
    folder, clean, _ = yard
    start, end = _first_segment(clean)
    middle = start + (end - start) / 3
    gap = CoverageGap(
        Shortfall.GAP,
        "/r1/nav_vel has a gap",
        "r1",
        "/r1/nav_vel",
        ("max_velocity",),
        middle,
        middle + (end - start) / 3,
    )
    plain = _judge(folder, clean, [])
    assert {v.outcome for v in plain.values()} == {Outcome.PASSED}, plain
    judged = _judge(folder, clean, [gap])
    before, after = "r1-max_velocity-before-r1-reaches-field-b", "r1-max_velocity-after-r1-reaches-field-b"
    assert judged[before].outcome is Outcome.INCONCLUSIVE, judged[before]
    assert judged[before].reason.startswith("/r1/nav_vel has a gap: the limit held")
    assert judged[after].outcome is Outcome.PASSED  # its segments start where the gap's ended
    assert judged["r1-max_velocity"].outcome is Outcome.INCONCLUSIVE  # the whole run holds the gap
    untouched = {name for name, v in judged.items() if v.outcome is Outcome.PASSED}
    assert untouched == set(plain) - {before, "r1-max_velocity"}  # other metrics, r2, the mission


def test_a_run_cut_short_passes_nothing_and_fails_what_it_broke(yard) -> None:
    folder, clean, fast = yard
    cut = CoverageGap(Shortfall.CUT_SHORT, "the recording ends with goals active", start=clean.start)
    judged = _judge(folder, clean, [cut])
    assert {v.outcome for v in judged.values()} == {Outcome.INCONCLUSIVE}, judged
    assert all(v.shortfalls == (Shortfall.CUT_SHORT,) for v in judged.values())
    plain = _judge(folder, fast, [])
    assert plain["r1-max_velocity"].outcome is Outcome.FAILED
    assert plain["r1-task_duration"].outcome is Outcome.FAILED  # faster than the baseline
    judged = _judge(folder, fast, [replace(cut, start=fast.start)])
    assert judged["r1-max_velocity"].outcome is Outcome.FAILED  # broken in what was recorded
    assert judged["r1-max_velocity"].observed == plain["r1-max_velocity"].observed > 1.0
    assert judged["r1-task_duration"].outcome is Outcome.INCONCLUSIVE  # not the whole run's duration
    assert judged["r2-max_velocity"].outcome is Outcome.INCONCLUSIVE


def test_a_scan_recorded_at_a_tenth_of_the_baselines_rate_leaves_its_clause_inconclusive(yard) -> None:
    folder, clean, _ = yard
    plain = _judge(folder, clean, [])
    assert plain["r1-distance_to_obstacles"].sources == ()  # a limit: from no runs
    sources = plain["r1-task_duration"].sources  # the baseline's runs
    assert len(sources) == 4

    def scan(rate: float) -> list[TopicRate]:
        return [TopicRate("/r1/scan", "r1", int(rate * 40), rate, ("distance_to_obstacles",))]

    rates = {**{run: scan(10.0) for run in sources}, _stored(folder, clean): scan(1.0)}
    judged = _judge(folder, clean, [], rates=rates)
    assert judged["r1-distance_to_obstacles"].outcome is Outcome.INCONCLUSIVE
    assert (
        "/r1/scan recorded at 1.0 Hz, the baseline's runs at 10.0 Hz"
        in judged["r1-distance_to_obstacles"].reason
    )
    assert judged["r1-distance_to_obstacles"].shortfalls == (Shortfall.LOW_RATE,)
    assert judged["r2-distance_to_obstacles"].outcome is Outcome.PASSED
    rates[_stored(folder, clean)] = scan(9.0)
    assert _judge(folder, clean, [], rates=rates)["r1-distance_to_obstacles"].outcome is Outcome.PASSED


def test_an_inconclusive_verdict_and_its_shortfall_are_provenance_in_the_store(yard) -> None:
    folder, clean, _ = yard
    uuid = _stored(folder, clean)
    gap = CoverageGap(Shortfall.GAP, "/r2/scan has a 5 s gap", "r2", "/r2/scan", ("distance_to_obstacles",))
    scenario = load_spec(folder / "spec.exsce").scenario()
    with open_store(str(folder / ".exsce" / "store")) as store:
        verification = verify_runs(store, scenario, [uuid], coverage={uuid: [gap]})
        assert not verification.passed
        [stored] = [v for v in stored_verdicts(store, "yard_run") if v.oracle == "r2-distance_to_obstacles"]
        kinds = store.select(
            "PREFIX oracle: <https://www.sesame-project.org/scenarios/oracles/> "
            "SELECT ?kinds WHERE { GRAPH ?g { ?v oracle:outcome 'inconclusive' ; oracle:shortfall ?kinds } }"
        )
    assert stored.outcome is Outcome.INCONCLUSIVE and stored.shortfalls == (Shortfall.GAP,)
    assert (
        stored.reason
        == "/r2/scan has a 5 s gap: the limit held in what was recorded, which does not show the rest"
    )
    assert [str(row["kinds"].value) for row in kinds] == ["gap"]  # type: ignore[union-attr]


def test_a_cut_the_recording_shows_is_said_once_whether_or_not_the_mission_says_so_too(
    yard, tmp_path
) -> None:
    """A cancelled run (its run-time PROV says so) whose coverage also says it was cut short gives
    one reason, ingestion's; without coverage, the mission's status is the reason."""
    folder, _, _ = yard
    scenario = load_spec(folder / "spec.exsce").scenario()
    store_copy = tmp_path / "store"
    shutil.copytree(folder / ".exsce" / "store", store_copy)
    bag = next(iter(simulate(scenario, tmp_path / "cut", 1, seed=5))).bag  # not stored yet
    document = json.loads(bag.with_suffix(".prov.json").read_text())
    for bundle in document["bundle"].values():
        for activity in bundle.get("activity", {}).values():
            if activity.get("prov:type", {}).get("$") == "exsce:run":
                activity["exsce:mission_status"] = "cancelled"
    bag.with_suffix(".prov.json").write_text(json.dumps(document))
    with open_store(str(store_copy)) as store:
        [uuid] = verify_runs(store, scenario, [bag], record=False).runs
        alone = {v.oracle: v for v in judge_runs(store, [uuid], scenario)}
        cut = CoverageGap(Shortfall.CUT_SHORT, "the recording ends with r1's goal to field-e active")
        both = {v.oracle: v for v in judge_runs(store, [uuid], scenario, {uuid: [cut]})}
    reason = "the run is incomplete (its mission was cancelled): it was not seen to the end"
    assert alone["r1-max_velocity"].reason.startswith(reason + ": the limit held")
    assert both["r1-max_velocity"].reason.startswith(cut.reason + ": the limit held")
    assert all(reason not in v.reason for v in both.values())
    assert {v.outcome for v in both.values()} == {v.outcome for v in alone.values()} == {Outcome.INCONCLUSIVE}
