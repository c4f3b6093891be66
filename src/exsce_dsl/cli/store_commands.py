"""Commands on the store: ``store info|graphs|export|clear|check|migrate`` and ``serve``."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any, TypeVar

import click

from exsce_dsl.cli.common import REMEDIES, ExitCode, reports_errors, write_text

F = TypeVar("F", bound=Callable[..., Any])

STORE_HELP = (
    "The store: a folder (embedded Oxigraph), memory:, or a SPARQL endpoint's URL "
    "(http(s)://..., or oxigraph+, fuseki+, graphdb+, virtuoso+, neptune+http(s)://...). "
    "Default: $EXSCE_STORE, else .exsce/store."
)


def store_option(func: F) -> F:
    """``--store URL``, passed to the command as ``store_url`` (None: the default store)."""
    return click.option("--store", "store_url", metavar="URL", help=STORE_HELP)(func)


def add_to_store(document: Any, store_url: str | None, replace: bool) -> None:
    """Add a compiled PROV document to the store and say what changed (on stderr)."""
    from exsce_dsl.api import add_to_store as add

    click.echo(add(document, store_url, replace=replace).summary(), err=True)


@click.group(name="store")
def store_group() -> None:
    """Look at and manage the provenance store.

    Each PROV bundle is a named graph.  The default store is the embedded
    Oxigraph store of the current folder (.exsce/store); --store or
    EXSCE_STORE point at another folder or at a SPARQL 1.1 endpoint
    (docs/stores.md).

    \b
    Example:
      exscec store graphs
      exscec store export -f trig -o everything.trig
    """


@store_group.command(name="info")
@store_option
@reports_errors
def info(store_url: str | None) -> None:
    """Say what the store is and how much it holds.

    \b
    Example:
      exscec store info
      exscec store info --store memory:
    """
    from exsce_dsl.api import store_info

    said = store_info(store_url)
    click.echo(f"store:      {said.location} ({said.kind})")
    click.echo(
        f"graphs:     {said.graphs} (+ {said.revisions} revisions, "
        f"+ {said.index_graphs} of its indexes)"
    )
    click.echo(f"statements: {said.statements}")


@store_group.command(name="graphs")
@store_option
@click.option(
    "--index",
    "with_index",
    is_flag=True,
    help="List the graphs of the store's indexes too (segment index, run summaries).",
)
@reports_errors
def graphs(store_url: str | None, with_index: bool) -> None:
    """List the named graphs with their number of statements.

    The segment index the store keeps beside each run (a graph per path segment
    and per action) is left out unless --index is given.

    \b
    Example:
      exscec store graphs
    """
    from exsce_dsl.api import store_graphs

    found = store_graphs(store_url, with_index=with_index)
    sizes, hidden = found.sizes, found.hidden_index
    width = max((len(str(n)) for n in sizes.values()), default=1)
    for name in sorted(sizes):
        click.echo(f"{sizes[name]:>{width}}  {name}")
    shown = f"{len(sizes)} graph{'s' if len(sizes) != 1 else ''}, {sum(sizes.values())} statements"
    if hidden:
        shown += f" (and {hidden} graphs of its indexes: --index lists them)"
    click.echo(shown, err=True)


@store_group.command(name="export")
@store_option
@click.option(
    "-f",
    "--format",
    "fmt",
    type=click.Choice(["trig", "nq"]),
    default="trig",
    show_default=True,
    help="TriG or N-Quads (both keep the named graphs).",
)
@click.option(
    "-o", "--output", type=click.Path(dir_okay=False, writable=True), help="Write here, not to stdout."
)
@reports_errors
def export(store_url: str | None, fmt: str, output: str | None) -> None:
    """Write every named graph of the store as TriG or N-Quads.

    \b
    Example:
      exscec store export -f nq -o store.nq
    """
    from exsce_dsl.api import export_store

    write_text(export_store(store_url, fmt), output)


@store_group.command(name="clear")
@store_option
@click.confirmation_option("--yes", prompt="Remove every graph from the store?", help="Do not ask.")
@reports_errors
def clear(store_url: str | None) -> None:
    """Remove everything from the store, in one transaction.

    \b
    Example:
      exscec store clear --yes
    """
    from exsce_dsl.api import clear_store

    cleared = clear_store(store_url)
    count = cleared.removed
    click.echo(f"{cleared.location}: removed {count} graph{'s' if count != 1 else ''}", err=True)


@store_group.command(name="check")
@store_option
@click.option("--fix", is_flag=True, help="Mend what is safe: remove orphan graphs, rename old bag bundles.")
@reports_errors
def check(store_url: str | None, fix: bool) -> None:
    """Find what no longer hangs together in the store, and with --fix mend what is safe.

    Orphan graphs (a run's graphs without its run, a bag's bundle without
    its run, a path segment no stored run observes), bag bundles named by the
    old scheme (by the bag's file), dangling references (a record naming
    something no graph describes, a baseline of runs the store no longer
    holds) and runs without their scenario.  --fix removes the orphans and
    renames the old bag bundles, in one write; the rest says what to run.
    Exits 1 when something is left to mend.

    \b
    Example:
      exscec store check
      exscec store check --fix
    """
    from exsce_dsl.api import check_store, open_store

    with open_store(store_url, read_only=not fix) as store:
        result = check_store(store, fix=fix)
    click.echo(result.summary(REMEDIES))
    if not result.clean:
        sys.exit(ExitCode.FAILED)


@store_group.command(name="migrate")
@store_option
@reports_errors
def migrate(store_url: str | None) -> None:
    """Move a store written by an older exscec to the current identities.

    A run's bag bundle was named by the bag's file (exsce:<bag file>_bundle),
    so two recordings with one file name could not share a store; it is
    named by the run now (<run>:bag_bundle).  This renames the old graphs,
    in one write; their statements do not change.

    \b
    Example:
      exscec store migrate
    """
    from exsce_dsl.api import migrate_store, open_store

    with open_store(store_url) as store:
        report = migrate_store(store)
    click.echo(report.summary())


@click.command()
@store_option
@click.option(
    "--bind",
    default="127.0.0.1:7878",
    show_default=True,
    metavar="HOST:PORT",
    help="Where to listen (port 0: any free port).",
)
@click.option("--allow-updates", is_flag=True, help="Accept SPARQL updates (with the bearer token).")
@click.option(
    "--token",
    envvar="EXSCE_STORE_TOKEN",
    metavar="TOKEN",
    help="The bearer token updates need, 16 characters or more "
    "(default: $EXSCE_STORE_TOKEN, else a new one, printed once).",
)
@click.option(
    "--allow-federation",
    "federation_hosts",
    multiple=True,
    metavar="HOST",
    help="Let SERVICE (and, with --allow-updates, LOAD) reach HOST; repeatable. Default: no host.",
)
@click.option(
    "--allowed-host",
    "allowed_hosts",
    multiple=True,
    metavar="NAME",
    help="Answer requests whose Host header is NAME (a reverse proxy's name), besides the bound "
    "address; repeatable.",
)
@click.option("--union-default-graph", is_flag=True, help="Queries without GRAPH see every named graph.")
@click.option("--log", "log_requests", is_flag=True, help="Print each request on stderr.")
@click.option(
    "--query-timeout",
    type=click.FloatRange(min=0, min_open=True),
    default=60.0,
    show_default=True,
    metavar="SECONDS",
    help="Stop a query or update that runs longer (with its answer) and answer 503.",
)
@click.option(
    "--max-answer-mb",
    type=click.FloatRange(min=0, min_open=True),
    default=256.0,
    show_default=True,
    metavar="MIB",
    help="Answer 503 instead of a larger answer (also /store).",
)
@reports_errors
def serve(
    store_url: str | None,
    bind: str,
    allow_updates: bool,
    token: str | None,
    federation_hosts: tuple[str, ...],
    allowed_hosts: tuple[str, ...],
    union_default_graph: bool,
    log_requests: bool,
    query_timeout: float,
    max_answer_mb: float,
) -> None:
    """Serve the store as a SPARQL 1.1 Protocol endpoint, read-only unless told.

    Queries: GET or POST /query (results as JSON, XML, CSV or TSV; graphs as
    Turtle or N-Triples), and a query page at /.  With --allow-updates, POST
    /update takes SPARQL updates that carry `Authorization: Bearer TOKEN`.
    While it runs, the server holds the store; other exscec commands on the
    same store go through it (writes only with --allow-updates and
    EXSCE_STORE_TOKEN set to the token).  The server's URL is the first line
    on stdout: ask it with `curl 'URL/query?query=ASK%7B%7D'`, or from
    another machine's exscec with --store URL/query.

    Closed unless opened: SERVICE and LOAD reach no other server without
    --allow-federation HOST; requests must name the server as bound in their
    Host header (--allowed-host adds a name) and come from its own page, not
    another origin's; a query is stopped at --query-timeout.

    \b
    Example:
      exscec serve                        # at http://127.0.0.1:7878/
      exscec serve --bind 127.0.0.1:0     # on a free port, printed first
      exscec serve --allow-federation query.wikidata.org
    """
    from exsce_dsl.api import is_loopback, serve_endpoint

    host, port = _parse_bind(bind)
    token = _update_token(token) if allow_updates else None
    if not is_loopback(host):
        click.echo(
            f"warning: listening on {host}: other machines can reach this endpoint"
            + (" and, with the token, change the store" if token else ""),
            err=True,
        )

    def log(line: str) -> None:
        click.echo(line, err=True)

    def ready(url: str, store_path: object) -> None:
        click.echo(f"{url}/")
        mode = "updates with a bearer token" if token else "read-only"
        where = store_path if store_path is not None else "memory:"
        click.echo(f"serving {where} at {url}/ ({mode}); Ctrl-C to stop", err=True)

    serve_endpoint(
        store_url, host, port, token=token, union_default_graph=union_default_graph,
        query_timeout=query_timeout, max_answer_mb=max_answer_mb, allowed_hosts=allowed_hosts,
        federation_hosts=federation_hosts, log=log if log_requests else None, on_ready=ready,
        wording=REMEDIES,
    )  # fmt: skip


def _update_token(given: str | None) -> str:
    """The token updates need: ``given`` (if long enough), else a new one, printed once."""
    from exsce_dsl.api import update_token

    token = update_token(given)
    if token.minted:
        shown = f"updates need this bearer token: {token.text}"
        click.echo(f"{shown}  (exscec commands: EXSCE_STORE_TOKEN={token.text})", err=True)
    return token.text


def _parse_bind(bind: str) -> tuple[str, int]:
    host, sep, port_text = bind.rpartition(":")
    if not sep:
        host, port_text = "", bind
    host = host.strip("[]") or "127.0.0.1"
    try:
        port = int(port_text)
    except ValueError:
        raise click.BadParameter(f"expected HOST:PORT, got {bind!r}", param_hint="--bind") from None
    if not 0 <= port <= 65535:
        raise click.BadParameter(f"port {port} is out of range", param_hint="--bind")
    return host, port


COMMANDS = [store_group, serve]
