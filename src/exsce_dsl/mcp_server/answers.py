"""What tools answer: query rows as SPARQL 1.1 Query Results JSON, and the tool results around them.

A query answer is the same JSON as ``exscec query NAME --format json`` and
``exscec sparql --format json`` print, so a client reads one format from the
command line and from the server.  At most ``max_rows`` rows are sent, and
no more than one further row is taken from the store; an answer cut short says
so in a ``truncated`` member (``{"shown": rows shown, "more": true}``).

A tool's result carries its answer twice, as the protocol asks: as structured
content (a JSON object) and as that object's JSON text, for clients that read
only text.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import mcp_types as types

from exsce_dsl.mcp_server.access import Access
from exsce_dsl.store import Bindings, Store, results_json

__all__ = ["READ_ONLY", "ToolEntry", "first_rows_json", "results_json", "tool_error", "tool_result"]

READ_ONLY = types.ToolAnnotations(
    read_only_hint=True, destructive_hint=False, idempotent_hint=True, open_world_hint=False
)
"""Every tool of this server only reads."""


@dataclass(frozen=True)
class ToolEntry:
    """A tool: what ``tools/list`` shows of it, and the work that answers a call (run in a
    worker thread, with arguments already checked against the input schema)."""

    tool: types.Tool
    answer: Callable[[Access, Mapping[str, Any]], dict[str, Any]]

    @property
    def name(self) -> str:
        return self.tool.name


def first_rows_json(
    store: Store, query: str, max_rows: int, bindings: Bindings | None = None
) -> dict[str, Any]:
    """The first ``max_rows`` rows of a SELECT as SPARQL 1.1 Query Results JSON, the store asked
    for one more only (:meth:`~exsce_dsl.store.base.Store.select_first`)."""
    rows, more = store.select_first(query, max_rows, bindings)
    answer = results_json(rows)
    if more:
        answer["truncated"] = {"shown": len(rows), "more": True}
    return answer


def tool_result(answer: dict[str, Any]) -> types.CallToolResult:
    return types.CallToolResult(
        content=[types.TextContent(text=json.dumps(answer, ensure_ascii=False))],
        structured_content=answer,
    )


def tool_error(message: str) -> types.CallToolResult:
    """A failed call, told to the model so that it can correct itself (``error: ...``)."""
    return types.CallToolResult(content=[types.TextContent(text=message)], is_error=True)
