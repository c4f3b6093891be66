"""``exscec derive``: a new scenario from a base one by input transformations."""

from __future__ import annotations

from pathlib import Path

import click

from exsce_dsl.cli.common import REMEDIES, all_runs_option, reports_errors
from exsce_dsl.cli.store_commands import store_option


def _requests(words: tuple[str, ...]) -> list[tuple[str, dict[str, str]]]:
    """``-t remove_robot --robot tiago2 --reassign tiago1 -t ...`` → steps with their arguments."""
    steps: list[tuple[str, dict[str, str]]] = []
    rest = list(words)
    while rest:
        word = rest.pop(0)
        if word in ("-t", "--transform"):
            if not rest:
                raise click.UsageError(f"{word} needs a transformation name")
            steps.append((rest.pop(0), {}))
        elif word.startswith("--") and len(word) > 2:
            if not steps:
                raise click.UsageError(f"{word} comes before any -t TRANSFORMATION")
            key, _, value = word[2:].partition("=")
            if not value:
                if not rest:
                    raise click.UsageError(f"{word} needs a value")
                value = rest.pop(0)
            steps[-1][1][key.replace("-", "_")] = value
        else:
            raise click.UsageError(
                f"unexpected '{word}' (arguments are --name value, after -t TRANSFORMATION)"
            )
    return steps


@click.command(context_settings={"ignore_unknown_options": True})
@click.argument("spec", type=click.Path(dir_okay=False, exists=True))
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Write the new .exsce file here.")
@click.option("--id", "new_id", help="The new scenario's id (default: the base's and a digest of the steps).")
@click.option("--scenario-id", help="The base scenario, when the file declares several.")
@click.option("--list", "list_them", is_flag=True, help="List the transformations and their arguments.")
@click.option(
    "--add-to-store", is_flag=True, help="Also add the new scenario and its generation PROV to the store."
)
@click.option(
    "--expect",
    "with_expectations",
    is_flag=True,
    help="Write acceptance criteria for the new scenario: the base's safety clauses, and the "
    "performance relations its expected values imply (see exscec expect), from the store; with "
    "--add-to-store its oracles go to the store too.",
)
@click.option(
    "--tolerance",
    type=click.FloatRange(min=0, min_open=True),
    default=10.0,
    show_default=True,
    help="With --expect: how far from the expected change a run may be, in percent of that change.",
)
@all_runs_option
@store_option
@click.argument("steps", nargs=-1, type=click.UNPROCESSED)
@reports_errors
def derive(
    spec: str,
    output: str | None,
    new_id: str | None,
    scenario_id: str | None,
    list_them: bool,
    add_to_store: bool,
    with_expectations: bool,
    tolerance: float,
    include_all: bool,
    store_url: str | None,
    steps: tuple[str, ...],
) -> None:
    """Derive a scenario from SPEC's by input transformations, applied in order.

    Prints (or writes with -o) a formatted .exsce file that imports SPEC and
    declares the new scenario and any task a transformation made (or, when the
    environment changed, e.g. an obstacle moved, a `derive NEW from BASE {...}`
    block that makes them); it checks clean.  --add-to-store adds the new
    scenario and its generation provenance (the method's shape: one activity
    per step) to the store.  --expect writes
    the new scenario's acceptance criteria from the stored runs (the base's
    safety clauses; distance and duration increasing, decreasing or invariant
    against the base's runs, by the change its expected values imply), from
    good runs only: a run that failed or was inconclusive when last verified,
    whose mission was cancelled or stopped or that broke a safety limit is
    left out, unless --all-runs.

    \b
    Example:
      exscec derive examples/brsu_building_c/scenario_c.exsce \\
          -t remove_robot --robot tiago2 --reassign tiago1 \\
          -t reverse_waypoint_order --task delivery_a -o scenario_c_alone.exsce
      exscec derive examples/brsu_building_c/scenario_c.exsce --id c_one \\
          -t remove_robot --robot tiago2 --reassign tiago1 -o c_one.exsce --expect --add-to-store
    """
    from exsce_dsl.api import TRANSFORMATIONS, add_derived, counted, load, open_store
    from exsce_dsl.api import derive as derive_spec

    if list_them:
        for t in TRANSFORMATIONS.values():
            arguments = " ".join([f"--{a} X" for a in t.required] + [f"[--{a} X]" for a in t.optional])
            click.echo(f"{t.name} {arguments}\n    {t.help}")
        return
    loaded, requests = load(spec), _requests(steps)
    if with_expectations:
        with open_store(store_url) as store:
            made = derive_spec(
                loaded, requests, new_id=new_id, scenario=scenario_id, target=output,
                expect_from=store, tolerance=tolerance, include_all=include_all, source=spec,
            )  # fmt: skip
        for note in made.notes:
            click.echo(f"note: {note}", err=True)
        if made.criteria is None:
            click.echo(
                "no acceptance criteria: neither safety clauses to copy nor runs to expect from", err=True
            )
    else:
        made = derive_spec(loaded, requests, new_id=new_id, scenario=scenario_id, target=output, source=spec)
    if output:
        Path(output).write_text(made.text, encoding="utf-8")
        load(output)  # what we wrote must check clean
        click.echo(f"wrote {output}: scenario {made.scenario.id}", err=True)
    else:
        click.echo(made.text, nl=False)
    if add_to_store:
        with open_store(store_url) as store:
            stored = add_derived(store, made, include_all=include_all)
        click.echo(stored.scenario.summary(), err=True)
        click.echo(stored.generation.summary(), err=True)
        if stored.oracles_written is not None:
            oracles = counted(len(stored.oracles), "oracle")
            click.echo(f"{oracles}: {stored.oracles_written.summary()}", err=True)


