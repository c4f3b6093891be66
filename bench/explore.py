"""Benchmark: does an exploration campaign find the latent faults planted against scenario_c, in
fewer executions than a baseline, with a small derivation and no false alarms?

For each latent fault of exsce_dsl.sim.faults (planted against the shipped scenario_c; the
derivation that reveals it in brackets) and each seed, on a fresh in-memory store:

- slow-area:classroom_c069 (add_robot starting in classroom_c069),
- detour:classroom_c018:classroom_c022 (reverse_waypoint_order --task delivery_a),
- deadlock-start:tiago1:classroom_c025-w002 (swap_start_poses --robot tiago1 --with tiago2),
- overspeed-reassigned:delivery_a:tiago1 (swap_assignment --robot tiago1 --with tiago2, or any
  step that gives delivery_a to another robot),

and, when --faults names it, overspeed-many-tasks:2 (remove_robot --robot tiago2 --reassign
tiago1, or any step that gives a robot a third task: 30 % of random two-step derivations do,
and random draws find it as fast as covering ones; see MEASURED),

three campaigns are run with the same budget (derivations) and runs per derived scenario:

- the campaign: covering draws, metamorphic relations, the whole budget (``--stop-at-violation``:
  up to the first violating trial), each distinct violated relation shrunk once.  It *found*
  the fault when some shrinking's minimal derivation, run again on the fault-free simulator
  (same per-scenario seeds, a fresh store with only the base's runs to estimate from), does not
  violate that relation, and the fault changed the relation's metric in those runs: the fault,
  not noise or a wrong expectation, made it fail.  (The second condition is needed: expected
  values are estimated from every run in the store, so a relation at the edge of its tolerance
  can fail in the campaign's store and pass in the fresh one with runs the fault never
  touched.)  Executions to detection: runs of derived scenarios up to and with the earliest
  trial a relation the fault caused was found in; shrunk size: steps of that minimal
  derivation (the smallest, if several relations were); shrinking's executions: runs that
  relation's shrinking executed.  The fault-free check's runs are the benchmark's, not the
  campaign's, and are not counted.
- the baseline: uniform random draws (exsce_dsl.explore.draw, as ``exscec explore --strategy
  random`` and ``--compare-random`` draw), the base's safety limits only (no relations), the
  whole budget, no shrinking.  It detected the fault when a violating trial's derivation, run
  fault-free with the same safety limits, does not violate one of them (and the fault changed
  its metric); violating trials are checked in draw order up to the first the fault caused.
- the false-alarm campaign (once per seed, no fault): covering draws, relations, the whole
  budget, no shrinking.  Every violating trial is a false alarm; the relations violated are
  listed, to see where they come from.

Beside detection, each campaign and baseline reports the figures falsification tools report
(exsce_dsl.model.campaign.CampaignFigures): *executions* (runs of drawn derivations: not the
base's, not the shrinkings'), *counterexamples* (trials that violated a relation, whether the
fault's or not), counterexamples per 100 executions, and executions to the first failure (the
first violating trial, whatever it violated), per seed and over all seeds (the rate pooled:
100 × Σ counterexamples / Σ executions; the median of the first failures, none counting as
budget × runs + 1).  They need the whole budget: a campaign stopped at its first failure has
one counterexample by construction.

A campaign or baseline that did not detect the fault counts as budget × runs + 1 executions
in the medians ("never" in the per-seed rows).  Targets (issue: exploration campaigns), per
fault: found in at least 4 of 5 seeds (80 % of --seeds); every found fault shrunk to at most
2 steps; median executions to detection below the baseline's; and a false-alarm rate of 0
(violating trials / trials of the fault-free campaigns, over all seeds).

Last measured (``--quick``: seed 0, budget 8 derivations × 2 runs = 16 executions each, the
whole budget; 2 cores shared with other work, 1 job, ~23 min for the five faults' runs):

    fault                    campaign: counterexamples  per 100  first failure | baseline: ...
    slow-area                          1 in 16            6.2         10       | 0 in 16  0.0  none in 16
    detour                             1 in 16            6.2          4       | 0 in 16  0.0  none in 16
    deadlock-start                     1 in 16            6.2         16       | 0 in 16  0.0  none in 16
    overspeed-reassigned               3 in 16           18.8          8       | 3 in 16  18.8        10
    no fault (false alarms)            0 in 16            0.0   none in 16

The fault-free campaign violated nothing; every relation the campaigns violated was the
fault's (each one's shrunk derivation checked fault-free), and each fault was found and shrunk
to 1 step; the baseline (safety limits only) found only the over-speed, two executions later
(its first counterexample checked, the fault's).  A campaign
finds a latent fault with the one or two derivations that reveal it, so its rate is low
(1 in 8 derivations) until a larger budget draws those derivations again.

    python bench/explore.py                    # 5 seeds, budget 15, 2 runs per scenario
    python bench/explore.py --budget 20        # as first planned (over 30 min on 2 busy cores)
    python bench/explore.py --quick            # 1 seed, budget 8: a smoke test
    python bench/explore.py --faults detour:classroom_c018:classroom_c022 --seeds 3
    python bench/explore.py --jobs 1           # one campaign at a time

Campaigns are independent (each its own store and folder) and run ``--jobs`` at a time; the
executions counted do not depend on it.  Prints figures; never a unit test.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import tempfile
import time
from collections import Counter
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path

from explore_report import progress, report_alarms, report_fault

from exsce_dsl.explore.campaign import (
    CampaignEvents,
    CampaignOptions,
    _Campaign,
    _violations,
    plan_campaign,
    run_campaign,
)
from exsce_dsl.explore.executors import SimulatorExecutor
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.campaign import CampaignFigures, CampaignTrial, CheckedRelation, Request, Shrinking
from exsce_dsl.model.document import Specification
from exsce_dsl.store.base import Store
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries import runs as stored_runs
from exsce_dsl.store.queries.segment_stats import mission_metric_over_runs, robot_metric_over_runs

SPEC = Path(__file__).resolve().parent.parent / "examples" / "brsu_building_c" / "scenario_c.exsce"
FAULTS = {
    "slow-area:classroom_c069": "add_robot starting in classroom_c069",
    "detour:classroom_c018:classroom_c022": "reverse_waypoint_order --task delivery_a",
    "deadlock-start:tiago1:classroom_c025-w002": "swap_start_poses --robot tiago1 --with tiago2",
    "overspeed-reassigned:delivery_a:tiago1": "delivery_a to another robot (swap_assignment, remove_robot "
    "--robot tiago1 --reassign tiago2, substitute_task ... --with delivery_a, ...)",
    "overspeed-many-tasks:2": "a robot with a third task (remove_robot --reassign, add_task, ...)",
}
"""The latent faults that can be measured, and the derivations that reveal each (sim/faults.py)."""
MEASURED = list(FAULTS)[:4]
"""The faults measured unless --faults names others: the four of the issue.  overspeed-many-tasks
stood in for a reassignment fault before overspeed-reassigned existed; 30 % of random two-step
derivations give a robot a third task, and covering draws do not aim at task counts, so random
draws find it as fast (in 4 of 5 seeds with their first derivation, last measured)."""
MANIFEST = "bags.txt"


@dataclass(frozen=True)
class Unit:
    """One campaign to run: ``kind`` is campaign, baseline or clean (fault-free, for false alarms)."""

    kind: str
    fault: str | None
    seed: int
    budget: int
    runs: int
    max_steps: int
    cache: str
    """The folder of bags kept for the other campaigns (see CountingExecutor)."""
    stop: bool = False
    """Campaign and baseline end their draws at the first violating trial (else: the whole budget)."""


@dataclass
class Outcome:
    unit: Unit
    seconds: float = 0.0
    executions: int = 0
    """Every run the campaign executed, the base's and the shrinkings' included."""
    fault_free_runs: int = 0
    """Runs of the fault-free check (its base's included)."""
    simulated: int = 0
    """Runs simulated by this campaign and its check (not copied from the cache)."""
    figures: CampaignFigures | None = None
    """Executions of drawn derivations, counterexamples, executions to the first failure."""
    to_first_violation: int | None = None
    detected: bool = False
    to_detection: int | None = None
    violated: list[str] = field(default_factory=list)
    """Relations violated by the first violating trial (campaign, baseline)."""
    detecting_trial: int | None = None
    """The first trial whose violation the fault caused."""
    caused: list[str] = field(default_factory=list)
    """Of those, the ones the fault caused (not violated fault-free)."""
    not_caused: list[str] = field(default_factory=list)
    """The others, and why not."""
    shrunk_steps: int | None = None
    minimal: tuple[Request, ...] = ()
    shrink_executions: int = 0
    """Runs the shrinkings executed (all of them, and the attributable one's below)."""
    shrink_executions_caused: int | None = None
    trials: int = 0
    violating_trials: int = 0
    false_alarms: Counter[str] = field(default_factory=Counter)
    """Fault-free campaign: relation text → violating trials."""
    alarm_steps: list[tuple[Request, ...]] = field(default_factory=list)


class CountingExecutor:
    """The simulator, counting the runs the campaign has it execute.  ``cache`` (a folder shared
    by the campaigns of a benchmark) keeps each execution's bags by executor, scenario, seed and
    runs: the simulator is deterministic for a seed, so a campaign handed a copy gets the bags it
    would have simulated (the base's runs are simulated once per seed and executor, not by every
    campaign).  ``runs`` counts them all, as the campaign does; ``simulated`` the ones run here."""

    def __init__(self, inner: SimulatorExecutor, cache: Path | None = None) -> None:
        self.inner, self.cache = inner, cache
        self.runs = 0
        self.simulated = 0

    @property
    def name(self) -> str:
        return self.inner.name

    def execute(
        self, scenario: Scenario, scenario_file: Path, out_dir: Path, runs: int, seed: int
    ) -> list[Path]:
        self.runs += runs
        if self.cache is None:
            self.simulated += runs
            return self.inner.execute(scenario, scenario_file, out_dir, runs, seed)
        key = hashlib.sha256(repr((self.name, scenario.id, runs, seed)).encode()).hexdigest()[:16]
        kept = self.cache / key
        if (kept / MANIFEST).is_file():
            shutil.copytree(kept, out_dir, dirs_exist_ok=True, ignore=shutil.ignore_patterns(MANIFEST))
            return [out_dir / name for name in (kept / MANIFEST).read_text().split()]
        bags = self.inner.execute(scenario, scenario_file, out_dir, runs, seed)
        self.simulated += runs
        keeping = Path(tempfile.mkdtemp(prefix=f"{key}-", dir=self.cache))
        shutil.copytree(out_dir, keeping, dirs_exist_ok=True)
        (keeping / MANIFEST).write_text("\n".join(bag.name for bag in bags))
        try:
            keeping.rename(kept)  # another campaign may have kept the same bags first
        except OSError:
            shutil.rmtree(keeping, ignore_errors=True)
        return bags


class FaultFree:
    """Derivations judged on the fault-free simulator with a campaign's options and seeds (the
    per-scenario seeds follow from the campaign's seed and the scenario), in a fresh store with
    only the base's runs to estimate from: did the fault cause a violation?"""

    def __init__(
        self, stack: ExitStack, spec: Specification, options: CampaignOptions, folder: Path, cache: Path
    ) -> None:
        self.stack, self.spec, self.options, self.folder = stack, spec, options, folder
        self.executor = CountingExecutor(SimulatorExecutor(), cache)
        self.campaign: _Campaign | None = None

    def judge(self, requests: Sequence[Request]) -> tuple[tuple[CheckedRelation, ...], tuple[str, ...]]:
        """The relations the fault-free runs of ``requests`` violate, and those runs."""
        if self.campaign is None:
            store: Store = self.stack.enter_context(open_store("memory:"))
            base = self.spec.scenario(None)
            plan = plan_campaign(base, self.options, self.executor)
            self.campaign = _Campaign(
                store, self.spec, SPEC, base, self.options, self.executor, self.folder, plan, CampaignEvents()
            )
            self.campaign.ensure_base_runs()
        _, runs, verdicts = self.campaign.judge(tuple(requests), "fault-free")
        return _violations(verdicts, len(runs)).violated, runs

    def caused(
        self, relation: CheckedRelation, requests: Sequence[Request], store: Store, runs: Sequence[str]
    ) -> str:
        """Whether the fault caused ``relation``'s violation by the derivation ``requests``, whose
        faulty runs are ``runs`` of ``store``: "yes" when the fault-free runs (same seeds) do not
        violate it and the fault changed the relation's metric; else why not.  (Expected values
        depend on every run in a store, so a relation at the edge of its tolerance can pass in
        the fresh store and fail in the campaign's, with runs the fault did not touch.)"""
        innocent, clean_runs = self.judge(requests)
        if any(relation.same_check(found) for found in innocent):  # as the campaign's shrinking counts it
            return "violated without the fault too"
        assert self.campaign is not None
        before, after = (
            metric_values(store, relation, runs),
            metric_values(self.campaign.store, relation, clean_runs),
        )
        if before is not None and after is not None and before == after:
            return "runs the same without the fault"
        return "yes"


def metric_values(store: Store, relation: CheckedRelation, runs: Sequence[str]) -> list[float] | None:
    """The relation's metric in each run, rounded to 9 digits and sorted (None if not stored)."""
    values = []
    for run in runs:
        if relation.robot is not None:
            stats = robot_metric_over_runs(store, relation.metric, relation.robot, [run])
        else:
            stats = mission_metric_over_runs(store, relation.metric, [run])
        if stats is None:
            return None
        values.append(round(stats.mean, 9))
    return sorted(values)


def options_of(unit: Unit) -> CampaignOptions:
    """The campaign's options (covering, relations, shrinking), the baseline's (random, safety
    limits only, no shrinking) or the fault-free campaign's (covering, relations, no shrinking);
    each tries the whole budget unless the unit stops at the first violation."""
    kind = {
        "campaign": ("covering", True, True),
        "baseline": ("random", False, False),
        "clean": ("covering", True, False),
    }
    strategy, relations, shrink = kind[unit.kind]
    stop = unit.stop and unit.kind != "clean"
    return CampaignOptions(
        budget=unit.budget,
        seed=unit.seed,
        runs_per_scenario=unit.runs,
        max_steps=unit.max_steps,
        strategy=strategy,
        relations=relations,
        shrink=shrink,
        stop_at_violation=stop,
    )


def run_unit(unit: Unit) -> Outcome:
    began = time.perf_counter()
    spec = load_spec(SPEC)
    options = options_of(unit)
    faults = [unit.fault] if unit.fault else []
    executor = CountingExecutor(SimulatorExecutor.with_faults(faults), Path(unit.cache))
    marks: list[tuple[str, int]] = []

    def said(line: str) -> None:
        if line.startswith("shrinking '"):
            marks.append((line.removeprefix("shrinking '").partition("' (found by")[0], executor.runs))

    outcome = Outcome(unit)
    with ExitStack() as stack:
        folder = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="exsce-explore-")))
        store: Store = stack.enter_context(open_store("memory:"))
        result = run_campaign(
            store, spec, SPEC, options, executor, folder / "campaign", events=CampaignEvents(said=said)
        )
        record = result.record
        outcome.executions = executor.runs
        outcome.figures = result.figures
        outcome.to_first_violation = result.figures.executions_to_first_failure
        outcome.trials = len(record.trials)
        violating = [t for t in record.trials if t.violated]
        outcome.violating_trials = len(violating)
        if unit.kind == "clean":
            for trial in violating:
                outcome.false_alarms.update(r.text for r in trial.violated)
                outcome.alarm_steps.append(trial.steps)
        elif violating:
            outcome.violated = [r.text for r in violating[0].violated]
            fault_free = FaultFree(stack, spec, options, folder / "fault-free", Path(unit.cache))
            if unit.kind == "baseline":
                judge_baseline(outcome, violating, fault_free, store)
            else:
                ends = [runs for _, runs in marks[1:]] + [executor.runs]
                spent = {text: end - runs for (text, runs), end in zip(marks, ends, strict=True)}
                judge_campaign(outcome, record.shrinkings, spent, fault_free, store)
            outcome.detected = outcome.detecting_trial is not None
            if outcome.detecting_trial is not None:
                outcome.to_detection = executions_until(record.trials, outcome.detecting_trial)
            outcome.fault_free_runs = fault_free.executor.runs
            outcome.simulated += fault_free.executor.simulated
        outcome.simulated += executor.simulated
    outcome.seconds = time.perf_counter() - began
    return outcome


