"""Statistical verdicts over repeated runs: pass rates, Wilson intervals, passed/failed/flaky.

A clause of a trial passed in ``k`` of its ``n`` judged runs (inconclusive runs are counted
apart and left out of the rate).  Its pass rate ``k/n`` gets the Wilson score interval at the
``confidence`` asked for, with ``z`` the standard normal quantile ``1 - (1 - confidence) / 2``::

    centre = (p + z²/2n) / (1 + z²/n)
    half   = z / (1 + z²/n) · sqrt(p(1 - p)/n + z²/4n²)

(Wilson, 1927; unlike the normal-approximation interval it stays inside [0, 1] and does not
collapse to a point when every run passed.)  The clause then

- **passed** when the interval's lower bound reaches the required pass rate,
- **failed** when its upper bound is below it,
- **flaky** when it straddles it and runs both passed and failed,
- **inconclusive** when it straddles it with only passes (or only failures): too few runs, and
  the reason says how many agreeing runs would settle it; or when no run could be judged.

The default required pass rate, :data:`REQUIRED_PASS_RATE`, is 0.8: a clause should hold in at
least four runs of five on a healthy system.  At 95 % confidence 16 runs that all pass show it
(the lower bound of 16 of 16 is 0.806): a trial one can afford on the simulator (a few seconds a run)
and overnight on a robot, where 0.9 would need 35 and 0.95 would need 73.  It also flags the
method's one-standard-deviation tolerance, which a fault-free run meets about 68 % of the time.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from statistics import NormalDist

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.trials import ClauseKey, ClauseTrial, Trial, TrialOutcome
from exsce_dsl.model.verdicts import Outcome, Verdict

REQUIRED_PASS_RATE = 0.8
"""The pass rate a clause must be shown to reach, by default (see the module's docstring)."""
CONFIDENCE = 0.95
"""The confidence of the Wilson interval, by default."""


def check_rates(required_pass_rate: float, confidence: float) -> None:
    if not 0 < required_pass_rate < 1:
        raise ExsceError(
            f"a required pass rate is between 0 and 1 (not {required_pass_rate:g}): "
            "no finite trial can show a rate of 1, and any shows 0"
        )
    if not 0 < confidence < 1:
        raise ExsceError(f"a confidence is between 0 and 1, such as 0.95 (not {confidence:g})")


def percent(confidence: float) -> str:
    """``95 %``, ``99.5 %``: a confidence as the tables and reasons print it."""
    return f"{confidence * 100:.4g} %"


def _z(confidence: float) -> float:
    return NormalDist().inv_cdf(1 - (1 - confidence) / 2)


def wilson_interval(passed: int, judged: int, confidence: float = CONFIDENCE) -> tuple[float, float]:
    """The Wilson score interval of the pass rate ``passed / judged`` at ``confidence``."""
    if judged <= 0 or not 0 <= passed <= judged:
        raise ValueError(f"no pass rate of {passed} in {judged} runs")
    z = _z(confidence)
    p = passed / judged
    spread = z * z / judged
    centre = (p + spread / 2) / (1 + spread)
    half = z / (1 + spread) * math.sqrt(p * (1 - p) / judged + spread / (4 * judged))
    return max(0.0, centre - half), min(1.0, centre + half)


def runs_to_pass(required_pass_rate: float, confidence: float = CONFIDENCE) -> int:
    """How many runs, all passing, show a pass rate of at least ``required_pass_rate``: the
    smallest ``n`` with ``n / (n + z²)`` (the Wilson lower bound of n of n) reaching it."""
    check_rates(required_pass_rate, confidence)
    z2 = _z(confidence) ** 2
    n = max(1, math.ceil(required_pass_rate * z2 / (1 - required_pass_rate)) - 1)
    while wilson_interval(n, n, confidence)[0] < required_pass_rate:
        n += 1
    return n


def runs_to_fail(required_pass_rate: float, confidence: float = CONFIDENCE) -> int:
    """How many runs, all failing, show a pass rate below ``required_pass_rate``: the smallest
    ``n`` with ``z² / (n + z²)`` (the Wilson upper bound of 0 of n) below it."""
    check_rates(required_pass_rate, confidence)
    z2 = _z(confidence) ** 2
    n = max(1, math.floor(z2 * (1 - required_pass_rate) / required_pass_rate))
    while wilson_interval(0, n, confidence)[1] >= required_pass_rate:
        n += 1
    return n


def clause_trial(
    verdicts: Sequence[Verdict],
    required_pass_rate: float = REQUIRED_PASS_RATE,
    confidence: float = CONFIDENCE,
) -> ClauseTrial:
    """The statistics of one clause from its verdicts, one per run (all of one :class:`ClauseKey`)."""
    check_rates(required_pass_rate, confidence)
    if not verdicts:
        raise ValueError("a clause of a trial needs at least one verdict")
    first = verdicts[0]
    passed = sum(v.outcome is Outcome.PASSED for v in verdicts)
    failed = sum(v.outcome is Outcome.FAILED for v in verdicts)
    inconclusive = len(verdicts) - passed - failed
    low = high = None
    if passed + failed:
        low, high = wilson_interval(passed, passed + failed, confidence)
    outcome, reason, needed = _judge(passed, failed, low, high, required_pass_rate, confidence)
    if outcome is TrialOutcome.INCONCLUSIVE and not passed + failed:
        reasons = dict.fromkeys(v.reason for v in verdicts if v.reason)
        reason += f" ({'; '.join(reasons)})" if reasons else ""
    return ClauseTrial(
        key=ClauseKey.of(first),
        metric=first.metric,
        robot=first.robot,
        criterion=first.criterion,
        passed=passed,
        failed=failed,
        inconclusive=inconclusive,
        low=low,
        high=high,
        outcome=outcome,
        reason=reason,
        required_pass_rate=required_pass_rate,
        confidence=confidence,
        runs=tuple(dict.fromkeys(v.run for v in verdicts)),
        runs_needed=needed,
    )


def _judge(
    passed: int, failed: int, low: float | None, high: float | None, required: float, confidence: float
) -> tuple[TrialOutcome, str, int | None]:
    """The outcome of a clause's counts and interval, the sentence that says why, and how many
    agreeing runs would settle a clause inconclusive for too few runs."""
    if low is None or high is None:
        return TrialOutcome.INCONCLUSIVE, "no run could be judged", None
    judged = passed + failed
    interval = f"{percent(confidence)} interval [{low:.2f}, {high:.2f}]"
    counts = f"{passed} of {judged} judged {'run' if judged == 1 else 'runs'} passed, {interval}"
    if low >= required:
        return TrialOutcome.PASSED, f"{counts}: at least the required {required:g}", None
    if high < required:
        return TrialOutcome.FAILED, f"{counts}: below the required {required:g}", None
    if passed and failed:
        return TrialOutcome.FLAKY, f"{counts} straddles the required {required:g}: flaky", None
    if passed:
        needed = runs_to_pass(required, confidence)
        said = f"{needed} passing runs show a pass rate of {required:g} at {percent(confidence)}"
        return TrialOutcome.INCONCLUSIVE, f"too few runs: {counts}; {said}", needed
    needed = runs_to_fail(required, confidence)
    said = f"{needed} failing runs show a pass rate below {required:g} at {percent(confidence)}"
    return TrialOutcome.INCONCLUSIVE, f"too few runs: {counts}; {said}", needed


def clause_trials(
    verdicts: Iterable[Verdict],
    required_pass_rate: float = REQUIRED_PASS_RATE,
    confidence: float = CONFIDENCE,
) -> list[ClauseTrial]:
    """Each clause's statistics over ``verdicts`` (of any runs; grouped by :class:`ClauseKey`), in
    the order the clauses first appear."""
    groups: dict[ClauseKey, list[Verdict]] = {}
    for verdict in verdicts:
        groups.setdefault(ClauseKey.of(verdict), []).append(verdict)
    return [clause_trial(group, required_pass_rate, confidence) for group in groups.values()]


def trial(
    scenario: str,
    runs: Sequence[str],
    verdicts: Sequence[Verdict],
    required_pass_rate: float = REQUIRED_PASS_RATE,
    confidence: float = CONFIDENCE,
    warnings: Sequence[str] = (),
) -> Trial:
    """The trial of ``runs`` of ``scenario`` from their verdicts."""
    clauses = clause_trials(verdicts, required_pass_rate, confidence)
    return Trial(
        scenario,
        tuple(runs),
        tuple(verdicts),
        tuple(clauses),
        required_pass_rate,
        confidence,
        tuple(warnings),
    )


def lowest_pass_rate_first(clauses: Iterable[ClauseTrial]) -> list[ClauseTrial]:
    """``clauses`` by pass rate, lowest first (then by the interval's upper bound, and its lower:
    of equal rates, the surer failure and the less sure pass first); those no run judged last."""
    return sorted(clauses, key=_by_rate)


def _by_rate(c: ClauseTrial) -> tuple[bool, float, float, float, str, str]:
    rate, high, low = c.pass_rate or 0.0, c.high or 0.0, c.low or 0.0
    return (c.pass_rate is None, rate, high, low, c.key.scenario, c.description)
