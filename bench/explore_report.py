"""The exploration benchmark's report (bench/explore.py): per fault, campaign beside baseline
seed by seed, the figures falsification tools report, the targets met; the false alarms."""

from __future__ import annotations

import math
import statistics
from collections import Counter
from collections.abc import Sequence
from typing import TYPE_CHECKING

from exsce_dsl.explore.figures import first_failure, per_100
from exsce_dsl.model.campaign import Request

if TYPE_CHECKING:
    from explore import Outcome

FOUND_SHARE = 0.8
"""Target: found in at least this share of the seeds (4 of 5)."""
MAX_SHRUNK = 2
"""Target: a found fault's minimal derivation has at most this many steps."""


def steps_text(steps: Sequence[Request]) -> str:
    return (
        " + ".join(f"{name}({', '.join(f'{k}={v}' for k, v in args.items())})" for name, args in steps) or "-"
    )


def progress(outcome: Outcome) -> str:
    unit = outcome.unit
    where = f"{unit.kind:8} seed {unit.seed} {unit.fault or 'no fault'}"
    if unit.kind == "clean":
        said = f"{outcome.violating_trials}/{outcome.trials} trials violated"
    elif not outcome.violated:
        said = "no violation"
    else:
        said = (
            f"violation after {outcome.to_first_violation} runs: {'; '.join(outcome.violated)}; "
            f"caused by the fault: {'; '.join(outcome.caused) or 'none'}"
            f"; not: {'; '.join(outcome.not_caused) or '-'}"
        )
        if unit.kind == "campaign" and outcome.minimal:
            said += f"; minimal: {steps_text(outcome.minimal)}"
    checked = f" + {outcome.fault_free_runs} fault-free" if outcome.fault_free_runs else ""
    rate = ""
    if outcome.figures is not None:
        f = outcome.figures
        rate = f"; {f.counterexamples} counterexamples in {f.executions} executions"
    return f"  {where}: {said}{rate} ({outcome.executions}{checked} runs, {outcome.seconds:.0f} s)"


def executions(outcome: Outcome, never: int) -> int:
    return outcome.to_detection if outcome.to_detection is not None else never


def cell(outcome: Outcome) -> str:
    if outcome.to_detection is not None:
        return str(outcome.to_detection)
    if outcome.violated:
        return "never*"
    return "never"


def report_fault(
    fault: str,
    revealed_by: str,
    campaigns: list[Outcome],
    baselines: list[Outcome],
    alarm_rate: float,
    never: int,
    seeds: int,
) -> list[tuple[str, bool]]:
    """One fault's table (campaign beside baseline, per seed), its figures and its targets met."""
    print(f"\n{fault}  [revealed by: {revealed_by}]")
    print(
        "  seed  campaign: found  to detection  shrunk steps  shrink runs  all runs"
        "  | baseline: detected  to detection  all runs"
    )
    by_seed = {o.unit.seed: o for o in baselines}
    for c in sorted(campaigns, key=lambda o: o.unit.seed):
        b = by_seed.get(c.unit.seed)
        shrunk = "-" if c.shrunk_steps is None else str(c.shrunk_steps)
        shrink_runs = f"{c.shrink_executions_caused if c.shrink_executions_caused is not None else '-'}"
        shrink_runs += f" ({c.shrink_executions})"
        row = (
            f"  {c.unit.seed:>4}  {'yes' if c.detected else 'no':>15}  {cell(c):>12}  {shrunk:>12}"
            f"  {shrink_runs:>11}  {c.executions:>8}"
        )
        if b is not None:
            row += f"  | {'yes' if b.detected else 'no':>18}  {cell(b):>12}  {b.executions:>8}"
        print(row)
    found = sum(c.detected for c in campaigns)
    median_campaign = statistics.median(executions(c, never) for c in campaigns)
    median_baseline = statistics.median(executions(b, never) for b in baselines) if baselines else math.nan
    sizes = [c.shrunk_steps for c in campaigns if c.shrunk_steps is not None]
    baseline_found = sum(b.detected for b in baselines)
    print(f"  found: campaign {found}/{len(campaigns)} seeds, baseline {baseline_found}/{len(baselines)}")
    ratio = median_baseline / median_campaign if median_campaign else math.nan
    print(
        f"  median executions to detection: campaign {median_campaign:g}, baseline {median_baseline:g}"
        f" (baseline / campaign: {ratio:.2f}×; never = {never})"
    )
    print(f"  median shrunk size: {statistics.median(sizes):g} steps" if sizes else "  median shrunk size: -")
    print(f"  false-alarm rate (fault-free campaigns, all seeds): {alarm_rate:.1%}")
    need = math.ceil(FOUND_SHARE * seeds)
    targets = [
        (f"found in ≥ {need}/{seeds} seeds", found >= need),
        (f"shrunk to ≤ {MAX_SHRUNK} steps whenever found", bool(sizes) and max(sizes) <= MAX_SHRUNK),
        ("fewer executions to detection than the baseline (medians)", median_campaign < median_baseline),
        ("false-alarm rate 0", alarm_rate == 0),
    ]
    report_rates(campaigns, baselines, never)
    for text, met in targets:
        print(f"  {'PASS' if met else 'FAIL'}  {text}")
    runs_per_derivation = min((c.unit.runs for c in campaigns), default=0)
    if baselines and median_baseline <= runs_per_derivation < median_campaign:
        print(
            f"        (the baseline's median, {median_baseline:g}, is its first derivation's runs: "
            "no campaign can take fewer, only as few)"
        )
    return targets


