"""Benchmark: how often a performance clause fails a healthy run, and how often it catches a fault.

Simulates fault-free runs of the shipped scenario_c with the kinematic executor (and runs with
each fault of exsce_dsl.sim.faults that shows in scenario_c's own runs), ingests them once into
an embedded store, then rotates baselines: the fault-free runs are cut into blocks of n (the
baseline's runs), and for each block the real code builds the oracles from that block alone
(``baseline_oracles(..., runs=block)``), writes them to the store and judges (``judge_runs``)
every fault-free run outside the block and every faulty run.  scenario_c's performance clauses
are judged three ways: ``at 95 %``, ``at 99 %`` (Student's prediction interval for one new run)
and the method's default (one standard deviation of the baseline, ``is invariant``).

Printed per performance oracle and setting: false failures / judged, their rate, the rate the
setting promises (1 − c; for the default, P(|t_{n−1}| > √((n−1)/(n+1))), what one population
std around the mean of n normal values leaves out), the binomial 95 % band of the rate around
that for so many judgements and whether the rate is inside, and the rate ± 1.96 standard errors
over the baselines (the judgements against one baseline share its mean and spread, so they are
not independent: this second band is the honest one).  Then the detection rate of each fault
at the same settings: the fraction of faulty runs each oracle failed, averaged over baselines.

    python bench/oracles.py --quick                 # 40 fault-free runs, 10 of each fault
    python bench/oracles.py                         # 200 fault-free runs, 30 of each fault
    python bench/oracles.py --baseline-runs 5
    python bench/oracles.py --store DIR             # keep the runs in DIR (filled once, reused after)

Prints figures; never a unit test.

MEASURED (2-core machine shared with others, 2026-11-27; 200 fault-free runs, seeds 1..200, 15
runs of each fault; 20 disjoint baselines of 10 runs, each judging the 190 other fault-free runs:
3800 judgements per oracle and setting; ~1300 s to simulate, ~110 s to ingest, ~60-85 s per
setting to build the 20 baselines and judge):

    oracle                     setting  ±band    failed/judged  rate   1−c    binomial band   in
    tiago1-task_duration       95 %     6.11 s     66/3800     0.017  0.050  [0.043, 0.057]  no
    tiago1-task_duration       99 %     8.78 s     11/3800     0.003  0.010  [0.007, 0.013]  no
    tiago1-task_duration       1 std    2.44 s   1723/3800     0.453  0.389  [0.374, 0.405]  no
    tiago2-task_duration       95 %     6.62 s     47/3800     0.012  0.050                  no
    tiago2-task_duration       99 %     9.51 s      0/3800     0.000  0.010                  no
    tiago2-task_duration       1 std    2.65 s   1698/3800     0.447  0.389                  no
    tiago1-distance_travelled  95 %     5.4 mm    149/3800     0.039  0.050  (se band [0.016, 0.062]: yes)
    tiago1-distance_travelled  99 %     7.8 mm     20/3800     0.005  0.010  (se band [0.001, 0.010]: no)
    tiago1-distance_travelled  1 std    2.2 mm   1393/3800     0.367  0.389  (se band [0.309, 0.425]: yes)
    tiago2-distance_travelled  95 %     5.4 mm    149/3800     0.039  0.050  (se band [0.025, 0.054]: yes)
    tiago2-distance_travelled  99 %     7.7 mm     24/3800     0.006  0.010  (se band [0.001, 0.011]: yes)
    tiago2-distance_travelled  1 std    2.2 mm   1454/3800     0.383  0.389  [0.374, 0.405]  yes
    tiago1/2-waypoints_visited any      0           0/3800     0.000         (always 3: no spread)
    mission_duration           95 %     6.60 s     39/3800     0.010  0.050                  no
    mission_duration           99 %     9.48 s      0/3800     0.000  0.010                  no
    mission_duration           1 std    2.64 s   1697/3800     0.447  0.389                  no
    fault-free runs failing any performance clause: 95 % 0.104, 99 % 0.014, 1 std 0.892

Why the durations miss their bands (not tuned away): the executor draws each robot's speed
uniformly in [0.9, 1.0] of its limit and its waits uniformly, so a duration is close to uniform:
excess kurtosis −1.15, Shapiro–Wilk p ≈ 1e-5 over the 200 runs.  A uniform value never goes
beyond √3 ≈ 1.73 standard deviations of its mean, while the 95 % band reaches 2.37 s_n (t_{.975,9}
· √1.1): light tails fail less than promised (1.0-1.7 % at 95 %, 0-0.3 % at 99 %), and fail one
standard deviation more often (0.45 against the 0.39 of normal values with n = 10; the asymptotic
"about a third" is 0.32).  The distances (pose noise, kurtosis −0.33 and −0.04) are near normal and
near their promise (0.039 at 95 %, 0.005 at 99 %; inside the baselines' standard-error band, just
under the binomial one, which is too narrow: the 190 judgements of one baseline share its mean
and spread).  waypoints_visited is 3 in every healthy run: its band is 0 and it never fails.

Detection, fraction of 15 faulty runs failed (mean over the 20 baselines), at 95 % / 99 % / 1 std:

    fault                       robot's duration  mission_duration  robot's distance  any performance clause
    overspeed:tiago1            1.00/1.00/1.00    0.08/0.00/0.62    0.92/0.89/1.00    1.00/1.00/1.00
    slow:tiago1                 1.00/1.00/1.00    1.00/1.00/1.00    0.49/0.16/1.00    1.00/1.00/1.00
    skip-waypoint:tiago1        1.00/1.00/1.00    0.53/0.22/0.81    1.00/1.00/1.00    1.00/1.00/1.00
    near-collision (tiago2)     1.00/0.93/1.00    1.00/0.93/1.00    1.00/1.00/1.00    1.00/1.00/1.00
    detour:c022:c018            1.00/1.00/1.00    1.00/1.00/1.00    1.00/1.00/1.00    1.00/1.00/1.00
    slow-area:classroom_c018    1.00/1.00/1.00    1.00/1.00/1.00    0.06/0.00/0.45    1.00/1.00/1.00

Every fault is caught by some performance clause in every run at 99 % too (skip-waypoint also by
waypoints_visited; overspeed and near-collision by their safety clauses), at 1.4 % of healthy runs
failing some performance clause instead of 89 % with one standard deviation.  The distance band is
a few millimetres (the executor drives the same grid path every run), so distance_travelled flags
any change of path, even the other robot's (tiago2's distance fails under overspeed:tiago1).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import tempfile
import time
from collections import Counter, defaultdict
from dataclasses import dataclass, field, replace
from pathlib import Path

from scipy import stats

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.acceptance import Acceptance, BasicRelation, Quantity
from exsce_dsl.model.verdicts import Outcome
from exsce_dsl.oracles.baseline import baseline_oracles
from exsce_dsl.oracles.verify import judge_runs
from exsce_dsl.prov.oracle import compile_oracles
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.faults import FAULT_KINDS, Fault
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.writing import add_prov

SPEC = Path(__file__).resolve().parent.parent / "examples" / "brsu_building_c" / "scenario_c.exsce"
FAULTS = (
    "overspeed:tiago1",
    "slow:tiago1",
    "skip-waypoint:tiago1",
    "near-collision",
    "detour:classroom_c022:classroom_c018",
    "slow-area:classroom_c018",
)
"""The faults planted, each one that shows in scenario_c's own runs: every plain fault of
exsce_dsl.sim.faults, and the latent ones whose trigger scenario_c has (its robots drive
classroom_c022 → classroom_c018)."""
MANIFEST = "runs.json"


def fill(
    store: EmbeddedStore, scenario: Scenario, folder: Path, runs: int, faulty: int, jobs: int
) -> dict[str, list[str]]:
    """Simulate and ingest the runs once: ``runs`` fault-free ones and ``faulty`` of each fault;
    the run uuids by group (``""`` for the fault-free runs) are kept next to the store."""
    manifest = folder / MANIFEST
    groups: dict[str, list[str]] = json.loads(manifest.read_text()) if manifest.exists() else {}
    wanted = {"": runs, **{fault: faulty for fault in FAULTS}}
    for seed, (group, count) in enumerate(wanted.items()):
        have = groups.get(group, [])
        if len(have) >= count:
            continue
        faults = (Fault.parse(group),) if group else ()
        started = time.perf_counter()
        out = folder / "bags" / (group.replace(":", "_") or "fault-free")
        bags = [r.bag for r in simulate(scenario, out, count, seed=1 + 10_000 * seed, faults=faults)]
        simulated = time.perf_counter() - started
        results = ingest_bags(bags, scenario, store, jobs=jobs)
        failed = [r for r in results if r.failed]
        assert not failed, failed[0].message
        groups[group] = [r.run_id for r in results if r.run_id is not None]
        manifest.write_text(json.dumps(groups, indent=1))
        print(
            f"{group or 'fault-free'}: {count} runs simulated in {simulated:.0f} s, "
            f"ingested in {time.perf_counter() - started - simulated:.0f} s",
            flush=True,
        )
    return groups


SETTINGS: dict[str, Quantity | None] = {
    "95 %": Quantity(95.0, "%", "95"),
    "99 %": Quantity(99.0, "%", "99"),
    "1 std": None,
}
"""How the performance clauses are judged: at a confidence, or the method's default (one std)."""


