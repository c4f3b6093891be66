"""A campaign: derivations of a base scenario drawn, derived with the relations they must meet,
run, judged, recorded; then each violated relation shrunk to a smallest derivation.

The store is the campaign's state.  Each trial (one derivation, its runs, its verdicts) and
each shrinking is written as one PROV bundle when it is done (:mod:`exsce_dsl.prov.campaign`),
so a campaign killed half-way and started again with the same arguments redoes only the trial
or shrinking it was in: the draws are the same for the same seed, the trials the store has are
read back, and a scenario whose bags are all in its folder and in the store is not run again.

A relation is *violated* by a derivation when it failed in more than half of its runs: one
odd run of three does not send shrinking after noise.  A smaller derivation still violates it
when it violates the same check (:meth:`~exsce_dsl.model.campaign.CheckedRelation.same_check`): an
expected value missed either way counts, whatever direction the smaller one's estimate took.
A trial whose relations neither failed nor passed in more than half of its runs (their other
verdicts inconclusive: a run cut short, data missing) is *inconclusive*: no counterexample,
no pass.

Every draw of the budget is tried unless ``stop_at_violation``, so that the campaign's figures
(:class:`~exsce_dsl.model.campaign.CampaignFigures`: counterexamples per 100 executions,
executions to the first failure) are measured over the whole budget; they are written on the
campaign's activity when it ends.  Each distinct relation violated is shrunk once, from the
first trial that violated it: later trials that violate it again are more counterexamples of
one fault, and shrinking them again would spend runs to find the same smallest derivation.
"""

from __future__ import annotations

import datetime
import hashlib
import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

from exsce_dsl.derive import DerivedSpec, add_derivation, derive_spec
from exsce_dsl.errors import ExsceError
from exsce_dsl.explore.cover import covering_derivations
from exsce_dsl.explore.draw import Candidate, draw_derivations
from exsce_dsl.explore.executors import Executor, bags_in
from exsce_dsl.explore.shrink import MAX_TRIES, shrink
from exsce_dsl.lang import declared_poses, format_document
from exsce_dsl.model import Acceptance, Scenario
from exsce_dsl.model.acceptance import BasicRelation
from exsce_dsl.model.campaign import (
    CampaignFigures,
    CampaignPlan,
    CampaignRecord,
    CampaignTrial,
    CheckedRelation,
    Request,
    Shrinking,
    ShrinkTry,
)
from exsce_dsl.model.document import Specification
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.oracles import verify_runs
from exsce_dsl.prov.campaign import compile_campaign, compile_shrinking, compile_trial
from exsce_dsl.runs import ingest_bags, stored_bag_run_id
from exsce_dsl.store import Store, add_prov, campaign_record, derivation_of
from exsce_dsl.store import runs as stored_runs
from exsce_dsl.transform import derived_document

STRATEGIES = ("covering", "random")
TOLERANCE = 25.0
"""Percent of an expected value a derived scenario's run may be off by default: the estimates
of unobserved path segments are off by up to ~14 % (``bench/estimate.py``), and a campaign that
cries wolf is not run twice."""
BASE_RUNS = 3
"""Runs of the base the store needs before the relations can be estimated (run if missing)."""
SHRINK_TRIES = 40
"""Derivations a shrinking runs at most."""


def scenario_seed(campaign_seed: int, scenario: str) -> int:
    """The seed a campaign gives the runs of ``scenario``: its own, the same in every call, so
    that a finding is played again by it."""
    text = f"{campaign_seed}/{scenario}".encode()
    return int(hashlib.sha256(text).hexdigest()[:5], 16)  # the executor wants seed × 1000 < 2³¹


@dataclass(frozen=True)
class CampaignOptions:
    budget: int
    """Derivations to try."""
    seed: int = 0
    runs_per_scenario: int = 3
    max_steps: int = 2
    transformations: tuple[str, ...] = ()
    strategy: str = "covering"
    relations: bool = True
    """Check the metamorphic relations (else only the base's safety limits: a baseline to compare with)."""
    tolerance: float = TOLERANCE
    shrink: bool = True
    stop_at_violation: bool = False
    """End the draws at the first trial that violates a relation (the figures then cover the
    trials up to it).  By default every draw of the budget is tried, so that counterexamples per
    100 executions is measured over the whole budget."""
    shrink_tries: int = SHRINK_TRIES
    jobs: int = 1
    """Bags of one scenario analysed in parallel."""
    dask_address: str | None = None
    """A Dask scheduler's address: the bags are analysed on its workers (``jobs`` is then not used),
    which open them by their absolute paths (a shared filesystem).  Where the runs are played is
    the executor's business (:class:`~exsce_dsl.explore.executors.SimulatorExecutor`'s ``dask_address``)."""


