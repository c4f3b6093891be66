"""``exscec mcp``: the store and the checker over the Model Context Protocol, read-only.

An MCP client (Claude Desktop, an IDE's assistant, any agent) starts
``exscec mcp`` and talks to it on stdin and stdout.  The server offers:

* **tools**: one per query of the store's query library (:mod:`.library_tools`),
  ``lineage`` and ``run_verdicts`` (:mod:`.store_tools`), ``check`` of a
  specification's text (:mod:`.check_tool`) and ``sparql`` for any SELECT or
  ASK query (:mod:`.sparql_tool`);
* **resources**: the scenarios and runs in the store, as lists and one by one
  (:mod:`.resources`).

Nothing it offers writes: the library's updates are left out, the SPARQL tool
refuses updates, and every value a client gives is checked against the tool's
input schema (:mod:`.arguments`) and bound as an RDF term, never pasted into a
query.  The store is opened per request (:mod:`.access`).
"""

from exsce_dsl.mcp_server.access import Access
from exsce_dsl.mcp_server.server import build_server, serve, tool_entries

__all__ = ["Access", "build_server", "serve", "tool_entries"]
