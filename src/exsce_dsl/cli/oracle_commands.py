"""``exscec baseline`` and ``exscec verify``: oracles from stored runs, and verdicts on runs."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from exsce_dsl.cli.common import (
    ExitCode,
    all_runs_option,
    bag_arguments,
    exit_status,
    reports_errors,
    said_with_options,
    write_text,
)
from exsce_dsl.cli.store_commands import store_option
from exsce_dsl.cli.trial_commands import trial_options

if TYPE_CHECKING:
    from exsce_dsl.api import Store, Verification
    from exsce_dsl.model import Scenario
    from exsce_dsl.model.trials import Trial


@click.command(epilog=exit_status(bad_input="bad input: a spec error, too few runs, no acceptance criteria"))
@click.argument("spec", type=click.Path(dir_okay=False))
@click.option("--scenario-id", help="Which scenario, when the file declares several.")
@all_runs_option
@store_option
@reports_errors
def baseline(spec: str, scenario_id: str | None, include_all: bool, store_url: str | None) -> None:
    """Build the oracles of a scenario from its acceptance criteria and its good stored runs.

    Each clause becomes an oracle per robot it is about; the value a
    performance clause compares with is the mean of the metric over the good
    stored runs (tolerance: as written, else one standard deviation).  A run
    is left out when its last verification failed or was inconclusive, its
    mission was cancelled or stopped, or it broke a safety limit (--all-runs
    keeps every run); the runs used and those left out, with why, are printed
    and go to the oracles' provenance.  The oracles are written to the store
    (the previous ones are kept as a revision) and shown.  Refuses while the
    scenario has fewer good runs than its criteria ask ('given at least N
    baseline runs', 3 if not said).

    \b
    Example:
      exscec baseline examples/brsu_building_c/scenario_c.exsce
      exscec baseline examples/brsu_building_c/scenario_c.exsce --all-runs
    """
    from exsce_dsl.api import aligned, load, open_store
    from exsce_dsl.api import baseline as build_baseline

    with open_store(store_url) as store:
        built = build_baseline(store, load(spec), scenario_id, include_all=include_all)
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
    for whose, chosen in built.runs.items():
        of = "" if whose == scenario.id else f" (runs of {whose})"
        every = " (every stored run: --all-runs)" if include_all else ""
        click.echo(f"{chosen.summary()}{every}{of}", err=True)
    click.echo(report.summary(), err=True)


@dataclass(frozen=True)
class _VerifyOptions:
    """``exscec verify``'s arguments and options, as click gives them."""

    runs: tuple[str, ...]
    spec: str
    scenario_id: str | None
    trial: bool
    repeat: int | None
    seed: int | None
    faults: tuple[str, ...]
    out_dir: str | None
    required_pass_rate: float
    confidence: float
    as_json: bool
    junit: str | None
    no_record: bool
    store_url: str | None


@click.command(
    epilog=exit_status(
        passed="every oracle passed (a trial: every clause passed)",
        failed="an oracle failed (a trial: a clause failed or is flaky)",
        bad_input="bad input: no oracles yet, an unknown or ambiguous run, a spec error, a bad bag",
        inconclusive="an oracle was inconclusive (the recording does not cover its data: missing, cut "
        "short, with gaps, too sparse; a trial: too few runs to tell), and none failed",
    )
)
@click.argument("runs", nargs=-1)
@click.option(
    "--scenario",
    "spec",
    required=True,
    type=click.Path(dir_okay=False),
    help="The .exsce file of the scenario the runs are of.",
)
@click.option("--scenario-id", help="Which scenario, when the file declares several.")
@click.option("--trial", is_flag=True, help="Judge the runs as one trial: a pass rate per clause.")
@click.option(
    "--repeat",
    type=click.IntRange(1),
    metavar="N",
    help="Play N new runs with the kinematic executor (as exscec simulate) and judge them, with "
    "RUNS if given, as one trial.",
)
@click.option(
    "--seed",
    type=int,
    metavar="S",
    help="With --repeat: the runs' seed, as simulate's [default: 1, not simulate's 0, whose runs "
    "usually made the baseline].",
)
@click.option(
    "--fault",
    "faults",
    multiple=True,
    metavar="NAME[:ARGS]",
    help="With --repeat: a fault planted in every new run, as simulate's --fault (repeatable).",
)
@click.option(
    "-o",
    "--output",
    "out_dir",
    type=click.Path(file_okay=False),
    help="With --repeat: the folder for the new runs' bags [default: runs/repeat].",
)
@trial_options
@click.option("--json", "as_json", is_flag=True, help="Print the verdicts (a trial: the clauses) as JSON.")
@click.option("--junit", type=click.Path(dir_okay=False), help="Also write a JUnit XML report to this file.")
@click.option("--no-record", is_flag=True, help="Do not write the verdicts to the store.")
@store_option
@reports_errors
def verify(**given: Any) -> None:
    """Judge runs against every oracle of their scenario.

    RUNS are stored runs (their uuids, or any unique prefix of one of 4
    characters or more, such as the 8 that the verdict table prints, or a
    run's IRI) or bag files, which are ingested first.  For each oracle: the
    value observed, the expectation, the margin and the verdict, and the runs
    the expectation came from.  The verdicts are written to the store as
    provenance.  A run the scenario's baseline was built from is judged with
    a warning: it is part of the mean it is compared with.

    A verdict is passed, failed or inconclusive: a clause whose data the
    recording does not cover (missing, the run cut short, a gap in a topic
    it reads, a topic far below its rate) is inconclusive, never passed; a
    limit broken in what was recorded still fails.  The table says why, the
    JUnit report has it as <skipped message="inconclusive: ...">.  Exits 0
    when every oracle passed, 1 when one failed, 3 when one was inconclusive
    (and none failed), 2 on bad input (nothing judged).

    With --trial, or --repeat N (N new runs of the kinematic executor), the
    runs are one trial: each run is judged and recorded as above, and each
    clause gets the runs that passed, failed and were inconclusive, its pass
    rate over the judged runs with a Wilson interval at --confidence, and an
    outcome against --required-pass-rate.  A clause is passed when the
    interval lies at or above the required rate, failed when below, flaky
    when it straddles it and runs both passed and failed: a flaky clause is a
    test that cannot be trusted to pass, and fails the trial (exit 1), as a
    failed one does.  Inconclusive (exit 3, when none failed or is flaky):
    the runs all agree but are too few (the table says how many would do),
    or none could be judged.

    \b
    Example:
      exscec verify runs/*.bag --scenario examples/brsu_building_c/scenario_c.exsce --junit verdicts.xml
      exscec verify runs/faulty/*.bag --scenario examples/brsu_building_c/scenario_c.exsce  # exits 1
      exscec verify runs/*.bag runs/faulty/*.bag --scenario examples/brsu_building_c/scenario_c.exsce \\
          --trial --junit trial.xml  # exits 1: tiago1's max_velocity passed 3 runs of 4, flaky
      exscec verify --scenario examples/brsu_building_c/scenario_c.exsce --repeat 2 --seed 7 \\
          --required-pass-rate 0.5 --confidence 0.9  # exits 3: 2 runs are too few
    """
    from exsce_dsl.api import IngestFailed, load, open_store
    from exsce_dsl.api import verify as verify_runs
    from exsce_dsl.cli.trial_commands import report_trial

    options = _VerifyOptions(**given)
    _check_runs_given(options)
    scenario = load(options.spec).scenario(options.scenario_id)
    runs = options.runs
    bags: list[str | Path] = [Path(r) for r in bag_arguments(runs) if Path(r).exists()]  # files, bag folders
    uuids: list[str | Path] = [r for r in runs if not Path(r).exists()]
    with open_store(options.store_url) as store:
        try:
            if options.trial or options.repeat is not None:
                judged = _verify_trial(store, scenario, [*uuids, *bags], options)
                sys.exit(report_trial(judged, options.as_json, options.junit))
            verification = verify_runs(store, scenario, [*uuids, *bags], record=not options.no_record)
        except IngestFailed as exc:
            click.echo(f"error: {said_with_options(exc)}", err=True)
            sys.exit(ExitCode.BAD_INPUT)
    sys.exit(report_verification(verification, options.as_json, options.junit))


def _check_runs_given(options: _VerifyOptions) -> None:
    """Runs to judge, or --repeat N; and --seed, --fault and --output only with --repeat."""
    if not options.runs and options.repeat is None:
        context = click.get_current_context()
        (argument,) = [p for p in context.command.params if p.name == "runs"]
        raise click.MissingParameter(
            "Give the runs to judge (stored runs or bags), or --repeat N.", context, argument
        )
    if options.repeat is None and (options.seed is not None or options.faults or options.out_dir is not None):
        raise click.UsageError("--seed, --fault and --output are for the runs of --repeat N")


def _verify_trial(store: Store, scenario: Scenario, runs: list[str | Path], options: _VerifyOptions) -> Trial:
    """The runs (and --repeat N new ones) judged as one trial."""
    from exsce_dsl.api import REPEAT_FOLDER, REPEAT_SEED, verify_trial

    return verify_trial(
        store,
        scenario,
        runs,
        repeat=options.repeat or 0,
        out_dir=options.out_dir or REPEAT_FOLDER,
        seed=REPEAT_SEED if options.seed is None else options.seed,
        faults=options.faults,
        record=not options.no_record,
        required_pass_rate=options.required_pass_rate,
        confidence=options.confidence,
    )


def report_verification(verification: Verification, as_json: bool, junit: str | None) -> ExitCode:
    """Print the verdicts (a table, or JSON), write the JUnit report, count them on stderr; the
    exit status they give: 1 if one failed, 3 if one was inconclusive (and none failed), else 0."""
    from exsce_dsl.api import junit_xml, verdict_table, verdicts_json
    from exsce_dsl.model.verdicts import Outcome

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
