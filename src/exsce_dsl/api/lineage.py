"""``exscec lineage RUN``: one stored run from dispatch to verdict.

The scenario and where it was derived from (every hop), the dispatcher's execution of the
mission (its run id, the goals it sent to each robot and their outcomes), the bag, each value
with what it used (its window and samples, as ``exscec explain`` shows them), the verdicts and
the baseline runs their expectations came from.  The run is given by its stored uuid (or a
prefix of it, or its IRI), or by the id the dispatcher gave it (what ``exscec simulate`` and
``execute`` print): both name the same run (:mod:`exsce_dsl.prov.run_execution`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from exsce_dsl.errors import AmbiguousRunError, Remedied, UnknownRunError
from exsce_dsl.model.derivation import Derivation, TransformationStep
from exsce_dsl.remedies import VERIFY_THE_RUN
from exsce_dsl.store import (
    RunChain,
    Store,
    ValueAccount,
    derivation_of,
    derived_scenarios,
    dispatched_runs,
    is_full_uuid,
    lineage,
    names_a_prefix,
    resolve_run,
    run_chain,
    scenario_ids,
    value_accounts,
)

__all__ = ["RunLineage", "ScenarioLineage", "lineage_of", "run_lineage"]


@dataclass(frozen=True)
class RunLineage:
    """A run's chain (:class:`~exsce_dsl.store.queries.RunChain`), its scenario's derivations
    (the scenario's own first) and what each value used."""

    chain: RunChain
    ancestry: tuple[Derivation, ...]
    accounts: tuple[ValueAccount, ...]

    def text(self, wording: Mapping[str, str] | None = None) -> str:
        """The chain for people, from the scenario to the baseline runs; a remedy in ``wording``
        (the command line's, ``cli.common.REMEDIES``) when given, else in words."""
        chain = self.chain
        lines = [f"run {chain.run}"]
        lines.append(f"scenario {chain.scenario or '(unknown)'}")
        for derivation in self.ancestry:
            steps = " → ".join(s.transformation for s in derivation.steps) or "derived"
            lines.append(f"  derived from {derivation.base} by {steps}")
        lines += _execution_lines(chain)
        lines.append(f"bag {chain.bag or '(none)'}" + (f"  {chain.bag_path}" if chain.bag_path else ""))
        lines += self._value_lines()
        judged = f"verdicts ({len(chain.verdicts)})"
        lines.append(judged if chain.verdicts else Remedied("verdicts: none", VERIFY_THE_RUN).said(wording))
        for verdict in chain.verdicts:
            observed = f" {verdict.observed:.6g}" if verdict.observed is not None else ""
            lines.append(f"  {verdict.outcome:<12} {verdict.oracle} {verdict.relation}{observed}")
        if chain.baselines:
            lines.append("baseline runs the verdicts used")
            lines += [f"  {run}" + (f"  {path}" if path else "") for run, path in chain.baselines]
        return "\n".join(lines)

    def _value_lines(self) -> list[str]:
        accounts = {(a.metric, a.robot, a.action, a.safety_metric): a for a in self.accounts}
        lines = [f"values ({len(self.chain.values)})"]
        for value in self.chain.values:
            whom = value.action or value.robot  # a segment's action names its robot
            unit = f" {value.unit}" if value.unit else ""
            of = f" of {whom}" if whom else ""
            safety = f" ({value.safety_metric})" if value.safety_metric else ""
            lines.append(f"  {value.metric}{safety}{of} = {value.value:.6g}{unit}")
            account = accounts.get((value.metric, value.robot, value.action, value.safety_metric))
            if account is not None and account.window is not None:
                lines.append(f"    window: {account.window_text()}")
                lines += [f"    {line}" for line in account.samples_text()]
        return lines


def _execution_lines(chain: RunChain) -> list[str]:
    execution = chain.execution
    if execution is None:
        return ["execution: no run-time PROV came with the bag"]
    said = f"execution {execution.run_id} (the dispatcher's run, from {execution.source})"
    if execution.mission_status:
        said += f"; mission {execution.mission_status}"
    lines = [said]
    if chain.simulator is not None:
        name, version, settings = chain.simulator
        lines.append(f"  played by {name} {version}" + (f" ({settings})" if settings else ""))
    for goal in chain.goals:
        outcome = f" ({goal.outcome})" if goal.outcome else ""
        attempts = f", {goal.attempts} attempts" if goal.attempts > 1 else ""
        lines.append(f"  goal {goal.name} → {goal.pose or '?'}: {goal.status}{outcome}{attempts}")
    return lines


def run_lineage(store: Store, run: str) -> RunLineage:
    """The chain of the stored run ``run``: its uuid, a unique prefix of it, its IRI, or the
    dispatcher's id of it (or a unique prefix of that).

    Raises :class:`~exsce_dsl.errors.UnknownRunError` when no run has that id and
    :class:`~exsce_dsl.errors.AmbiguousRunError` when a prefix names several."""
    try:
        uuid = resolve_run(store, run)
    except UnknownRunError:
        found = {stored for stored, _ in dispatched_runs(store, run)} if run else set()
        if not found:
            raise
        if len(found) > 1:
            raise AmbiguousRunError(
                f"run id '{run}' is ambiguous: the dispatcher's ids of {len(found)} runs start with it "
                f"({', '.join(sorted(found))})",
                (),
            ) from None
        uuid = found.pop()
    chain = run_chain(store, uuid)
    ancestry = tuple(lineage(store, chain.scenario)) if chain.scenario else ()
    return RunLineage(chain, ancestry, tuple(value_accounts(store, uuid)))


@dataclass(frozen=True)
class ScenarioLineage:
    """A stored scenario's derivations: its ancestors' (the oldest first) and its descendants',
    each with the steps that made it, as a tree."""

    scenario: str
    ancestry: tuple[Derivation, ...]
    descendants: tuple[tuple[int, str, tuple[TransformationStep, ...]], ...]
    """Depth-first: (depth below the scenario, the derived scenario, the steps that made it)."""

    def text(self, wording: Mapping[str, str] | None = None) -> str:
        """The ancestors, the scenario, then its descendants as a tree (``wording`` as
        :meth:`RunLineage.text` takes it: this text has no remedy to word)."""
        lines = []
        for derivation in self.ancestry:
            lines.append(derivation.base)
            lines.append(f"  └─ {' → '.join(_step_text(s) for s in derivation.steps)}")
        lines.append(f"{self.scenario}  (this one)")
        for depth, child, steps in self.descendants:
            made = " → ".join(_step_text(s) for s in steps)
            lines.append(f"{'    ' * depth}  └─ {made}: {child}")
        return "\n".join(lines)


def _step_text(step: TransformationStep) -> str:
    arguments = " ".join(f"{k}={v}" for k, v in step.parameters)
    return f"{step.transformation}({arguments})" if arguments else step.transformation


def _descendants(
    store: Store, parent: str, depth: int, seen: frozenset[str]
) -> list[tuple[int, str, tuple[TransformationStep, ...]]]:
    found = []
    for child in derived_scenarios(store, parent):
        if child in seen:
            continue
        made = derivation_of(store, child)
        found.append((depth, child, tuple(made.steps) if made else ()))
        found += _descendants(store, child, depth + 1, seen | {child})
    return found


def lineage_of(store: Store, name: str) -> RunLineage | ScenarioLineage:
    """``exscec lineage NAME``: a stored scenario's derivations, or, when the store holds no
    scenario ``name``, the chain of the run it names (:func:`run_lineage`).  A name that is no
    stored run either is a scenario without derivations, unless it has the shape of a run's id
    (then an :class:`~exsce_dsl.errors.UnknownRunError`)."""
    if name not in scenario_ids(store):
        try:
            return run_lineage(store, name)
        except UnknownRunError:
            if names_a_prefix(name) or is_full_uuid(name):
                raise  # an id of a run: say the store lacks it
    ancestry = tuple(reversed(lineage(store, name)))
    return ScenarioLineage(name, ancestry, tuple(_descendants(store, name, 0, frozenset({name}))))