def rate_cells(outcome: Outcome | None) -> str:
    """Executions, counterexamples, per 100 executions, executions to the first failure."""
    if outcome is None or outcome.figures is None:
        return f"{'-':>10}  {'-':>15}  {'-':>7}  {'-':>13}"
    f = outcome.figures
    return f"{f.executions:>10}  {f.counterexamples:>15}  {per_100(f):>7}  {first_failure(f):>13}"


def pooled(outcomes: Sequence[Outcome], never: int) -> str:
    """The cells of all seeds: counterexamples per 100 executions over all of them, and the
    median executions to the first failure (a campaign with none counts as ``never``)."""
    figures = [o.figures for o in outcomes if o.figures is not None]
    executions = sum(f.executions for f in figures)
    found = sum(f.counterexamples for f in figures)
    rate = f"{100 * found / executions:.1f}" if executions else "-"
    firsts = [f.executions_to_first_failure or never for f in figures]
    median = f"{statistics.median(firsts):g}" if firsts else "-"
    return f"{executions:>10}  {found:>15}  {rate:>7}  {median:>13}"


def report_rates(campaigns: list[Outcome], baselines: list[Outcome], never: int) -> None:
    """Counterexamples per 100 executions and executions to the first failure (whichever
    relation failed, the fault's or not), campaign and baseline side by side."""
    head = f"{'executions':>10}  {'counterexamples':>15}  {'per 100':>7}  {'first failure':>13}"
    print(f"  seed  campaign: {head}  | baseline: {head}")
    by_seed = {o.unit.seed: o for o in baselines}
    for c in sorted(campaigns, key=lambda o: o.unit.seed):
        baseline = rate_cells(by_seed.get(c.unit.seed))
        print(f"  {c.unit.seed:>4}            {rate_cells(c)}  |           {baseline}")
    print(f"  {'all':>4}            {pooled(campaigns, never)}  |           {pooled(baselines, never)}")


def report_alarms(cleans: list[Outcome]) -> float:
    trials = sum(o.trials for o in cleans)
    violating = sum(o.violating_trials for o in cleans)
    rate = violating / trials if trials else 0.0
    print(
        f"\nfalse alarms (no fault; covering, relations, whole budget): "
        f"{violating}/{trials} trials = {rate:.1%}"
    )
    for o in sorted(cleans, key=lambda o: o.unit.seed):
        print(f"  seed {o.unit.seed}: {o.violating_trials}/{o.trials} trials violated")
    figures = [o.figures for o in cleans if o.figures is not None]
    executions = sum(f.executions for f in figures)
    if executions:
        found = sum(f.counterexamples for f in figures)
        print(f"  counterexamples per 100 executions without a fault: {100 * found / executions:.1f}")
    relations: Counter[str] = Counter()
    for o in cleans:
        relations.update(o.false_alarms)
    if relations:
        print("  relations violated (violating trials):")
        for text, count in relations.most_common():
            print(f"    {count:>3}  {text}")
        print("  the violating derivations:")
        for o in sorted(cleans, key=lambda o: o.unit.seed):
            for steps in o.alarm_steps:
                print(f"    seed {o.unit.seed}: {steps_text(steps)}")
    return rate