def judged_as(acceptance: Acceptance, confidence: Quantity | None) -> Acceptance:
    """scenario_c's criteria with every performance clause (an ``invariant`` around the baseline's
    mean) at ``confidence``, or with the method's default tolerance (None)."""
    criteria = []
    for criterion in acceptance.criteria:
        clauses = tuple(
            replace(e, tolerance=None, confidence=confidence)
            if e.relation is BasicRelation.INVARIANT and e.value is None and e.against is None
            else e
            for e in criterion.expectations
        )
        criteria.append(replace(criterion, expectations=clauses))
    return replace(acceptance, criteria=tuple(criteria))


ANY_PERFORMANCE, ANY = "any performance clause", "any clause"
"""Runs that failed at least one performance oracle / at least one oracle of scenario_c."""


def promised(setting: str, n: int) -> float:
    """The false-failure rate a setting promises for normal values and a baseline of n runs."""
    confidence = SETTINGS[setting]
    if confidence is not None:
        return 1.0 - confidence.value / 100.0
    # |x − mean| > σ_pop, σ_pop = s·√((n−1)/n), and (x − mean)/(s·√(1+1/n)) is t with n − 1 df
    return 2.0 * float(stats.t.sf(math.sqrt((n - 1) / (n + 1)), n - 1))


