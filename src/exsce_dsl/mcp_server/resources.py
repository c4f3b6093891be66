"""Resources: the scenarios and the runs in the store, each list and each one's summary, as JSON.

==============================  ====================================================================
URI                             what it holds
==============================  ====================================================================
``exsce://scenarios``           every scenario: its id, its number of runs, its URI
``exsce://scenarios/{id}``      a scenario: robots, the derivation it comes from, the scenarios
                                derived from it, its runs and its oracles
``exsce://runs``                every run, oldest first: uuid, scenario, times, bag, URI
``exsce://runs/{uuid}``         a run: its scenario, times, bag, every whole-run metric value and
                                the counts of its verdicts
==============================  ====================================================================

Each summary is read from the store with the typed queries of
:mod:`exsce_dsl.store.queries` when the client reads it.
"""

from __future__ import annotations

import datetime
import json
import re
from collections import Counter
from typing import Any

import mcp_types as types

from exsce_dsl.errors import ExsceError, ResourceNotFound
from exsce_dsl.mcp_server.access import Access
from exsce_dsl.mcp_server.arguments import NAME, RUN_ID
from exsce_dsl.mcp_server.store_tools import derivation_json, stored_run, stored_scenario
from exsce_dsl.model.verdicts import Outcome
from exsce_dsl.store import (
    Store,
    StoredRun,
    derivation_of,
    derived_scenarios,
    oracles,
    robots,
    run_metric_values,
    runs,
    scenario_ids,
    verdicts,
)

__all__ = ["SCHEME", "list_resources", "read_resource", "resource_templates"]

SCHEME = "exsce://"
SCENARIOS = f"{SCHEME}scenarios"
RUNS = f"{SCHEME}runs"
JSON = "application/json"
PAGE = 500
"""Resources listed per page of ``resources/list``."""

_URI = re.compile(r"exsce://(scenarios|runs)(?:/([^/]*))?")


def scenario_uri(scenario: str) -> str:
    return f"{SCENARIOS}/{scenario}"


def run_uri(run: str) -> str:
    return f"{RUNS}/{run}"


def resource_templates() -> list[types.ResourceTemplate]:
    return [
        types.ResourceTemplate(
            name="scenario",
            title="A scenario in the store",
            uri_template=f"{SCENARIOS}/{{scenario}}",
            description="A scenario by id: its robots, where it was derived from, the scenarios derived "
            "from it, its runs and its oracles.",
            mime_type=JSON,
        ),
        types.ResourceTemplate(
            name="run",
            title="A run in the store",
            uri_template=f"{RUNS}/{{run}}",
            description="A run by uuid (or a unique prefix of it): its scenario, times, bag, whole-run "
            "metric values and the counts of its verdicts (passed, failed, inconclusive).",
            mime_type=JSON,
        ),
    ]


def list_resources(access: Access, cursor: str | None) -> tuple[list[types.Resource], str | None]:
    """A page of the resources (the two lists, then each scenario, then each run) and the cursor
    of the next page (None after the last)."""
    start = _offset(cursor)
    with access.store() as store:
        scenarios, stored = scenario_ids(store), runs(store)
    found = [
        types.Resource(
            name="scenarios",
            title="Scenarios",
            uri=SCENARIOS,
            mime_type=JSON,
            description=f"The {len(scenarios)} scenarios in the store.",
        ),
        types.Resource(
            name="runs",
            title="Runs",
            uri=RUNS,
            mime_type=JSON,
            description=f"The {len(stored)} runs in the store, oldest first.",
        ),
    ]
    found += [
        types.Resource(name=s, title=f"Scenario {s}", uri=scenario_uri(s), mime_type=JSON) for s in scenarios
    ]
    found += [
        types.Resource(
            name=r.uuid, title=f"Run {r.uuid[:8]} of {r.scenario}", uri=run_uri(r.uuid), mime_type=JSON
        )
        for r in stored
    ]
    page = found[start : start + PAGE]
    return page, str(start + PAGE) if start + PAGE < len(found) else None


def _offset(cursor: str | None) -> int:
    if cursor is None:
        return 0
    if not cursor.isdigit():
        raise ExsceError(f"not a cursor of this server: {cursor!r}")
    return int(cursor)


def read_resource(access: Access, uri: str) -> str:
    """The JSON text of the resource at ``uri``."""
    match = _URI.fullmatch(uri)
    if match is None:
        raise ResourceNotFound(f"no resource {uri!r}: the URIs are {SCENARIOS}[/ID] and {RUNS}[/UUID]")
    kind, key = match.groups()
    if key is not None and not re.fullmatch(NAME if kind == "scenarios" else RUN_ID, key):
        what = "a scenario id" if kind == "scenarios" else "a run uuid (or a prefix of one)"
        raise ResourceNotFound(f"no resource {uri!r}: {key!r} is not {what}")
    with access.store() as store:
        if kind == "scenarios":
            answer = _scenarios(store) if key is None else _scenario(store, key)
        else:
            answer = {"runs": [_run_json(r) for r in runs(store)]} if key is None else _run(store, key)
    return json.dumps(answer, ensure_ascii=False, indent=1)


def _scenarios(store: Store) -> dict[str, Any]:
    counts = Counter(r.scenario for r in runs(store))
    return {
        "scenarios": [
            {"scenario": s, "runs": counts.get(s, 0), "uri": scenario_uri(s)} for s in scenario_ids(store)
        ]
    }


def _scenario(store: Store, key: str) -> dict[str, Any]:
    try:
        scenario = stored_scenario(store, key)
    except ExsceError as exc:
        raise ResourceNotFound(exc.message) from None
    derivation = derivation_of(store, scenario)
    return {
        "scenario": scenario,
        "robots": [
            {"robot": r.robot, "type": r.type, "base": r.base, "torso": r.torso}
            for r in robots(store, scenario)
        ],
        "derived_from": derivation_json(derivation) if derivation is not None else None,
        "derived": [{"scenario": d, "uri": scenario_uri(d)} for d in derived_scenarios(store, scenario)],
        "runs": [_run_json(r) for r in runs(store, scenario)],
        "oracles": [
            {
                "metric": o.metric,
                "robot": o.robot,
                "relation": o.relation,
                "type": o.type.value,
                "value": o.value,
                "limit": o.limit,
                "delta": o.delta,
                "tolerance": o.tolerance,
                "window": o.window,
                "criterion": o.criterion,
            }
            for o in oracles(store, scenario)
        ],
    }


def _run(store: Store, key: str) -> dict[str, Any]:
    try:
        run = stored_run(store, key)
    except ExsceError as exc:
        raise ResourceNotFound(exc.message) from None
    outcomes = Counter(v.outcome for v in verdicts(store, run.scenario) if v.run == run.uuid)
    return {
        **_run_json(run),
        "scenario_uri": scenario_uri(run.scenario),
        "metrics": [
            {"metric": m.metric, "robot": m.robot, "value": m.value, "unit": m.unit, "safety": m.safety}
            for m in run_metric_values(store, [run.uuid])
        ],
        "verdicts": {outcome.value: outcomes.get(outcome, 0) for outcome in Outcome},
    }


def _run_json(run: StoredRun) -> dict[str, Any]:
    return {
        "run": run.uuid,
        "scenario": run.scenario,
        "start": _time(run.start),
        "end": _time(run.end),
        "bag": run.bag,
        "path": run.path,
        "uri": run_uri(run.uuid),
    }


def _time(moment: datetime.datetime | None) -> str | None:
    return None if moment is None else moment.isoformat()
