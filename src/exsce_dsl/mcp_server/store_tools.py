"""Tools over the store beyond single queries: a scenario's or a run's lineage, a run's verdicts.

Both answer what the command line shows, from the same library functions:
``lineage`` what ``exscec lineage`` prints (:func:`exsce_dsl.store.queries.lineage`,
:func:`~exsce_dsl.store.queries.derived_scenarios`, and for a run its chain from dispatch to
verdict, :func:`~exsce_dsl.store.queries.run_chain` with each value's account), ``run_verdicts``
what the
store holds of a run's last ``exscec verify``
(:func:`exsce_dsl.store.queries.results.verdicts`, as ``exscec verify --json``
writes each verdict).
"""

from __future__ import annotations

import dataclasses
import datetime
import json
from collections.abc import Mapping, Sequence
from typing import Any

import mcp_types as types

from exsce_dsl.errors import ArgumentError, ExsceError, Remedied
from exsce_dsl.mcp_server.access import Access
from exsce_dsl.mcp_server.answers import READ_ONLY, ToolEntry
from exsce_dsl.mcp_server.arguments import NAME, RUN_ID, identifier, object_schema
from exsce_dsl.model.derivation import Derivation
from exsce_dsl.model.verdicts import Outcome
from exsce_dsl.oracles import verdicts_json
from exsce_dsl.remedies import VERIFY_THE_RUN
from exsce_dsl.store import (
    RunChain,
    Store,
    StoredRun,
    ValueAccount,
    derivation_of,
    derived_scenarios,
    lineage,
    resolve_run,
    run_chain,
    runs,
    scenario_ids,
    value_accounts,
    verdicts,
)
from exsce_dsl.suggest import did_you_mean

__all__ = ["lineage_tool", "run_verdicts_tool", "stored_run", "stored_scenario"]


# -- looking things up ----------------------------------------------------------------------


def stored_scenario(store: Store, scenario: str) -> str:
    """``scenario`` if the store holds it; an ExsceError with the nearest id otherwise."""
    known = scenario_ids(store)
    if scenario not in known:
        raise ExsceError(f"no scenario '{scenario}' in the store{did_you_mean(scenario, known)}")
    return scenario


def stored_run(store: Store, run: str) -> StoredRun:
    """The run whose uuid is ``run`` or starts with it (a unique prefix); an ExsceError if the store
    has none, or several runs start with it (listed)."""
    uuid = resolve_run(store, run)
    for found in runs(store):
        if found.uuid == uuid:
            return found
    raise ExsceError(f"no run '{run}' in the store (the runs tool lists them)")


# -- lineage ----------------------------------------------------------------------------------


def derivation_json(derivation: Derivation) -> dict[str, Any]:
    return {
        "scenario": derivation.new,
        "base": derivation.base,
        "steps": [
            {"transformation": step.transformation, "parameters": dict(step.parameters)}
            for step in derivation.steps
        ],
    }


def _descendants(store: Store, parent: str, seen: frozenset[str]) -> list[dict[str, Any]]:
    found = []
    for child in derived_scenarios(store, parent):
        if child in seen:
            continue
        derivation = derivation_of(store, child)
        steps = derivation_json(derivation)["steps"] if derivation is not None else []
        found.append(
            {"scenario": child, "steps": steps, "derived": _descendants(store, child, seen | {child})}
        )
    return found


def _lineage(access: Access, arguments: Mapping[str, Any]) -> dict[str, Any]:
    scenario, run = arguments.get("scenario"), arguments.get("run")
    if (scenario is None) == (run is None):
        raise ArgumentError("give either a scenario or a run")
    answer: dict[str, Any] = {}
    with access.store() as store:
        chain = None
        if run is not None:
            found = stored_run(store, str(run))
            answer["run"] = found.uuid
            scenario = found.scenario
            chain = (run_chain(store, found.uuid), value_accounts(store, found.uuid))
        scenario = stored_scenario(store, str(scenario))
        ancestry = lineage(store, scenario)
        answer["scenario"] = scenario
        answer["ancestors"] = [derivation_json(d) for d in reversed(ancestry)]
        answer["descendants"] = _descendants(store, scenario, frozenset({scenario}))
    if chain is not None:
        answer["chain"] = chain_json(*chain, access.max_rows)
    return answer