@dataclass
class CampaignEvents:
    """What a campaign tells its caller as it goes (a progress bar, log lines)."""

    said: Callable[[str], None] = lambda line: None
    trial_done: Callable[[CampaignTrial, bool], None] = lambda trial, resumed: None
    """After each trial; ``resumed``: it was read back from the store, not run."""
    shrink_try_done: Callable[[ShrinkTry], None] = lambda tried: None


@dataclass(frozen=True)
class CampaignResult:
    record: CampaignRecord
    folder: Path
    executions: int
    """Runs executed by this call (not those read back), the base's and the shrinkings' included."""
    figures: CampaignFigures
    """What the trials of this budget found (those read back included): executions of drawn
    derivations, counterexamples, executions to the first failure."""
    minimal_files: dict[str, Path] = field(default_factory=dict)
    """A checked relation's text → the ``.exsce`` file of its minimal failing derivation."""


def plan_campaign(base: Scenario, options: CampaignOptions, executor: Executor) -> CampaignPlan:
    """The plan of a campaign, with its id: a hash of everything but the budget."""
    if options.strategy not in STRATEGIES:
        raise ExsceError(f"unknown strategy '{options.strategy}'; use one of {', '.join(STRATEGIES)}")
    if options.budget < 1 or options.runs_per_scenario < 1:
        raise ExsceError("a campaign needs a budget and runs per scenario of 1 or more")
    identity = repr(
        (
            base.id,
            options.seed,
            options.runs_per_scenario,
            options.max_steps,
            tuple(sorted(options.transformations)),
            executor.name,
            options.strategy,
            options.relations,
            float(options.tolerance),
        )
    )
    digest = hashlib.sha256(identity.encode()).hexdigest()[:8]
    return CampaignPlan(
        id=f"campaign_{digest}",
        base=base.id,
        budget=options.budget,
        seed=options.seed,
        runs_per_scenario=options.runs_per_scenario,
        max_steps=options.max_steps,
        transformations=tuple(sorted(options.transformations)),
        executor=executor.name,
        strategy=options.strategy,
        relations=options.relations,
        tolerance=float(options.tolerance),
    )


def draw(spec: Specification, base: Scenario, options: CampaignOptions) -> list[Candidate]:
    """The derivations a campaign with these options tries, in order."""
    tasks = {t.id: t for t in spec.tasks}
    chosen = options.transformations or None
    if options.strategy == "random":
        return draw_derivations(base, tasks, options.budget, options.seed, options.max_steps, chosen)
    return covering_derivations(base, tasks, options.budget, options.seed, options.max_steps, chosen)


