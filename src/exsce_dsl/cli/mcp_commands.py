"""``exscec mcp``: the store and the checker for MCP clients, on stdio."""

from __future__ import annotations

import click

from exsce_dsl.api import QUERY_TIMEOUT  # the store's: the endpoint's would import http.server
from exsce_dsl.cli.common import reports_errors
from exsce_dsl.cli.store_commands import store_option


@click.command(name="mcp")
@click.option(
    "--timeout",
    type=click.FloatRange(min=0.1),
    default=QUERY_TIMEOUT,
    show_default=True,
    metavar="SECONDS",
    help="How long a tool call or resource read may take (as exscec serve's query time limit).",
)
@click.option(
    "--max-rows",
    type=click.IntRange(min=1),
    default=1000,
    show_default=True,
    metavar="N",
    help="The most rows a query answer shows; a longer answer says it was cut.",
)
@click.option(
    "--root",
    type=click.Path(exists=True, file_okay=False),
    default=None,
    metavar="DIR",
    help="The folder whose specification files the check tool may read (default: where it starts).",
)
@store_option
@reports_errors
def mcp(timeout: float, max_rows: int, root: str | None, store_url: str | None) -> None:
    """Serve the store and the checker to an MCP client (Model Context Protocol), on stdio.

    Read-only.  Tools: one per query of the query library (exscec query
    --list), lineage, run_verdicts, check (exscec check of a specification's
    text, diagnostics as file:line:col) and sparql (SELECT and ASK only; no
    updates, no SERVICE).  The check tool reads no file outside the folder the
    server started in (or --root).  Resources: exsce://scenarios, exsce://runs, and
    exsce://scenarios/{id}, exsce://runs/{uuid}.  The store is opened for each
    request, so ingests and other commands may use it in between.

    MCP clients start the server themselves and talk to it on stdin and
    stdout; give the store as an absolute --store, and the project's folder
    as --root (a client may start the server in any folder).

    \b
    Example (a client's session, by hand):
      exscec mcp --store "$PWD/.exsce/store"
    \b
    Claude Desktop (claude_desktop_config.json), or any client's mcpServers:
      {
        "mcpServers": {
          "exsce": {
            "command": "/path/to/venv/bin/exscec",
            "args": ["mcp", "--store", "/path/to/project/.exsce/store",
                     "--root", "/path/to/project"]
          }
        }
      }
    \b
    Claude Code:
      claude mcp add exsce -- exscec mcp --store "$PWD/.exsce/store"
    \b
    Try it with the MCP Inspector:
      npx @modelcontextprotocol/inspector exscec mcp
    """
    from exsce_dsl.api import serve_mcp

    def ready(url: str) -> None:
        click.echo(f"exscec mcp: serving {url} read-only on stdio", err=True)

    serve_mcp(store_url, timeout=timeout, max_rows=max_rows, root=root, on_ready=ready)


COMMANDS = [mcp]
