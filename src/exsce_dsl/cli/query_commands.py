"""Commands that ask the store: ``query`` (the query library), ``sparql`` (any SPARQL), ``runs``."""

from __future__ import annotations

import csv
import io
import json
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import click
from pyoxigraph import BlankNode, Literal, NamedNode

from exsce_dsl.cli.common import reports_errors, write_text
from exsce_dsl.cli.store_commands import store_option
from exsce_dsl.errors import ExsceError
from exsce_dsl.store.base import Rows, Term
from exsce_dsl.store.literals import literal_text
from exsce_dsl.tables import aligned

FORMATS = ("table", "json", "csv")
_PREFIX_DECLARATION = re.compile(r"^\s*PREFIX\s+([A-Za-z][\w.-]*)?:", re.IGNORECASE | re.MULTILINE)
_KIND_AFTER_PROLOGUE = re.compile(
    r"^(?:\s|#[^\n]*\n|PREFIX\s+[^\s:]*:\s*<[^>]*>|BASE\s*<[^>]*>)*\s*(SELECT|ASK|CONSTRUCT|DESCRIBE)\b",
    re.IGNORECASE,
)


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


# -- writing answers -------------------------------------------------------------


def results_json(rows: Rows) -> str:
    """SPARQL 1.1 Query Results JSON."""
    from exsce_dsl.store.answers import results_json as answer

    return json.dumps(answer(rows), indent=2) + "\n"


def results_csv(rows: Rows) -> str:
    """SPARQL 1.1 Query Results CSV: lexical forms (each literal in its one form), CRLF line ends."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\r\n")
    writer.writerow(rows.variables)
    for row in rows.rows:
        writer.writerow([_csv_text(t) for t in row])
    return out.getvalue()


def _csv_text(t: Term | None) -> str:
    if t is None:
        return ""
    if isinstance(t, Literal):
        return literal_text(t)
    return f"_:{t.value}" if isinstance(t, BlankNode) else t.value


def results_table(rows: Rows, prefixes: Mapping[str, str]) -> str:
    """Aligned columns, IRIs shortened with the library's prefixes, literals as their text (in
    their one form, doubles to 15 significant digits: :mod:`exsce_dsl.store.literals`)."""
    namespaces = sorted(((iri, p) for p, iri in prefixes.items()), key=lambda item: -len(item[0]))

    def show(t: Term | None) -> str:
        if t is None:
            return ""
        if isinstance(t, NamedNode):
            for iri, prefix in namespaces:
                if t.value.startswith(iri) and len(t.value) > len(iri):
                    return f"{prefix}:{t.value[len(iri) :]}"
            return f"<{t.value}>"
        if isinstance(t, BlankNode):
            return f"_:{t.value}"
        return literal_text(t)

    cells = [list(rows.variables)] + [[show(t) for t in row] for row in rows.rows]
    if not rows.variables:
        return ""
    widths = [max(len(line[i]) for line in cells) for i in range(len(rows.variables))]
    lines = aligned(cells)
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines) + "\n"


def render(rows: Rows, fmt: str) -> str:
    from exsce_dsl.store.queries import standard_prefixes

    if fmt == "json":
        return results_json(rows)
    if fmt == "csv":
        return results_csv(rows)
    return results_table(rows, standard_prefixes())


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
    from exsce_dsl.store.queries import query, query_names, run_query
    from exsce_dsl.store.queries.stored_names import unknown_names

    if list_queries:
        lines = []
        for known in query_names():
            q = query(known)
            lines.append(f"{known}{' (update)' if q.is_update else ''}: {q.description}")
            for p in q.parameters:
                mark = (" (one or more)" if p.many else "") + (" (optional)" if p.optional else "")
                lines.append(f"    -p {p.name}=<{p.kind}>{mark}  {p.description}")
        write_text("\n".join(lines) + "\n", output)
        return
    if name is None:
        raise click.UsageError("name a query (exscec query --list shows them)")
    from exsce_dsl.store.open import open_store

    library_query = query(name)
    given = _parameters(params)
    library_query.bindings(given)  # check the parameters before opening the store
    with open_store(store_url, read_only=not library_query.is_update) as store:
        rows = run_query(store, name, given, check_runs=True)
        unknown = [] if library_query.is_update else unknown_names(store, name, given)
    for warning in unknown:
        click.echo(f"warning: {warning}", err=True)
    if library_query.is_update:
        click.echo(f"{name}: done", err=True)
        return
    write_text(render(rows, fmt), output)


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
    from exsce_dsl.store.open import open_store
    from exsce_dsl.store.queries import standard_prefixes
    from exsce_dsl.textfiles import read_text

    if text.startswith("@"):
        path = Path(text[1:])
        text = read_text(path, "query file")
    declared = {m.group(1) or "" for m in _PREFIX_DECLARATION.finditer(text)}
    prologue = "".join(
        f"PREFIX {p}: <{iri}>\n" for p, iri in standard_prefixes().items() if p not in declared
    )
    kind = _KIND_AFTER_PROLOGUE.match(text)
    verb = kind.group(1).upper() if kind else ""
    if verb not in ("SELECT", "ASK"):
        raise ExsceError("exscec sparql runs SELECT and ASK queries")
    with open_store(store_url, read_only=True) as store:
        if verb == "ASK":
            answer = store.ask(prologue + text)
            if fmt == "json":
                write_text(json.dumps({"head": {}, "boolean": answer}) + "\n", output)
            else:
                write_text(("true" if answer else "false") + "\n", output)
            return
        rows = store.select(prologue + text)
    write_text(render(rows, fmt), output)


@click.command(name="runs")
@click.argument("scenario", required=False)
@format_option
@output_option
@store_option
@reports_errors
def runs_command(scenario: str | None, fmt: str, output: str | None, store_url: str | None) -> None:
    """List the runs of SCENARIO (of every scenario without one), oldest first.

    \b
    Example:
      exscec runs scenario_c
    """
    from exsce_dsl.store.open import open_store
    from exsce_dsl.store.queries import run_query
    from exsce_dsl.store.queries.stored_names import unknown_names

    given = {} if scenario is None else {"scenario": scenario}
    with open_store(store_url, read_only=True) as store:
        rows = run_query(store, "runs", given)
        unknown = unknown_names(store, "runs", given) if not rows else []
    for warning in unknown:
        click.echo(f"warning: {warning}", err=True)
    write_text(render(rows, fmt), output)
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
    from exsce_dsl.api.explain import explain
    from exsce_dsl.store.open import open_store

    with open_store(store_url, read_only=True) as store:
        found = explain(store, run, metric, robot, segment)
    click.echo(found.text())


COMMANDS = [query_command, sparql_command, runs_command, explain_command]
