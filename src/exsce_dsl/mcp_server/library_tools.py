"""One tool per query of the store's query library, typed from the query's own metadata.

Each ``NAME.rq`` of :mod:`exsce_dsl.store.queries` becomes the tool ``NAME``:
its first comment line is the tool's description, and each ``?parameter`` line
a property of the input schema, typed by its kind (an id, a pose name, a run
uuid, a number...), a list when the kind is marked ``+``, required unless it
is marked ``?``.  A call runs the query exactly as ``exscec query NAME -p k=v``
does (:func:`exsce_dsl.store.queries.run_query`): the values are bound as RDF
terms, never pasted into the query.  The library's updates (``.ru``) are not
offered: this server only reads.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import mcp_types as types

from exsce_dsl.mcp_server.access import Access
from exsce_dsl.mcp_server.answers import READ_ONLY, ToolEntry, results_json
from exsce_dsl.mcp_server.arguments import MAX_TEXT, MAX_VALUES, NAME, POSE_NAME, RUN_ID, object_schema
from exsce_dsl.store import Query, QueryParameter, query, query_names, run_query

__all__ = ["library_tools", "parameter_schema", "query_tool"]

Answer = Callable[[Access, Mapping[str, Any]], dict[str, Any]]

_KIND_SCHEMAS: dict[str, dict[str, Any]] = {
    "scenario": {"type": "string", "pattern": NAME},
    "id": {"type": "string", "pattern": NAME},
    "robot": {"type": "string", "pattern": NAME},
    "metric": {"type": "string", "pattern": NAME},
    "metric_property": {"type": "string", "pattern": NAME},
    "point": {"type": "string", "pattern": NAME},
    "pose": {"type": "string", "pattern": POSE_NAME},
    "run": {"type": "string", "pattern": RUN_ID},
    "run_activity": {"type": "string", "pattern": RUN_ID},  # given as its uuid, like "run"
    "run_prefix": {"type": "string", "pattern": RUN_ID},  # the start of a run's uuid (4 characters or more)
    "string": {"type": "string"},
    "double": {"type": "number"},
}
"""The JSON schema of one value of each parameter kind of the library
(:data:`exsce_dsl.store.queries.KINDS`) but those bound from the runs given, never offered
(:data:`~exsce_dsl.store.queries.library.FROM_RUNS`); a kind missing here is a plain string,
still made an RDF term by the library."""


def parameter_schema(parameter: QueryParameter) -> dict[str, Any]:
    """The JSON schema of a query parameter: its kind's, a list of those for a ``+`` kind."""
    one = dict(_KIND_SCHEMAS.get(parameter.kind, {"type": "string"}))
    if one["type"] == "string":
        one.setdefault("maxLength", MAX_TEXT if "pattern" not in one else 200)
    description = parameter.description or parameter.kind
    if parameter.many:
        return {
            "type": "array",
            "items": one,
            "minItems": 1,
            "maxItems": MAX_VALUES,
            "description": f"{description} (one or more)",
        }
    return {**one, "description": description}


def query_tool(q: Query) -> types.Tool:
    """The tool of library query ``q``."""
    given = [p for p in q.parameters if not p.from_runs]  # the others are bound from the runs
    properties = {p.name: parameter_schema(p) for p in given}
    required = tuple(p.name for p in given if not p.optional)
    return types.Tool(
        name=q.name,
        title=q.name.replace("_", " "),
        description=(
            f"{q.description} (The store's query library: `exscec query {q.name}`.)  "
            "Answers SPARQL 1.1 Query Results JSON."
        ),
        input_schema=object_schema(properties, required),
        annotations=READ_ONLY,
    )


def library_tools() -> list[ToolEntry]:
    """A tool for each query (not update) of the library, in name order."""
    found = []
    for name in query_names():
        q = query(name)
        if not q.is_update:
            found.append(ToolEntry(query_tool(q), _answer_of(q.name)))
    return found


def _answer_of(name: str) -> Answer:
    def answer(access: Access, arguments: Mapping[str, Any]) -> dict[str, Any]:
        given = {key: _texts(value) for key, value in arguments.items()}
        with access.store() as store:
            rows = run_query(store, name, given, check_runs=True)
        return results_json(rows, access.max_rows)

    return answer


def _texts(value: Any) -> str | Sequence[str]:
    """An argument as the library takes parameters: text (a number as Python writes it)."""
    if isinstance(value, list):
        return [_text(v) for v in value]
    return _text(value)


def _text(value: Any) -> str:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return repr(float(value))
    return str(value)