@dataclass
class Tally:
    """Failures of one oracle, per baseline (block) and in all."""

    failed: list[int] = field(default_factory=list)
    judged: list[int] = field(default_factory=list)
    inconclusive: int = 0
    widths: list[float] = field(default_factory=list)
    """The oracle's tolerance (the band's half-width) from each baseline."""

    @property
    def rate(self) -> float:
        return sum(self.failed) / max(1, sum(self.judged))

    def standard_error(self) -> float:
        """Of the mean rate over the baselines (each baseline's rate one observation)."""
        rates = [f / j for f, j in zip(self.failed, self.judged, strict=True) if j]
        return statistics.stdev(rates) / math.sqrt(len(rates)) if len(rates) > 1 else math.nan


def measure(
    store: EmbeddedStore, acceptance: Acceptance, scenario: Scenario, groups: dict[str, list[str]], n: int
) -> tuple[dict[tuple[str, str, str], Tally], list[str], dict[str, dict[str, float]]]:
    """(setting, group, oracle) → its tally over the rotated baselines; the performance oracles; and
    each oracle's value in each fault-free run."""
    clean = groups[""]
    blocks = [clean[i : i + n] for i in range(0, len(clean) - n + 1, n)]
    tallies: dict[tuple[str, str, str], Tally] = defaultdict(Tally)
    performance: list[str] = []
    observed: dict[str, dict[str, float]] = defaultdict(dict)
    for setting, confidence in SETTINGS.items():
        criteria = judged_as(acceptance, confidence)
        started = time.perf_counter()
        for block in blocks:
            oracles = baseline_oracles(store, criteria, scenario, runs=block)
            if not performance:
                performance = [o.name for o in oracles if o.relation == "invariant"]
            add_prov(store, compile_oracles(scenario.id, oracles), replace=True)
            for oracle in oracles:
                tallies[setting, "", oracle.name].widths.append(oracle.tolerance or 0.0)
            inside = set(block)
            judged = {group: [r for r in runs if r not in inside] for group, runs in groups.items()}
            verdicts = judge_runs(store, [r for runs in judged.values() for r in runs], scenario)
            group_of = {run: group for group, runs in judged.items() for run in runs}
            counts: Counter[tuple[str, str, Outcome]] = Counter(
                (group_of[v.run], v.oracle, v.outcome) for v in verdicts
            )
            failing: dict[str, set[str]] = defaultdict(set)
            for v in verdicts:
                if v.observed is not None and group_of[v.run] == "":
                    observed[v.oracle][v.run] = v.observed
                if v.outcome is Outcome.FAILED:
                    failing[v.run].add(v.oracle)
            for group, runs in judged.items():
                for name, chosen in ((ANY_PERFORMANCE, set(performance)), (ANY, None)):
                    tally = tallies[setting, group, name]
                    tally.failed.append(sum(1 for r in runs if failing[r] & (chosen or failing[r])))
                    tally.judged.append(len(runs))
                for oracle in {v.oracle for v in verdicts}:
                    tally = tallies[setting, group, oracle]
                    tally.failed.append(counts[group, oracle, Outcome.FAILED])
                    tally.judged.append(len(runs) - counts[group, oracle, Outcome.INCONCLUSIVE])
                    tally.inconclusive += counts[group, oracle, Outcome.INCONCLUSIVE]
        print(
            f"{setting}: {len(blocks)} baselines of {n} runs built and their runs judged "
            f"in {time.perf_counter() - started:.0f} s",
            flush=True,
        )
    return tallies, performance, observed


