"""Coverage of a verdict: whether the recording covers the part of the run a clause looks at.

A verdict computed over data the recording does not cover claims more than it saw.  Ingestion
finds what a run's recording lacks (:class:`~exsce_dsl.model.coverage.CoverageGap`); here each
verdict meets the gaps that concern it, and the rules below decide what it still says:

* A gap concerns a clause when it touches the clause's metric and robot
  (:meth:`CoverageGap.concerns`) and overlaps the part of the run the clause looks at: the whole
  run for a clause without a window, the time of its path segments for a windowed one
  (``during delivery_a``, ``before tiago1 reaches P``).  A run cut short concerns every clause,
  whatever its window: what the run would have done next is not known.
* A clause nothing concerns keeps its verdict.
* A limit (``below_max``, ``above_min``) broken in what was recorded stays **failed** when more
  data could not have mended it: a maximum or a sum only grows with more data, a minimum only
  falls.  Any other verdict a gap concerns is **inconclusive** (never passed): a limit met in what
  was recorded may be broken in what was not, and a performance value computed over part of the
  data is not the run's.
* A topic recorded below :data:`LOW_RATE_FRACTION` of the median rate of the same topic in the
  runs the clause's expectation came from (a limit's: the runs of its scenario's baseline) is a
  gap too
  (:func:`learned_rate_gaps`), when ingestion did not already find it thinned against a rate the
  specification declares.
"""

from __future__ import annotations

import datetime
import statistics
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace

from exsce_dsl.model.coverage import CoverageGap, Shortfall, TopicRate
from exsce_dsl.model.metrics import Combine
from exsce_dsl.model.verdicts import Outcome, Verdict

__all__ = [
    "LIMIT_RELATIONS",
    "LOW_RATE_FRACTION",
    "Span",
    "clause_gaps",
    "judge_coverage",
    "learned_rate_gaps",
]

LOW_RATE_FRACTION = 0.5
"""A topic recorded at less than this fraction of the median rate of its baseline's runs makes the
clauses reading it inconclusive (half: a scan at 4 Hz where the baseline's ran at 10 Hz)."""

LIMIT_RELATIONS = frozenset({"below_max", "above_min"})
"""The safety clauses' relations (``stays below``, ``stays above``)."""

_SHOWN = 3
"""How many shortfalls a reason names before it counts the rest."""


@dataclass(frozen=True)
class Span:
    """The part of a run's timeline a clause looks at; None leaves that side open (the whole run)."""

    start: datetime.datetime | None = None
    end: datetime.datetime | None = None

    def overlaps(self, gap: CoverageGap) -> bool:
        """Whether ``gap`` lies (partly) inside this span; touching at one instant is not overlapping."""
        before = gap.end is not None and self.start is not None and gap.end <= self.start
        after = gap.start is not None and self.end is not None and gap.start >= self.end
        return not (before or after)


def clause_gaps(verdict: Verdict, gaps: Iterable[CoverageGap], span: Span) -> list[CoverageGap]:
    """The gaps that concern ``verdict``'s clause: its metric and robot, inside ``span`` (a run cut
    short concerns every part of it)."""
    return [
        gap
        for gap in gaps
        if gap.concerns(verdict.metric, verdict.robot)
        and (gap.kind is Shortfall.CUT_SHORT or span.overlaps(gap))
    ]


def learned_rate_gaps(
    verdict: Verdict,
    topics: Sequence[str],
    rates: Mapping[str, Sequence[TopicRate]],
    baseline: Sequence[str],
    fraction: float = LOW_RATE_FRACTION,
) -> list[CoverageGap]:
    """A ``low_rate`` gap for each topic ``verdict``'s clause reads that its run recorded below
    ``fraction`` of the median rate of the same topic in the ``baseline`` runs (uuids; the run
    itself left out): those its expectation came from, or for a limit, which comes from no run,
    those of its scenario's baseline.

    ``rates`` are run uuid → the rates of its topics; a topic's rate concerns the clause when it
    names the clause's metric (or, naming none, is one of ``topics``, the oracle's) and robot.
    A topic no baseline run recorded is not compared."""
    baseline = [run for run in dict.fromkeys(baseline) if run != verdict.run and run in rates]
    found = []
    for own in rates.get(verdict.run, ()):
        if not _reads(own, verdict, topics):
            continue
        theirs = [r.rate for run in baseline for r in rates[run] if r.topic == own.topic]
        if not theirs:
            continue
        median = statistics.median(theirs)
        if own.rate < fraction * median:
            reason = (
                f"{own.topic} recorded at {_hz(own.rate)} Hz, the baseline's runs at {_hz(median)} Hz "
                f"(median of {len(theirs)}): below {fraction:.0%} of theirs"
            )
            found.append(CoverageGap(Shortfall.LOW_RATE, reason, own.robot, own.topic, own.metrics))
    return found


def judge_coverage(verdict: Verdict, gaps: Sequence[CoverageGap], accumulates: Combine | None) -> Verdict:
    """``verdict`` as the gaps that concern it leave it (see the module's rules).

    ``accumulates`` says how the clause's metric grows with more data: ``MAX`` or ``SUM`` only up,
    ``MIN`` only down, None not known (then a broken limit is inconclusive too)."""
    if not gaps:
        return verdict
    kinds = tuple(dict.fromkeys(gap.kind for gap in gaps))
    said = _shortfalls_text(gaps)
    if verdict.outcome is Outcome.INCONCLUSIVE:
        reason = f"{verdict.reason}; {said}" if verdict.reason else said
        return replace(verdict, reason=reason, shortfalls=kinds)
    if verdict.outcome is Outcome.FAILED and _broken_for_good(verdict.relation, accumulates):
        return replace(verdict, reason=f"{verdict.reason} in what was recorded ({said})", shortfalls=kinds)
    if verdict.relation in LIMIT_RELATIONS:
        held = "held" if verdict.outcome is Outcome.PASSED else "was broken"
        why = f"the limit {held} in what was recorded, which does not show the rest"
    else:
        shown = f"{verdict.observed:g}" if verdict.observed is not None else "the value"
        why = f"{shown} is not the whole run's value"
    return replace(
        verdict, outcome=Outcome.INCONCLUSIVE, reason=f"{said}: {why}", margin=None, shortfalls=kinds
    )


def _broken_for_good(relation: str, accumulates: Combine | None) -> bool:
    """Whether a limit broken in part of the data is broken in all of it."""
    if relation == "below_max":
        return accumulates in (Combine.MAX, Combine.SUM)
    if relation == "above_min":
        return accumulates is Combine.MIN
    return False


def _reads(rate: TopicRate, verdict: Verdict, topics: Sequence[str]) -> bool:
    metric = verdict.metric in rate.metrics if rate.metrics else rate.topic in topics
    return metric and (rate.robot is None or verdict.robot is None or rate.robot == verdict.robot)


def _shortfalls_text(gaps: Sequence[CoverageGap]) -> str:
    reasons = list(dict.fromkeys(gap.reason for gap in gaps))
    text = "; ".join(reasons[:_SHOWN])
    if len(reasons) > _SHOWN:
        text += f"; and {len(reasons) - _SHOWN} more"
    return text


def _hz(rate: float) -> str:
    return f"{rate:.1f}" if rate >= 1 else f"{rate:.2g}"