@click.command()
@click.argument("scenario")
@store_option
@reports_errors
def lineage(scenario: str, store_url: str | None) -> None:
    """Print where a scenario or a run comes from.

    For a scenario: its ancestors first (each with the transformations that
    made the next), then the scenario, then its descendants as a tree, from the
    derivation provenance in the store.

    For a run (its uuid or a prefix of it, or the id its dispatcher gave it, as
    `exscec simulate` and `execute` print it): the chain from dispatch to
    verdict: scenario and derivations, the dispatcher's execution (the goals it
    sent and their outcomes), the bag, each value with its window and samples,
    the verdicts and the baseline runs they used.

    \b
    Example:
      exscec lineage c_one
    """
    from exsce_dsl.api import lineage_of, open_store

    with open_store(store_url) as store:
        click.echo(lineage_of(store, scenario).text(REMEDIES))


@click.command()
@click.argument("spec", type=click.Path(dir_okay=False, exists=True))
@click.option("--scenario-id", help="Which scenario, when the file declares several.")
@all_runs_option
@store_option
@reports_errors
def expect(spec: str, scenario_id: str | None, include_all: bool, store_url: str | None) -> None:
    """Show a scenario's expected distance travelled and task duration per robot, and where each
    value comes from: the path segments, observed in good stored runs (of any scenario; every
    run with --all-runs) or estimated from segments near them, with the number of runs.

    \b
    Example:
      exscec expect c_one.exsce
      exscec expect examples/brsu_building_c/scenario_c_alone.exsce
    """
    from exsce_dsl.api import expect as expected_values
    from exsce_dsl.api import load, open_store

    scenario = load(spec).scenario(scenario_id)
    with open_store(store_url) as store:
        for found in expected_values(store, scenario, include_all=include_all):
            shown = f"{found.value:.4g}" if found.value is not None else "unknown"
            click.echo(f"{found.robot} {found.metric}: {shown}")
            for part in found.segments:
                value = f"{part.value:.4g}" if part.value is not None else "-"
                runs = f" ({part.runs} runs)" if part.runs else ""
                click.echo(f"  {part.start} → {part.goal}: {value}  {part.how}{runs}")


COMMANDS = [derive, lineage, expect]
