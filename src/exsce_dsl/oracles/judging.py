"""Judging runs by their scenario's oracles, as the CLI, the Python API and the demo do it.

:func:`build_baseline`: a scenario's oracles from its acceptance criteria and its stored runs,
written to the store.  :func:`verify_runs`: runs (stored uuids, or bags ingested first) judged
against every oracle of their scenario, the verdicts written to the store as provenance.
"""

from __future__ import annotations

import datetime
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from prov.model import ProvDocument

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Scenario
from exsce_dsl.model.coverage import CoverageGap, TopicRate
from exsce_dsl.model.document import Specification
from exsce_dsl.model.oracles import Oracle
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.oracles.baseline import learn_baseline
from exsce_dsl.oracles.good_runs import GoodRuns
from exsce_dsl.oracles.verify import judge_runs
from exsce_dsl.prov.oracle import compile_oracles
from exsce_dsl.prov.verdicts import compile_verdicts
from exsce_dsl.runs import ingest_bags, names_a_bag
from exsce_dsl.store import (
    Store,
    WriteReport,
    add_prov,
    names_a_prefix,
    resolve_runs,
    run_coverage,
    run_topic_rates,
)
from exsce_dsl.store import oracles as stored_oracles
from exsce_dsl.store import runs as stored_runs

"""What a bag's name ends with: such a name that is not a file is a missing bag, not a run id."""


@dataclass(frozen=True)
class Baseline:
    """The oracles built, and what writing them to the store did."""

    scenario: Scenario
    oracles: tuple[Oracle, ...]
    written: WriteReport
    runs: dict[str, GoodRuns] = field(default_factory=dict)
    """The runs the oracles learnt from and those left out with why, by scenario (its own, and
    each base a metamorphic clause compares with)."""


def build_baseline(
    store: Store, spec: Specification, scenario_id: str | None = None, *, include_all: bool = False
) -> Baseline:
    """Build the oracles of a scenario of ``spec`` from its acceptance criteria and its good runs
    in ``store`` (every run with ``include_all``), and write them there, with the runs used and
    those left out (the previous oracles are kept as a revision)."""
    scenario = spec.scenario(scenario_id)
    acceptance = spec.acceptance_of(scenario.id)
    if acceptance is None:
        raise ExsceError(
            f"{spec.root} gives no acceptance criteria for '{scenario.id}' "
            f"(write 'acceptance for {scenario.id} {{...}}')"
        )
    bases = {s.id: s for s in spec.scenarios}
    learnt = learn_baseline(store, acceptance, scenario, bases, include_all=include_all)
    written = add_prov(store, compile_learnt(scenario.id, learnt.oracles, learnt.runs), replace=True)
    return Baseline(scenario, learnt.oracles, written, learnt.runs)


def compile_learnt(scenario_id: str, oracles: Sequence[Oracle], runs: dict[str, GoodRuns]) -> ProvDocument:
    """The PROV of a scenario's oracles with the runs they learnt from and those left out."""
    return compile_oracles(
        scenario_id,
        oracles,
        runs={base: chosen.used for base, chosen in runs.items()},
        left_out={base: chosen.left_out for base, chosen in runs.items() if chosen.left_out},
    )


@dataclass(frozen=True)
class Verification:
    """Every verdict on the runs judged, run by run."""

    scenario: Scenario
    runs: tuple[str, ...]
    verdicts: tuple[Verdict, ...]
    warnings: tuple[str, ...] = ()
    """What makes verdicts say less than they seem to: a run judged against a baseline built
    from it (:func:`own_baseline_warnings`)."""

    def count(self, outcome: Outcome) -> int:
        return sum(v.outcome is outcome for v in self.verdicts)

    @property
    def passed(self) -> bool:
        """No oracle failed and every one was judged."""
        return not self.count(Outcome.FAILED) and not self.count(Outcome.INCONCLUSIVE)


def verify_runs(
    store: Store,
    scenario: Scenario,
    runs: Sequence[str | Path],
    *,
    record: bool = True,
    now: datetime.datetime | None = None,
    coverage: Mapping[str, Sequence[CoverageGap]] | None = None,
    rates: Mapping[str, Sequence[TopicRate]] | None = None,
) -> Verification:
    """Judge ``runs`` (stored runs' uuids, unique prefixes of them or their IRIs, or paths of bags,
    which are ingested first) against every
    oracle of ``scenario``; with ``record``, write the verdicts to the store (at ``now``, UTC).

    ``coverage`` and ``rates`` (run uuid → what its recording does not cover, and how densely it
    recorded each topic; see :func:`~exsce_dsl.oracles.verify.judge_runs`) make verdicts over
    data the recording lacks inconclusive; without them, the store's are taken (what ingest
    found, and the rates of the judged runs and of the runs their baselines learnt from)."""
    bags = [Path(r) for r in runs if isinstance(r, Path) or Path(r).exists()]
    given = [str(r) for r in runs if not (isinstance(r, Path) or Path(r).exists())]
    for text in given:
        if not names_a_prefix(text) and ("/" in text or names_a_bag(text)):  # a path
            raise ExsceError(f"no bag or bag folder {text} (nor is it a run id)")
    uuids = resolve_runs(store, given)  # prefixes and IRIs as well as whole uuids
    for result in ingest_bags(bags, scenario, store) if bags else []:
        if result.failed or result.run_id is None:
            raise result.failure()
        uuids.append(result.run_id)
    judged = tuple(dict.fromkeys(uuids))
    if coverage is None:
        coverage = run_coverage(store, judged)
    if rates is None:
        rates = run_topic_rates(store, _rate_references(store, scenario.id, judged))
    verdicts = judge_runs(store, list(judged), scenario, coverage, rates)
    if record:
        at = now or datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
        for run in dict.fromkeys(v.run for v in verdicts):
            mine = [v for v in verdicts if v.run == run]
            add_prov(store, compile_verdicts(run, mine, at), replace=True)
    return Verification(scenario, judged, tuple(verdicts), own_baseline_warnings(verdicts))


def _rate_references(store: Store, scenario_id: str, judged: Sequence[str]) -> list[str]:
    """The judged runs and every stored run of the scenario and of the scenarios its oracles
    compare with: the runs whose topic rates a judged run's are compared with."""
    scenarios = {scenario_id} | {o.base_scenario for o in stored_oracles(store, scenario_id)}
    others = [run.uuid for sid in sorted(scenarios) for run in stored_runs(store, sid)]
    return list(dict.fromkeys([*judged, *others]))


def own_baseline_warnings(verdicts: Sequence[Verdict]) -> tuple[str, ...]:
    """A warning for each judged run that is one of the runs its oracles' expectations came from
    (the runs a baseline records in the store, ``oracle:runs`` of its PROV): a run compared with a
    mean it is part of passes more easily than a new run would."""
    baselines: dict[str, dict[str, int]] = {}
    for v in verdicts:
        if v.run in v.sources:
            baselines.setdefault(v.run, {})[v.against or v.scenario] = len(v.sources)
    return tuple(
        f"run {run[:8]} is one of the {count} runs the baseline of '{scenario}' was built from: "
        "its verdicts against that baseline say little (judge runs the baseline did not use)"
        for run, built in baselines.items()
        for scenario, count in built.items()
    )