def false_failures(tallies: dict[tuple[str, str, str], Tally], performance: list[str], n: int) -> None:
    print(f"\nFalse failures of fault-free runs (baselines of {n} runs, every other fault-free run judged)")
    header = (
        f"{'oracle':<28} {'setting':<7} {'± mean':>8} {'failed/judged':>14} {'rate':>7} {'1−c':>7} "
        f"{'binomial 95 % band':>19} {'in':>3} {'rate ± 1.96 se (baselines)':>27} {'in':>3}"
    )
    print(header)
    print("-" * len(header))
    for oracle in performance:
        for setting in SETTINGS:
            tally = tallies[setting, "", oracle]
            judged, failed = sum(tally.judged), sum(tally.failed)
            expected = promised(setting, n)
            low, high = (stats.binom.ppf(q, judged, expected) / judged for q in (0.025, 0.975))
            se = tally.standard_error()
            near = (tally.rate - 1.96 * se, tally.rate + 1.96 * se)
            print(
                f"{oracle:<28} {setting:<7} {statistics.fmean(tally.widths):>8.3g} "
                f"{f'{failed}/{judged}':>14} {tally.rate:>7.3f} {expected:>7.3f} "
                f"{f'[{low:.3f}, {high:.3f}]':>19} {'yes' if low <= tally.rate <= high else 'NO':>3} "
                f"{f'[{near[0]:.3f}, {near[1]:.3f}]':>27} "
                f"{'yes' if near[0] <= expected <= near[1] else 'NO':>3}"
                + (f"  ({tally.inconclusive} inconclusive)" if tally.inconclusive else "")
            )