class _Campaign:
    """One campaign being run: what it needs at every trial and shrinking."""

    def __init__(
        self,
        store: Store,
        spec: Specification,
        spec_path: Path,
        base: Scenario,
        options: CampaignOptions,
        executor: Executor,
        folder: Path,
        plan: CampaignPlan,
        events: CampaignEvents,
    ) -> None:
        self.store, self.spec, self.spec_path, self.base = store, spec, spec_path, base
        self.options, self.executor, self.folder, self.plan, self.events = (
            options,
            executor,
            folder,
            plan,
            events,
        )
        self.executions = 0

    def seed_of(self, scenario: str) -> int:
        return scenario_seed(self.plan.seed, scenario)

    def ensure_base_runs(self) -> None:
        have = len(stored_runs(self.store, self.base.id))
        if have >= BASE_RUNS:
            return
        self.events.said(f"the store has {have} run(s) of {self.base.id}: running {BASE_RUNS - have} more")
        self.run(self.base, self.spec_path, BASE_RUNS - have, self.folder / "runs" / self.base.id)

    def run(self, scenario: Scenario, scenario_file: Path, runs: int, out: Path) -> list[str]:
        """The uuids of ``runs`` stored runs of ``scenario``: those already in ``out`` and the
        store, else executed now and ingested (one transaction per run)."""
        if out.is_dir():
            bags = bags_in(out)  # not the .prov.json, .rosparams and logs beside them
            known = [stored_bag_run_id(bag, self.store, scenario.id) for bag in bags]
            if len(bags) == runs and all(known):
                return [k for k in known if k is not None]
            shutil.rmtree(out)  # a run cut short: start the scenario again
        bags = self.executor.execute(scenario, scenario_file, out, runs, self.seed_of(scenario.id))
        self.executions += len(bags)
        uuids = []
        if self.options.dask_address is not None:  # a worker's working folder is not ours
            bags = [bag.absolute() for bag in bags]
        for result in ingest_bags(
            bags, scenario, self.store, self.options.jobs, dask_address=self.options.dask_address
        ):
            if result.failed or result.run_id is None:
                raise result.failure()
            uuids.append(result.run_id)
        return uuids

    def derived(self, requests: Sequence[Request], folder: str) -> DerivedSpec:
        """The derived scenario, its file written under ``folder`` and its oracles in the store."""
        scenario_id = _derived_id(self.spec, self.spec_path, self.base, requests)
        target = self.folder / folder / f"{scenario_id}.exsce"
        made = derive_spec(
            self.spec,
            self.spec_path,
            requests,
            new_id=scenario_id,
            scenario_id=self.base.id,
            target=target,
            expect_from=self.store,
            tolerance=self.options.tolerance,
        )
        if not self.options.relations:
            made = _safety_only(made, self.spec, self.spec_path)
        for note in made.notes:
            self.events.said(f"{scenario_id}: note: {note}")
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(made.text, encoding="utf-8")
        # a scenario drawn again by other steps keeps the derivation that made it first
        add_derivation(self.store, made, generation=derivation_of(self.store, scenario_id) is None)
        return made

    def judge(
        self, requests: Sequence[Request], folder: str
    ) -> tuple[DerivedSpec, tuple[str, ...], list[Verdict]]:
        made = self.derived(requests, folder)
        if made.criteria is None:
            return made, (), []
        runs = self.run(
            made.scenario,
            made.target,
            self.options.runs_per_scenario,
            self.folder / "runs" / made.scenario.id,
        )
        verification = verify_runs(self.store, made.scenario, runs)
        return made, tuple(runs), list(verification.verdicts)

    def trial(self, number: int, candidate: Candidate) -> CampaignTrial:
        made, runs, verdicts = self.judge(candidate.requests, "scenarios")
        found = _violations(verdicts, len(runs))
        trial = CampaignTrial(
            self.plan.id,
            number,
            made.scenario.id,
            candidate.requests,
            runs,
            found.checked,
            found.violated,
            found.failing,
            found.inconclusive,
        )
        add_prov(self.store, compile_trial(trial))
        return trial

    def shrinking(self, number: int, relation: CheckedRelation, trial: CampaignTrial) -> Shrinking:
        tries: list[ShrinkTry] = []

        def still_fails(requests: tuple[Request, ...]) -> bool:
            made, runs, verdicts = self.judge(requests, "shrinking")
            violated = any(relation.same_check(found) for found in _violations(verdicts, len(runs)).violated)
            tried = ShrinkTry(made.scenario.id, requests, violated)
            tries.append(tried)
            self.events.shrink_try_done(tried)
            return violated

        tasks = {t.id: t for t in self.spec.tasks}
        found = shrink(self.base, tasks, trial.steps, still_fails, min(self.options.shrink_tries, MAX_TRIES))
        minimal = _derived_id(self.spec, self.spec_path, self.base, found.requests)
        shrinking = Shrinking(
            self.plan.id,
            number,
            relation,
            trial.number,
            trial.scenario,
            minimal,
            found.requests,
            tuple(tries),
        )
        add_prov(self.store, compile_shrinking(shrinking))
        return shrinking


def run_campaign(
    store: Store,
    spec: Specification,
    spec_path: str | Path,
    options: CampaignOptions,
    executor: Executor,
    folder: str | Path | None = None,
    *,
    scenario_id: str | None = None,
    events: CampaignEvents | None = None,
) -> CampaignResult:
    """Run (or go on with) the campaign these arguments name on a scenario of ``spec`` (read
    from ``spec_path``): files go under ``folder`` (default ``explore/<campaign id>``), the
    provenance to ``store``; see the module's docstring."""
    events = events or CampaignEvents()
    base = spec.scenario(scenario_id)
    plan = plan_campaign(base, options, executor)
    where = Path(folder) if folder is not None else Path("explore") / plan.id
    campaign = _Campaign(store, spec, Path(spec_path), base, options, executor, where, plan, events)
    before = campaign_record(store, plan.id)
    started = before.started if before and before.started else _now()
    add_prov(store, compile_campaign(plan, started), replace=True)
    done = {t.number: t for t in (before.trials if before else ())}
    if done:
        events.said(f"going on with {plan.id}: {len(done)} trial(s) done already")
    campaign.ensure_base_runs()
    trials: list[CampaignTrial] = []
    for number, candidate in enumerate(draw(spec, base, options), start=1):
        if number in done:
            trial = done[number]
            events.trial_done(trial, True)
        else:
            trial = campaign.trial(number, candidate)
            events.trial_done(trial, False)
        trials.append(trial)
        if trial.violated and options.stop_at_violation:
            break
    shrunk = {s.relation: s for s in (before.shrinkings if before else ())}
    if options.shrink:
        for trial in trials:
            for relation in trial.violated:
                if any(relation.same_check(done) for done in shrunk):
                    continue  # found again, or its other direction: shrunk already
                events.said(f"shrinking '{relation.text}' (found by trial {trial.number}: {trial.scenario})")
                shrunk[relation] = campaign.shrinking(len(shrunk) + 1, relation, trial)
    files = {s.relation.text: _minimal_file(campaign, s) for s in shrunk.values()}
    figures = CampaignFigures.of(trials)
    add_prov(store, compile_campaign(plan, started, figures, _now()), replace=True)
    record = campaign_record(store, plan.id)
    assert record is not None  # written above
    return CampaignResult(record, where, campaign.executions, figures, files)


