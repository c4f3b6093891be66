"""The server: the tools and resources of this package behind the SDK's low-level ``Server``.

The low-level server is used rather than ``MCPServer``'s decorators because the
tools are data: one per query of the library, their input schemas written from
the queries' metadata, not from Python signatures.  Every tool is a
:class:`~exsce_dsl.mcp_server.answers.ToolEntry` looked up by name; a call is
checked against the tool's input schema, worked on in a worker thread within
the time limit (:class:`~exsce_dsl.mcp_server.access.Access`), and a library
error comes back as a tool error the model can read and correct.
"""

from __future__ import annotations

import functools
import logging
import os
import sys
from collections.abc import Callable
from typing import Any, TypeVar

import anyio
import mcp_types as types
from mcp.server import Server, ServerRequestContext
from mcp.server.stdio import stdio_server
from mcp.shared.exceptions import MCPError
from mcp_types import INTERNAL_ERROR, INVALID_PARAMS

from exsce_dsl import __version__
from exsce_dsl.errors import ExsceError, ResourceNotFound
from exsce_dsl.mcp_server.access import Access
from exsce_dsl.mcp_server.answers import ToolEntry, tool_error, tool_result
from exsce_dsl.mcp_server.arguments import checked_arguments
from exsce_dsl.mcp_server.check_tool import check_tool
from exsce_dsl.mcp_server.library_tools import library_tools
from exsce_dsl.mcp_server.resources import (
    list_resources,
    read_resource,
    resource_templates,
)
from exsce_dsl.mcp_server.sparql_tool import sparql_tool
from exsce_dsl.mcp_server.store_tools import lineage_tool, run_verdicts_tool
from exsce_dsl.suggest import did_you_mean

__all__ = ["INSTRUCTIONS", "build_server", "serve", "tool_entries"]

_log = logging.getLogger(__name__)
T = TypeVar("T")

INSTRUCTIONS = """\
exsce's provenance store of robot test scenarios (W3C PROV as RDF), read-only.
Scenarios are compiled from the exsce language; each run of a scenario has its metric values, per
run and per path segment; verdicts say whether a run passed its oracles, failed them, or was
inconclusive (its recording does not cover what a clause needs: never a pass).
Start with the `scenarios` and `runs` tools (or the resources exsce://scenarios and exsce://runs);
the other query tools take scenario ids, run uuids, robot ids, metric names and pose names as those
answers give them.  `lineage` shows how scenarios were derived, `run_verdicts` a run's verdicts,
`check` checks the text of a specification, and `sparql` runs any SELECT or ASK query.
"""


def tool_entries() -> dict[str, ToolEntry]:
    """Every tool by name: the query library's, then lineage, run_verdicts, check and sparql."""
    found: dict[str, ToolEntry] = {}
    for entry in [*library_tools(), lineage_tool(), run_verdicts_tool(), check_tool(), sparql_tool()]:
        if entry.name in found:
            raise ExsceError(
                f"two tools are called '{entry.name}': rename the query library's {entry.name}.rq"
            )
        found[entry.name] = entry
    return found


def build_server(access: Access) -> Server[Any]:
    """The MCP server over the store that ``access`` opens."""
    tools = tool_entries()

    async def on_list_tools(
        ctx: ServerRequestContext[Any], params: types.PaginatedRequestParams | None
    ) -> types.ListToolsResult:
        return types.ListToolsResult(tools=[entry.tool for entry in tools.values()])

    async def on_call_tool(
        ctx: ServerRequestContext[Any], params: types.CallToolRequestParams
    ) -> types.CallToolResult:
        entry = tools.get(params.name)
        if entry is None:
            raise MCPError(
                INVALID_PARAMS, f"no tool called '{params.name}'{did_you_mean(params.name, tools)}"
            )
        try:
            arguments = checked_arguments(entry.tool.input_schema, params.arguments)
            answer = await access.run(functools.partial(entry.answer, access, arguments))
        except ExsceError as exc:
            return tool_error("\n".join(str(d) for d in exc.diagnostics))
        except Exception as exc:  # a bug of ours: say so, keep serving
            _log.exception("tool %s failed", params.name)
            return tool_error(f"internal error: {type(exc).__name__}: {exc}")
        return tool_result(answer)

    async def on_list_resources(
        ctx: ServerRequestContext[Any], params: types.PaginatedRequestParams | None
    ) -> types.ListResourcesResult:
        cursor = params.cursor if params is not None else None
        found, after = await _resource_work(access, functools.partial(list_resources, access, cursor))
        return types.ListResourcesResult(resources=found, next_cursor=after)

    async def on_list_resource_templates(
        ctx: ServerRequestContext[Any], params: types.PaginatedRequestParams | None
    ) -> types.ListResourceTemplatesResult:
        return types.ListResourceTemplatesResult(resource_templates=resource_templates())

    async def on_read_resource(
        ctx: ServerRequestContext[Any], params: types.ReadResourceRequestParams
    ) -> types.ReadResourceResult:
        text = await _resource_work(access, functools.partial(read_resource, access, params.uri))
        contents = types.TextResourceContents(uri=params.uri, mime_type="application/json", text=text)
        return types.ReadResourceResult(contents=[contents])

    return Server(
        "exsce",
        version=__version__,
        title="exsce store and checker",
        instructions=INSTRUCTIONS,
        on_list_tools=on_list_tools,
        on_call_tool=on_call_tool,
        on_list_resources=on_list_resources,
        on_list_resource_templates=on_list_resource_templates,
        on_read_resource=on_read_resource,
    )


async def _resource_work(access: Access, work: Callable[[], T]) -> T:
    """``work`` in a worker thread, its errors as the protocol's (a resource not found: invalid
    parameters)."""
    try:
        return await access.run(work)
    except ResourceNotFound as exc:
        raise MCPError(INVALID_PARAMS, exc.message) from None
    except ExsceError as exc:
        raise MCPError(INTERNAL_ERROR, exc.message) from None


def serve(access: Access) -> None:
    """Serve on stdin and stdout until the client closes them."""
    server = build_server(access)

    async def run() -> None:
        async with stdio_server() as (read, write):
            await server.run(read, write, server.create_initialization_options())

    logging.basicConfig(stream=sys.stderr, level=logging.WARNING, format="exscec mcp: %(message)s")
    anyio.run(run)
    if access.working:  # queries given up on still run, and Python would wait for them: they only read
        _log.warning("stopping with %d unfinished queries", access.working)
        logging.shutdown()
        os._exit(0)