def shapes(observed: dict[str, dict[str, float]], performance: list[str]) -> None:
    """How far from normal each performance metric's fault-free values are: a prediction interval
    promises 1 − c for normal values only (light tails fail less, heavy tails more)."""
    print("\nThe fault-free values (all runs): how normal they are")
    print(
        f"{'oracle':<28} {'distinct':>8} {'mean':>10} {'std':>9} {'skew':>6} "
        f"{'excess kurtosis':>16} {'Shapiro p':>10}"
    )
    for oracle in performance:
        values = list(observed[oracle].values())
        distinct = len(set(values))
        spread = statistics.stdev(values) if len(values) > 1 else 0.0
        if distinct < 3 or spread == 0:
            print(
                f"{oracle:<28} {distinct:>8} {statistics.fmean(values):>10.4g} {spread:>9.3g}  "
                "(no spread to speak of)"
            )
            continue
        print(
            f"{oracle:<28} {distinct:>8} {statistics.fmean(values):>10.4g} {spread:>9.3g} "
            f"{float(stats.skew(values)):>6.2f} {float(stats.kurtosis(values)):>16.2f} "
            f"{float(stats.shapiro(values).pvalue):>10.2g}"
        )


def runs_failed(tallies: dict[tuple[str, str, str], Tally]) -> None:
    print("\nFault-free runs that failed ...")
    for name in (ANY_PERFORMANCE, ANY):
        print(f"  {name + ':':<24} " + "  ".join(f"{s} {tallies[s, '', name].rate:.3f}" for s in SETTINGS))


def detections(
    tallies: dict[tuple[str, str, str], Tally], performance: list[str], groups: dict[str, list[str]]
) -> None:
    print("\nDetection: fraction of faulty runs each oracle failed, judged against fault-free baselines")
    for group in groups:
        if not group:
            continue
        print(f"\n{group} ({len(groups[group])} runs; {FAULT_KINDS[Fault.parse(group).kind].summary})")
        names = sorted({o for (s, g, o) in tallies if g == group})
        caught = [
            o
            for o in names
            if o not in [*performance, ANY_PERFORMANCE, ANY]
            and any(tallies[s, group, o].rate > 0 for s in SETTINGS)
        ]
        shown = performance + caught + [ANY_PERFORMANCE, ANY]
        print(f"{'oracle':<40} " + " ".join(f"{s:>7}" for s in SETTINGS))
        for oracle in shown:
            print(f"{oracle:<40} " + " ".join(f"{tallies[s, group, oracle].rate:>7.3f}" for s in SETTINGS))


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="40 fault-free runs and 10 of each fault")
    parser.add_argument("--runs", type=int, default=200, help="fault-free runs (default 200)")
    parser.add_argument("--faulty-runs", type=int, default=30, help="runs of each fault (default 30)")
    parser.add_argument("--baseline-runs", type=int, default=10, help="runs in each baseline (default 10)")
    parser.add_argument("--jobs", type=int, default=1, help="ingest worker processes (default 1)")
    parser.add_argument("--store", type=Path, help="keep the runs in this folder (filled once, reused after)")
    parser.add_argument("--fill-only", action="store_true", help="simulate and ingest, measure nothing")
    options = parser.parse_args()
    runs, faulty = (40, 10) if options.quick else (options.runs, options.faulty_runs)
    spec = load_spec(SPEC)
    scenario = spec.scenario("scenario_c")
    acceptance = spec.acceptance_of("scenario_c")
    assert acceptance is not None
    with tempfile.TemporaryDirectory(prefix="exsce-oracles-") as scratch:
        folder = options.store or Path(scratch)
        folder.mkdir(parents=True, exist_ok=True)
        store = EmbeddedStore(folder / "store")
        groups = fill(store, scenario, folder, runs, faulty, options.jobs)
        groups = {group: groups[group][: runs if not group else faulty] for group in ["", *FAULTS]}
        print(f"fault-free runs: {len(groups[''])}; faulty runs: {faulty} of each of {len(FAULTS)} faults")
        if not options.fill_only:
            tallies, performance, observed = measure(
                store, acceptance, scenario, groups, options.baseline_runs
            )
            false_failures(tallies, performance, options.baseline_runs)
            runs_failed(tallies)
            shapes(observed, performance)
            detections(tallies, performance, groups)
        store.close()


if __name__ == "__main__":
    main()