def chain_json(found: RunChain, values: Sequence[ValueAccount], max_items: int) -> dict[str, Any]:
    """A run's chain as JSON, as ``exscec lineage RUN`` prints it: execution, goals, bag, values
    (each with its window and samples), verdicts and baseline runs; at most ``max_items`` goals,
    values and verdicts each, ``truncated`` naming the lists cut short."""
    chain = dataclasses.asdict(found)
    accounts = {(a.metric, a.robot, a.action, a.safety_metric): a for a in values}
    for value in chain["values"]:
        account = accounts.get((value["metric"], value["robot"], value["action"], value["safety_metric"]))
        if account is not None and account.window is not None:
            value["window"] = account.window_text()
            value["samples"] = account.samples_text()
    chain["baselines"] = [{"run": run, "bag_path": path} for run, path in found.baselines]
    cut = [name for name in ("goals", "values", "verdicts") if len(chain[name]) > max_items]
    for name in cut:
        chain[name] = chain[name][:max_items]
    if cut:
        chain["truncated"] = {"lists": cut, "shown": max_items}
    answer: dict[str, Any] = json.loads(json.dumps(chain, default=_json_default))
    return answer


def _json_default(value: object) -> object:
    if isinstance(value, datetime.datetime):
        return value.isoformat()
    raise TypeError(f"{type(value).__name__} is not JSON")


def lineage_tool() -> ToolEntry:
    tool = types.Tool(
        name="lineage",
        title="Lineage of a scenario or run",
        description=(
            "Where a scenario (or the scenario of a run) comes from and what was derived from it, as "
            "`exscec lineage` shows: 'ancestors' oldest first, each the derivation of a scenario from "
            "its base with the transformations applied in order; 'descendants' a tree of the scenarios "
            "derived from it.  For a run, 'chain' too: the dispatcher's execution and the goals it "
            "sent, the bag, each value with its window and samples, the verdicts and the baseline "
            "runs they used.  Give either scenario or run."
        ),
        input_schema=object_schema(
            {
                "scenario": identifier(NAME, "the scenario, by id (e.g. scenario_c)"),
                "run": identifier(RUN_ID, "a run, by uuid or unique prefix: the lineage of its scenario"),
            }
        ),
        annotations=READ_ONLY,
    )
    return ToolEntry(tool, _lineage)


# -- verdicts ---------------------------------------------------------------------------------


def _run_verdicts(access: Access, arguments: Mapping[str, Any]) -> dict[str, Any]:
    with access.store() as store:
        run = stored_run(store, str(arguments["run"]))
        found = [v for v in verdicts(store, run.scenario) if v.run == run.uuid]
    answer: dict[str, Any] = {
        "run": run.uuid,
        "scenario": run.scenario,
        **{outcome.value: sum(v.outcome is outcome for v in found) for outcome in Outcome},
        "verdicts": json.loads(verdicts_json(found)),
    }
    if not found:
        answer["note"] = Remedied(
            "the store holds no verdicts of this run: it was not verified", VERIFY_THE_RUN
        ).said()
    return answer


def run_verdicts_tool() -> ToolEntry:
    tool = types.Tool(
        name="run_verdicts",
        title="Verdicts of a run",
        description=(
            "The verdicts of a run's last validation (`exscec verify`) as the store holds them: one per "
            "oracle, failed ones first, each with the metric, robot, relation, observed and expected "
            "values, limit, tolerance, margin, the runs the expectation came from and, when it failed "
            "or was inconclusive, why; `shortfalls` names what the recording did not cover there "
            "(cut_short, no_data, gap, low_rate, clock_jump). An inconclusive verdict is never a pass: "
            "the data the clause needs is missing, cut short or too sparse. With the counts of passed, "
            "failed and inconclusive oracles."
        ),
        input_schema=object_schema(
            {"run": identifier(RUN_ID, "the run, by uuid or a unique prefix of it")}, ("run",)
        ),
        annotations=READ_ONLY,
    )
    return ToolEntry(tool, _run_verdicts)
