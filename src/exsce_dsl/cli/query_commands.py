"""Commands that ask the store: ``query`` (the query library), ``sparql`` (any SPARQL), ``runs``."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click

from exsce_dsl.cli.common import reports_errors, write_text
from exsce_dsl.cli.store_commands import store_option

FORMATS = ("table", "json", "csv")  # api.ANSWER_FORMATS, spelled here so that --help imports nothing


def format_option(func: Any) -> Any:
    return click.option(
        "-f",
        "--format",
        "fmt",
        type=click.Choice(FORMATS),
        default="table",
        show_default=True,
        help="Aligned columns, SPARQL 1.1 results JSON, or SPARQL 1.1 results CSV.",
    )(func)


def output_option(func: Any) -> Any:
    return click.option(
        "-o", "--output", type=click.Path(dir_okay=False, writable=True), help="Write here instead of stdout."
    )(func)


def _parameters(pairs: Sequence[str]) -> dict[str, list[str]]:
    given: dict[str, list[str]] = {}
    for pair in pairs:
        name, sep, value = pair.partition("=")
        if not sep or not name:
            raise click.UsageError(f"a parameter is NAME=VALUE, not {pair!r}")
        given.setdefault(name.strip(), []).append(value)
    return given


# -- commands ---------------------------------------------------------------------


@click.command(name="query")
@click.argument("name", required=False)
@click.option(
    "-p", "--param", "params", multiple=True, metavar="NAME=VALUE", help="A parameter; repeat for lists."
)
@click.option("--list", "list_queries", is_flag=True, help="List the queries with what each answers.")
@format_option
@output_option
@store_option
@reports_errors
def query_command(
    name: str | None,
    params: tuple[str, ...],
    list_queries: bool,
    fmt: str,
    output: str | None,
    store_url: str | None,
) -> None:
    """Run a query of the library by NAME, its parameters given with -p.

    Parameters are bound as RDF terms, never pasted into the query.  A
    parameter that takes a list (runs) is given once per value.  A run is
    given by its uuid, any unique prefix of it (4 characters or more: the 8
    that tables print will do) or its IRI.  A metric, robot or scenario the
    store does not hold is a warning naming the store's closest names (the
    answer is then empty, and the exit status 0).

    \b
    Examples:
      exscec query --list
      exscec query runs -p scenario=scenario_c
      exscec query segment_metric_of_scenario -p scenario=scenario_c -p metric=distance_travelled \\
          -p start=classroom_c025-w001-R0.00_P0.00_Y0.00 -p goal=classroom_c022-w001-R0.00_P0.00_Y2.269
      exscec query pose_positions -p pose=classroom_c025-w001-R0.00_P0.00_Y0.00 \\
          -p pose=classroom_c022-w001-R0.00_P0.00_Y2.269 -f json
      exscec query metric_names
    """
    from exsce_dsl.api import answer_query, answer_text, library_queries

    if list_queries:
        lines = []
        for q in library_queries():
            lines.append(f"{q.name}{' (update)' if q.is_update else ''}: {q.description}")
            for p in (p for p in q.parameters if not p.from_runs):  # those are bound from the runs
                mark = (" (one or more)" if p.many else "") + (" (optional)" if p.optional else "")
                lines.append(f"    -p {p.name}=<{p.kind}>{mark}  {p.description}")
        write_text("\n".join(lines) + "\n", output)
        return
    if name is None:
        raise click.UsageError("name a query (exscec query --list shows them)")
    answer = answer_query(store_url, name, _parameters(params))
    for warning in answer.warnings:
        click.echo(f"warning: {warning}", err=True)
    if answer.rows is None:
        click.echo(f"{name}: done", err=True)
        return
    write_text(answer_text(answer.rows, fmt), output)


@click.command(name="sparql")
@click.argument("text", metavar="QUERY")
@format_option
@output_option
@store_option
@reports_errors
def sparql_command(text: str, fmt: str, output: str | None, store_url: str | None) -> None:
    """Run a SPARQL SELECT or ASK QUERY (or @FILE to read it from a file).

    The library's prefixes (exsce:, run:, pose:, prov:, xsd:...) are declared
    for you unless the query declares them itself.  Every PROV bundle is a
    named graph: match with GRAPH ?g { ... }.

    \b
    Examples:
      exscec sparql 'SELECT ?run WHERE { GRAPH ?g { ?r a exsce:run ; exsce:run ?run } }'
      echo 'ASK { GRAPH ?g { ?r a exsce:run } }' > any-runs.rq && exscec sparql @any-runs.rq -f csv
    """
    from exsce_dsl.api import answer_sparql, answer_text, read_text

    if text.startswith("@"):
        path = Path(text[1:])
        text = read_text(path, "query file")
    answer = answer_sparql(store_url, text)
    if isinstance(answer, bool):
        if fmt == "json":
            write_text(json.dumps({"head": {}, "boolean": answer}) + "\n", output)
        else:
            write_text(("true" if answer else "false") + "\n", output)
        return
    write_text(answer_text(answer, fmt), output)


@click.command(name="runs")
@click.argument("scenario", required=False)
@format_option
@output_option
@store_option
@reports_errors
def runs_command(scenario: str | None, fmt: str, output: str | None, store_url: str | None) -> None:
    """List the runs of SCENARIO (of every scenario without one), oldest first.

    \b
    Examples:
      exscec runs scenario_c
      exscec --timings runs scenario_c   # and how long the store took to answer
    """
    from exsce_dsl.api import answer_text, stored_runs

    answer = stored_runs(store_url, scenario)
    for warning in answer.warnings:
        click.echo(f"warning: {warning}", err=True)
    assert answer.rows is not None
    rows = answer.rows
    write_text(answer_text(rows, fmt), output)
    if fmt == "table":
        click.echo(f"{len(rows)} run{'s' if len(rows) != 1 else ''}", err=True)


@click.command(name="explain")
@click.argument("run")
@click.argument("metric")
@click.option("--robot", help="Only this robot's values (the mission's left out).")
@click.option(
    "--segment", metavar="ACTION", help="Only this path segment: its action's name, or its end (w_002)."
)
@store_option
@reports_errors
def explain_command(
    run: str, metric: str, robot: str | None, segment: str | None, store_url: str | None
) -> None:
    """Show what each value of METRIC in RUN used: its sources, its window and why, the samples
    of each source it used of those in the window (and why fewer), and the coverage findings
    that touch it; a missing value, why it is missing.

    RUN is a run's uuid, a unique prefix of it, or its IRI (`exscec runs` lists them).

    \b
    Example:
      exscec explain $(exscec runs scenario_c -f csv | sed -n 2p | cut -d, -f1) \\
          distance_travelled --robot tiago1
    """
    from exsce_dsl.api import explain, open_store

    with open_store(store_url, read_only=True) as store:
        found = explain(store, run, metric, robot, segment)
    click.echo(found.text())


COMMANDS = [query_command, sparql_command, runs_command, explain_command]