def _minimal_file(campaign: _Campaign, shrinking: Shrinking) -> Path:
    """The minimal failing derivation's file, with the criteria it was checked against, copied
    to ``minimal/`` (a sibling of the folders it was written in: its import stays right)."""
    target = campaign.folder / "minimal" / f"{shrinking.minimal}.exsce"
    for folder in ("scenarios", "shrinking"):
        made = campaign.folder / folder / f"{shrinking.minimal}.exsce"
        if made.is_file():
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(made, target)
            break
    return target


class RelationVerdicts(NamedTuple):
    """What a trial's runs showed of each relation checked."""

    checked: tuple[CheckedRelation, ...]
    violated: tuple[CheckedRelation, ...]
    """Failed in more than half of the runs."""
    failing: tuple[tuple[str, str], ...]
    """The failed verdicts of the violated relations as ``(run, verdict local name)``."""
    inconclusive: tuple[CheckedRelation, ...]
    """Not violated, but they would be had the runs that could not judge them (cut short, their
    recordings not covering the clause) failed them: neither passed nor a counterexample."""


def _violations(verdicts: Sequence[Verdict], runs: int) -> RelationVerdicts:
    """The relations checked, violated and inconclusive in a trial of ``runs`` runs."""
    failures: dict[CheckedRelation, list[Verdict]] = {}
    unjudged: dict[CheckedRelation, set[str]] = {}
    for verdict in verdicts:
        relation = CheckedRelation(verdict.metric, verdict.robot, verdict.relation, verdict.against)
        failures.setdefault(relation, [])
        if verdict.outcome is Outcome.FAILED:
            failures[relation].append(verdict)
        elif verdict.outcome is Outcome.INCONCLUSIVE:
            unjudged.setdefault(relation, set()).add(verdict.run)
    failed = {r: {v.run for v in found} for r, found in failures.items()}
    violated = tuple(sorted((r for r, found in failed.items() if 2 * len(found) > runs), key=_order))
    undecided = tuple(
        sorted(
            (
                r
                for r, found in failed.items()
                if r not in violated and 2 * len(found | unjudged.get(r, set())) > runs
            ),
            key=_order,
        )
    )
    failing = tuple((v.run, _verdict_name(v)) for relation in violated for v in failures[relation])
    return RelationVerdicts(tuple(sorted(failures, key=_order)), violated, failing, undecided)


def _order(relation: CheckedRelation) -> tuple[str, str, str, str]:
    return (relation.robot or "", relation.metric, relation.relationship, relation.against or "")


def _verdict_name(verdict: Verdict) -> str:
    against = f"-vs-{verdict.against}" if verdict.against else ""
    return f"verdict-{verdict.oracle}{against}-{verdict.relation}"


def _derived_id(spec: Specification, spec_path: Path, base: Scenario, requests: Sequence[Request]) -> str:
    """The id of the scenario ``requests`` give: the base's and a hash of the scenario as
    written, so that derivations giving the same scenario (a shrunk one and a drawn one, say)
    are one scenario, with one set of runs, and different scenarios never share an id."""
    made = derive_spec(spec, spec_path, requests, scenario_id=base.id)
    text = made.text.replace(made.scenario.id, "_")
    return f"{base.id}_{hashlib.sha256(text.encode()).hexdigest()[:8]}"


def _safety_only(made: DerivedSpec, spec: Specification, spec_path: Path) -> DerivedSpec:
    """``made`` with only the base's safety clauses: no relation to the base or expected value."""
    if made.criteria is None:
        return made
    limits = (BasicRelation.BELOW_MAX, BasicRelation.ABOVE_MIN)
    criteria = tuple(
        replace(c, expectations=kept)
        for c in made.criteria.criteria
        if (kept := tuple(e for e in c.expectations if e.relation in limits))
    )
    if not criteria:
        return replace(made, criteria=None, text=_text(made, spec, spec_path, None), notes=())
    safety = Acceptance(made.criteria.scenario, criteria)
    return replace(made, criteria=safety, text=_text(made, spec, spec_path, safety), notes=())


def _text(made: DerivedSpec, spec: Specification, spec_path: Path, criteria: Acceptance | None) -> str:
    document = derived_document(made.derived, spec_path, made.target)
    if criteria is not None:
        document = replace(document, declarations=(*document.declarations, criteria))
    return format_document(document, declared_poses(spec.environments))


def _now() -> datetime.datetime:
    return datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
