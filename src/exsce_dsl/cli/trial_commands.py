"""``exscec flaky``, and what every command that judges a trial shares (``verify --trial``,
``verify --repeat``, ``execute --runs N --verify``): the options, the table, the exit status."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import click

from exsce_dsl.cli.common import ExitCode, exit_status, reports_errors, write_text
from exsce_dsl.cli.query_commands import format_option, output_option
from exsce_dsl.cli.store_commands import store_option

if TYPE_CHECKING:
    from exsce_dsl.model.trials import ClauseTrial, Trial

REQUIRED_PASS_RATE = 0.8  # oracles.trials.REQUIRED_PASS_RATE, spelled here so that --help imports nothing
CONFIDENCE = 0.95  # oracles.trials.CONFIDENCE

TRIAL_OUTCOMES = (
    "A clause is passed when the Wilson interval of its pass rate (over the runs judged; "
    "inconclusive runs left out) lies at or above the required pass rate, failed when it lies "
    "below, flaky when it straddles it and runs both passed and failed, and inconclusive when it "
    "straddles it with runs that all agree (too few runs: the table says how many would do) or "
    "when no run could be judged."
)
"""What a clause's trial outcome means, for the --help of the commands that judge trials."""


def trial_options(func: Any) -> Any:
    """``--required-pass-rate`` and ``--confidence``, passed as ``required_pass_rate`` and
    ``confidence``."""
    func = click.option(
        "--confidence",
        type=click.FloatRange(0, 1, min_open=True, max_open=True),
        default=CONFIDENCE,
        show_default=True,
        metavar="LEVEL",
        help="The confidence of the pass rates' Wilson intervals.",
    )(func)
    return click.option(
        "--required-pass-rate",
        type=click.FloatRange(0, 1, min_open=True, max_open=True),
        default=REQUIRED_PASS_RATE,
        show_default=True,
        metavar="RATE",
        help="The pass rate each clause must be shown to reach over a trial's runs (0.8: four runs "
        "in five; 16 runs that all pass show it at 95 % confidence).",
    )(func)


def trial_exit(trial: Trial) -> ExitCode:
    """0 every clause passed, 1 one failed or is flaky, 3 one is inconclusive (none failed)."""
    from exsce_dsl.model.trials import TrialOutcome

    return {
        TrialOutcome.PASSED: ExitCode.PASSED,
        TrialOutcome.FAILED: ExitCode.FAILED,
        TrialOutcome.FLAKY: ExitCode.FAILED,
        TrialOutcome.INCONCLUSIVE: ExitCode.INCONCLUSIVE,
    }[trial.outcome]


def report_trial(trial: Trial, as_json: bool, junit: str | None) -> ExitCode:
    """Print the trial's pass-rate table (or JSON), write its JUnit report, count the clauses on
    stderr; the exit status they give (:func:`trial_exit`)."""
    from exsce_dsl.api import counted, pass_rate_table, pass_rates_json, percent, trial_junit_xml
    from exsce_dsl.model.trials import TrialOutcome

    for warning in trial.warnings:
        click.echo(f"warning: {warning}", err=True)
    click.echo(pass_rates_json(trial.clauses) if as_json else pass_rate_table(trial.clauses), nl=not as_json)
    if junit:
        write_text(trial_junit_xml(trial.clauses, len(trial.runs)), junit)
    counts = ", ".join(f"{trial.count(o)} {o.value}" for o in TrialOutcome)
    click.echo(
        f"trial of {counted(len(trial.runs), 'run')}: {counted(len(trial.clauses), 'clause')}: {counts} "
        f"(required pass rate {trial.required_pass_rate:g}, {percent(trial.confidence)} intervals)",
        err=True,
    )
    return trial_exit(trial)


def _render(clauses: Sequence[ClauseTrial], fmt: str) -> str:
    from exsce_dsl.api import pass_rate_table, pass_rates_csv, pass_rates_json

    if fmt == "json":
        return pass_rates_json(clauses)
    if fmt == "csv":
        return pass_rates_csv(clauses)
    return pass_rate_table(clauses, show_scenario=True) + "\n"


@click.command(epilog=exit_status(bad_input="a scenario the store does not hold, or bad input"))
@click.argument("scenario", required=False)
@trial_options
@format_option
@output_option
@store_option
@reports_errors
def flaky(
    scenario: str | None,
    required_pass_rate: float,
    confidence: float,
    fmt: str,
    output: str | None,
    store_url: str | None,
) -> None:
    """List the clauses of SCENARIO (of every scenario without one) by pass rate, lowest first.

    The pass rates are over the verdicts the store holds: each run's last
    validation (exscec verify, execute --verify, explore).  Per clause: the
    runs that passed, failed and could not be judged, the pass rate over the
    judged ones with its Wilson interval, and the outcome.  A flaky clause is
    a test that cannot be trusted to pass: fix the system, or the clause's
    tolerance.  The listing exits 0 whatever the outcomes (verify --trial
    judges them).

    \b
    Example:
      exscec flaky scenario_c
      exscec flaky --format csv --required-pass-rate 0.9 -o pass_rates.csv
    """
    from exsce_dsl.api import flaky as stored_pass_rates
    from exsce_dsl.api import open_store

    with open_store(store_url) as store:
        clauses = stored_pass_rates(
            store, scenario, required_pass_rate=required_pass_rate, confidence=confidence
        )
    write_text(_render(clauses, fmt), output)
    if not clauses:
        click.echo(f"no verdicts stored{f' of {scenario}' if scenario else ''} (exscec verify)", err=True)
    elif fmt == "table" and output is None:
        runs = len({run for c in clauses for run in c.runs})
        click.echo(f"{len(clauses)} clauses over {runs} judged runs", err=True)


COMMANDS = [flaky]
