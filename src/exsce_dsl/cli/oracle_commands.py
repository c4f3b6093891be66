"""``exscec baseline`` and ``exscec verify``: oracles from stored runs, and verdicts on runs."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import click

from exsce_dsl.cli.common import ExitCode, bag_arguments, exit_status, reports_errors, write_text
from exsce_dsl.cli.store_commands import store_option

if TYPE_CHECKING:
    from exsce_dsl.oracles.workflows import Verification


@click.command(epilog=exit_status(bad_input="bad input: a spec error, too few runs, no acceptance criteria"))
@click.argument("spec", type=click.Path(dir_okay=False))
@click.option("--scenario-id", help="Which scenario, when the file declares several.")
@store_option
@reports_errors
def baseline(spec: str, scenario_id: str | None, store_url: str | None) -> None:
    """Build the oracles of a scenario from its acceptance criteria and its stored runs.

    Each clause becomes an oracle per robot it is about; the value a
    performance clause compares with is the mean of the metric over the stored
    runs (tolerance: as written, else one standard deviation).  The oracles
    are written to the store (the previous ones are kept as a revision) and
    shown.  Refuses while the scenario has fewer runs than its criteria ask
    ('given at least N baseline runs', 3 if not said).

    \b
    Example:
      exscec baseline examples/brsu_building_c/scenario_c.exsce
    """
    from exsce_dsl.lang.build import load_spec
    from exsce_dsl.oracles.workflows import build_baseline
    from exsce_dsl.store.open import open_store
    from exsce_dsl.tables import aligned

    with open_store(store_url) as store:
        built = build_baseline(store, load_spec(spec), scenario_id)
    scenario, oracles, report = built.scenario, built.oracles, built.written
    rows: list[tuple[str, ...]] = [("oracle", "relation", "value", "limit", "delta", "tolerance", "runs")]
    for o in oracles:
        rows.append(
            (
                o.name,
                o.relation + ("" if o.base_scenario == scenario.id else f" of {o.base_scenario}"),
                *(f"{n:.4g}" if n is not None else "" for n in (o.value, o.limit, o.delta)),
                (f"{o.tolerance:.4g}" if o.tolerance is not None else "")
                + (f" (at {o.confidence * 100:g} %)" if o.confidence is not None else ""),
                str(len(o.sources)) if o.sources else "",
            )
        )
    click.echo("\n".join(aligned(rows)))
    click.echo(report.summary(), err=True)


@click.command(
    epilog=exit_status(
        passed="every oracle passed",
        failed="an oracle failed",
        bad_input="bad input: no oracles yet, an unknown or ambiguous run, a spec error, a bad bag",
        inconclusive="an oracle could not be judged (its data missing or cut short), and none failed",
    )
)
@click.argument("runs", nargs=-1, required=True)
@click.option(
    "--scenario",
    "spec",
    required=True,
    type=click.Path(dir_okay=False),
    help="The .exsce file of the scenario the runs are of.",
)
@click.option("--scenario-id", help="Which scenario, when the file declares several.")
@click.option("--json", "as_json", is_flag=True, help="Print the verdicts as JSON.")
@click.option("--junit", type=click.Path(dir_okay=False), help="Also write a JUnit XML report to this file.")
@click.option("--no-record", is_flag=True, help="Do not write the verdicts to the store.")
@store_option
@reports_errors
def verify(
    runs: tuple[str, ...],
    spec: str,
    scenario_id: str | None,
    as_json: bool,
    junit: str | None,
    no_record: bool,
    store_url: str | None,
) -> None:
    """Judge runs against every oracle of their scenario.

    RUNS are stored runs (their uuids, or any unique prefix of one of 4
    characters or more, such as the 8 that the verdict table prints, or a
    run's IRI) or bag files, which are ingested first.  For each oracle: the
    value observed, the expectation, the margin and the verdict, and the runs
    the expectation came from.  The verdicts are written to the store as
    provenance.  A run the scenario's baseline was built from is judged with
    a warning: it is part of the mean it is compared with.  Exits 0 when
    every oracle passed, 1 when one failed, 3 when one could not be judged
    (and none failed), 2 when nothing could be judged (bad input: below).

    \b
    Example:
      exscec verify runs/*.bag --scenario examples/brsu_building_c/scenario_c.exsce --junit verdicts.xml
      exscec verify runs/faulty/*.bag --scenario examples/brsu_building_c/scenario_c.exsce  # exits 1
    """
    from exsce_dsl.lang.build import load_spec
    from exsce_dsl.oracles.workflows import IngestFailed, verify_runs
    from exsce_dsl.store.open import open_store

    scenario = load_spec(spec).scenario(scenario_id)
    bags: list[str | Path] = [Path(r) for r in bag_arguments(runs) if Path(r).exists()]  # files, bag folders
    uuids: list[str | Path] = [r for r in runs if not Path(r).exists()]
    with open_store(store_url) as store:
        try:
            verification = verify_runs(store, scenario, [*uuids, *bags], record=not no_record)
        except IngestFailed as exc:
            click.echo(f"error: {exc.message}", err=True)
            sys.exit(ExitCode.BAD_INPUT)
    sys.exit(report_verification(verification, as_json, junit))


def report_verification(verification: Verification, as_json: bool, junit: str | None) -> ExitCode:
    """Print the verdicts (a table, or JSON), write the JUnit report, count them on stderr; the
    exit status they give: 1 if one failed, 3 if one was not judged (and none failed), else 0."""
    from exsce_dsl.model.verdicts import Outcome
    from exsce_dsl.oracles.report import junit_xml, verdict_table, verdicts_json

    verdicts = list(verification.verdicts)
    for warning in verification.warnings:
        click.echo(f"warning: {warning}", err=True)
    click.echo(verdicts_json(verdicts) if as_json else verdict_table(verdicts))
    if junit:
        write_text(junit_xml(verdicts), junit)
    failed = sum(v.outcome is Outcome.FAILED for v in verdicts)
    inconclusive = sum(v.outcome is Outcome.INCONCLUSIVE for v in verdicts)
    click.echo(
        f"{len(verdicts) - failed - inconclusive} passed, {failed} failed, {inconclusive} inconclusive",
        err=True,
    )
    return ExitCode.FAILED if failed else ExitCode.INCONCLUSIVE if inconclusive else ExitCode.PASSED


COMMANDS = [baseline, verify]