def executions_until(trials: Sequence[CampaignTrial], number: int) -> int:
    """Runs of the trials drawn up to and with trial ``number``."""
    return sum(len(t.runs) for t in trials if t.number <= number)


def judge_baseline(
    outcome: Outcome, violating: Sequence[CampaignTrial], fault_free: FaultFree, store: Store
) -> None:
    """The first violating trial whose violation the fault caused (trials checked in draw order,
    up to that one: each check runs the derivation fault-free)."""
    for trial in violating:
        for relation in trial.violated:
            why = fault_free.caused(relation, trial.steps, store, trial.runs)
            if why == "yes":
                outcome.caused.append(relation.text)
            else:
                outcome.not_caused.append(f"{relation.text} (trial {trial.number}: {why})")
        if outcome.caused:
            outcome.detecting_trial = trial.number
            return


def judge_campaign(
    outcome: Outcome,
    shrinkings: Sequence[Shrinking],
    spent: dict[str, int],
    fault_free: FaultFree,
    store: Store,
) -> None:
    """The shrinkings whose minimal derivation the fault caused to violate its relation: the
    smallest of them, and the earliest trial one of them was found in."""
    outcome.shrink_executions = sum(spent.values())
    best = None
    for shrinking in shrinkings:
        runs = [r.uuid for r in stored_runs(store, shrinking.minimal)]
        why = fault_free.caused(shrinking.relation, shrinking.minimal_steps, store, runs)
        if why != "yes":
            outcome.not_caused.append(f"{shrinking.relation.text} ({why})")
            continue
        outcome.caused.append(shrinking.relation.text)
        if outcome.detecting_trial is None or shrinking.trial < outcome.detecting_trial:
            outcome.detecting_trial = shrinking.trial
        if best is None or len(shrinking.minimal_steps) < len(best.minimal_steps):
            best = shrinking
    if best is not None:
        outcome.shrunk_steps = len(best.minimal_steps)
        outcome.minimal = best.minimal_steps
        outcome.shrink_executions_caused = spent.get(best.relation.text)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--seeds", type=int, default=5, help="seeds 0 .. N-1 (default 5)")
    parser.add_argument("--budget", type=int, default=15, help="derivations per campaign (default 15)")
    parser.add_argument("--runs", type=int, default=2, help="runs per derived scenario (default 2)")
    parser.add_argument("--max-steps", type=int, default=2, help="steps per drawn derivation (default 2)")
    parser.add_argument(
        "--faults",
        nargs="+",
        default=MEASURED,
        metavar="FAULT",
        help="the faults to measure (default: all but overspeed-many-tasks)",
    )
    parser.add_argument("--quick", action="store_true", help="1 seed, budget 8")
    parser.add_argument(
        "--stop-at-violation",
        action="store_true",
        help="campaign and baseline end at their first violating trial (as measured before: "
        "executions to detection only) [default: the whole budget]",
    )
    parser.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1), help="campaigns run at once")
    options = parser.parse_args()
    if options.quick:
        options.seeds, options.budget = 1, 8
    seeds = list(range(options.seeds))
    never = options.budget * options.runs + 1
    unknown = [f for f in options.faults if f not in FAULTS]
    if unknown:
        parser.error(f"unknown fault {unknown[0]}; the faults: {', '.join(FAULTS)}")
    cache = tempfile.TemporaryDirectory(prefix="exsce-explore-bags-")
    sizes = (options.budget, options.runs, options.max_steps, cache.name, options.stop_at_violation)
    units = [Unit("clean", None, s, *sizes) for s in seeds]  # the longest first
    units += [Unit(k, f, s, *sizes) for s in seeds for f in options.faults for k in ("baseline", "campaign")]
    print(
        f"exploration benchmark on {SPEC.name}: seeds {seeds[0]}..{seeds[-1]}, budget {options.budget} "
        f"derivations, {options.runs} runs each, at most {options.max_steps} steps, {options.jobs} job(s)"
    )
    began = time.perf_counter()
    outcomes: list[Outcome] = []
    if options.jobs > 1:
        with ProcessPoolExecutor(options.jobs) as pool:
            for future in as_completed([pool.submit(run_unit, u) for u in units]):
                outcomes.append(future.result())
                print(progress(outcomes[-1]), flush=True)
    else:
        for unit in units:
            outcomes.append(run_unit(unit))
            print(progress(outcomes[-1]), flush=True)
    cache.cleanup()
    print(
        f"runs: {sum(o.executions for o in outcomes)} executed by the campaigns, "
        f"{sum(o.fault_free_runs for o in outcomes)} by the fault-free checks; "
        f"{sum(o.simulated for o in outcomes)} simulated (the rest were the same bags again)"
    )
    alarm_rate = report_alarms([o for o in outcomes if o.unit.kind == "clean"])
    passed = []
    for fault in options.faults:
        of = [o for o in outcomes if o.unit.fault == fault]
        campaigns = [o for o in of if o.unit.kind == "campaign"]
        baselines = [o for o in of if o.unit.kind == "baseline"]
        passed += report_fault(
            fault, FAULTS.get(fault, "?"), campaigns, baselines, alarm_rate, never, len(seeds)
        )
    print(
        "\n'to detection': runs of derived scenarios up to and with the first trial whose violation the "
        "fault caused;\n'never': no violation within the budget, 'never*': violations, none the fault's "
        f"(of those checked); both count as {never} (budget × runs + 1) in the medians.\n'shrink runs': "
        "the found relation's shrinking (all shrinkings in brackets); 'all runs': every run executed, the "
        "base's 3 included.\n'executions': runs of drawn derivations; 'counterexamples': trials that "
        "violated a relation (the fault's or not); 'per 100': counterexamples per 100 executions; 'first "
        f"failure': executions to the first violating trial ('all': median, none counting {never})."
    )
    met = sum(ok for _, ok in passed)
    print(f"\ntargets met: {met}/{len(passed)}; wall time {time.perf_counter() - began:.0f} s")


if __name__ == "__main__":
    main()
