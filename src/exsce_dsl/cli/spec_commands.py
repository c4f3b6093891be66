"""Commands on specifications: check, compile, fmt, import, export."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from exsce_dsl.cli.common import (
    ExitCode,
    exit_status,
    print_diagnostics,
    reports_errors,
    spec_files,
    write_text,
)

PROV_FORMATS = ("provn", "json", "xml", "ttl", "trig", "nq", "jsonld")


@click.command(epilog=exit_status(bad_input="a file has errors (or cannot be read)"))
@click.argument("specs", nargs=-1, required=True, type=click.Path())
@reports_errors
def check(specs: tuple[str, ...]) -> None:
    """Parse and check SPEC files; report every error found, not only the first.

    A folder stands for the .exsce files below it (recursively, in sorted
    order).  After the language's own checks pass, each scenario is compiled
    and its PROV-O validated against exsce's SHACL shapes; a violation is
    reported at the DSL element it concerns.

    \b
    Example:
      exscec check examples/brsu_building_c/scenario_c.exsce
      exscec check examples      # every .exsce file below the folder
    """
    from exsce_dsl.api import check as check_spec

    failed = False
    for spec in spec_files(specs):
        checked = check_spec(spec)
        print_diagnostics(list(checked.diagnostics))
        errors = len(checked.errors)
        if not checked.ok or checked.spec is None:
            failed = True
            click.echo(f"{spec}: {errors} error{'s' if errors != 1 else ''}", err=True)
        else:
            n = len(checked.spec.scenarios)
            click.echo(f"{spec}: ok ({n} scenario{'s' if n != 1 else ''})", err=True)
    if failed:
        sys.exit(ExitCode.BAD_INPUT)


@click.command(name="compile")
@click.argument("spec", type=click.Path(dir_okay=False))
@click.option(
    "-f",
    "--format",
    "fmt",
    type=click.Choice(PROV_FORMATS),
    default="provn",
    show_default=True,
    help="PROV-N, PROV-JSON, PROV-XML, or PROV-O as Turtle, TriG, N-Quads or JSON-LD.",
)
@click.option(
    "-o",
    "--output",
    type=click.Path(dir_okay=False, writable=True),
    help="Write here instead of stdout.",
)
@click.option("--scenario", "scenario_id", help="Which scenario, when the file declares several.")
@click.option(
    "--store",
    "store_url",
    is_flag=False,
    flag_value="",
    default=None,
    metavar="[URL]",
    help="Also add the scenario to the store (alone: the default store, $EXSCE_STORE or .exsce/store); "
    "then PROV is printed only with -f or -o.",
)
@click.option("--replace", is_flag=True, help="With --store: replace a changed scenario, keeping a revision.")
@reports_errors
def compile_command(
    spec: str, fmt: str, output: str | None, scenario_id: str | None, store_url: str | None, replace: bool
) -> None:
    """Compile a scenario to W3C PROV (bundles per scenario, environment, area, robot and task).

    \b
    Example:
      exscec compile examples/brsu_building_c/scenario_c.exsce -f json -o scenario_c.prov.json
      exscec compile examples/brsu_building_c/scenario_c.exsce --store
    """
    from exsce_dsl.api import compile_prov, load, prov_text

    document = compile_prov(load(spec), scenario_id)
    assert not isinstance(document, str)  # a document: no format given
    if store_url is not None:
        from exsce_dsl.cli.store_commands import add_to_store

        add_to_store(document, store_url or None, replace)
        fmt_given = (
            click.get_current_context().get_parameter_source("fmt") != click.core.ParameterSource.DEFAULT
        )
        if output is None and not fmt_given:
            return
    elif replace:
        raise click.UsageError("--replace goes with --store")
    text = prov_text(document, fmt)
    write_text(text, output)


@click.command(epilog=exit_status(failed="--check: a file would change (as black exits)"))
@click.argument("specs", nargs=-1, required=True, type=click.Path())
@click.option("--check", "check_only", is_flag=True, help="Change nothing; exit 1 if a file would change.")
@click.option(
    "--diff", "show_diff", is_flag=True, help="Print what would change as a unified diff; change nothing."
)
@reports_errors
def fmt(specs: tuple[str, ...], check_only: bool, show_diff: bool) -> None:
    """Rewrite SPEC files in canonical form.

    A folder stands for the .exsce files below it.  The formatter prints the
    checked model, so a file must be valid to be formatted.  Comments stay
    before the element that follows them.

    \b
    Example:
      exscec fmt --check examples     # for CI: fails if a file below examples/ would change
      exscec fmt specs/
    """
    from exsce_dsl.api import format_file

    changed = []
    for spec_path in spec_files(specs):
        formatted = format_file(spec_path)
        if not formatted.changed:
            continue
        changed.append(spec_path)
        if show_diff:
            click.echo(formatted.diff(), nl=False)
        if check_only or show_diff:  # as black does: --diff shows, it does not write
            click.echo(f"would reformat {spec_path}", err=True)
        else:
            formatted.write()
            click.echo(f"reformatted {spec_path}", err=True)
    if check_only and changed:
        sys.exit(ExitCode.FAILED)


@click.command(name="import")
@click.argument("yaml_file", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "-o",
    "--output",
    "out_dir",
    type=click.Path(file_okay=False),
    default=".",
    show_default=True,
    help="Folder to write the .exsce files to (for an oracle file: print unless given).",
)
@click.option(
    "-t",
    "--tasks",
    "task_dirs",
    multiple=True,
    type=click.Path(exists=True, file_okay=False),
    help="Folder to search for the task files the scenario names (repeatable).",
)
@click.option(
    "--spec",
    "spec_path",
    type=click.Path(exists=True, dir_okay=False),
    help="For an oracle file: the spec that declares its scenario.",
)
@click.option("--force", is_flag=True, help="Overwrite existing files.")
@reports_errors
def import_command(
    yaml_file: str, out_dir: str, task_dirs: tuple[str, ...], spec_path: str | None, force: bool
) -> None:
    """Import a scenario in the method's YAML format (with its task files) as .exsce files,
    or an oracle file as the acceptance criteria of its scenario.

    Task files are found by their ROS package and path under each --tasks
    folder (and the scenario's own folder), or by file name.  An oracle file
    (one with a baseline or metamorphic section, such as the method's
    oracles/scenario_c.yaml) needs --spec, the .exsce file of its scenario;
    its criteria are printed, or with -o written to
    <scenario>_acceptance.exsce, which imports the spec.  The example reads
    the files `exscec export --to yaml -o out/` writes.

    \b
    Example:
      exscec import out/scenarios/scenario_c.yaml -t out/config/tasks -o specs/
    """
    from exsce_dsl.api import import_scenario_file, is_oracle_file

    if is_oracle_file(yaml_file):
        _import_oracles(Path(yaml_file), spec_path, out_dir, force)
        return
    if spec_path is not None:
        raise click.UsageError("--spec goes with an oracle file; this is a scenario file")
    for path in import_scenario_file(yaml_file, out_dir, task_dirs, force=force):
        click.echo(f"wrote {path}", err=True)


def _import_oracles(yaml_file: Path, spec_path: str | None, out_dir: str, force: bool) -> None:
    from exsce_dsl.api import import_oracle_file

    if spec_path is None:
        raise click.UsageError(f"{yaml_file} holds oracles: name the spec of its scenario with --spec")
    source = click.get_current_context().get_parameter_source("out_dir")
    printed = source == click.core.ParameterSource.DEFAULT
    imported = import_oracle_file(yaml_file, spec_path, None if printed else out_dir, force=force)
    if isinstance(imported, str):
        click.echo(imported, nl=False)
        return
    for path in imported:
        click.echo(f"wrote {path}", err=True)


@click.command(name="export")
@click.argument("spec", type=click.Path(dir_okay=False))
@click.option(
    "--to",
    "target",
    type=click.Choice(["yaml", "oracle-yaml", "gherkin", "osc2"]),
    default="yaml",
    show_default=True,
    help="The format to write: the method's scenario and task files, its oracle file, Gherkin "
    "features, or a scenario_execution OSC2 scenario.",
)
@click.option(
    "-o",
    "--output",
    "out_dir",
    type=click.Path(),
    default=".",
    show_default=True,
    help="Folder to write to (with --to osc2, a .osc file may be named instead).",
)
@click.option("--scenario", "scenario_id", help="Which scenario, when the file declares several.")
@reports_errors
def export_command(spec: str, target: str, out_dir: str, scenario_id: str | None) -> None:
    """Export a scenario to the method's YAML scenario and task files, its acceptance
    criteria to the method's oracle file (oracles/<scenario>.yaml), the criteria of
    each scenario to Gherkin (<scenario>.feature), or its mission to an OSC2 scenario
    for scenario_execution (<scenario>.osc).

    The OSC2 scenario drives each robot's Nav2 (an actor named by its
    namespace, else by its id): bag_record of the topics the metrics read,
    init_nav2 at the start poses, then follow_waypoints or nav_to_pose per task
    in the mission's order, with the spec's timeouts; its comments name the
    clauses that judge the bag, and the ingest and verify commands to run on
    it.  A scenario id, or a robot id that must name an actor, that is not an
    OSC2 identifier is an error.

    An oracle file holds numbers: a clause that expects the mean of stored runs
    (no 'around' or 'from' value) cannot be written without a baseline, nor can
    a clause about part of a run ('when tiago1 does delivery_a'); scenario_c's
    criteria have both, so its oracle-yaml export fails and says where.

    \b
    Example:
      exscec export examples/brsu_building_c/scenario_c.exsce --to yaml -o out/
      exscec export examples/brsu_building_c/scenario_c.exsce --to gherkin -o features/
      exscec export examples/brsu_building_c/scenario_c.exsce --to oracle-yaml -o out/  # exits 2
      exscec export examples/brsu_building_c/scenario_c.exsce --to osc2 -o scenario_c.osc
    """
    from exsce_dsl.api import export_spec

    if target != "osc2" and Path(out_dir).is_file():
        raise click.BadParameter(f"{out_dir} is a file; --to {target} writes to a folder", param_hint="-o")

    written = export_spec(spec, target, out_dir, scenario_id)
    for path in written:
        click.echo(f"wrote {path}", err=True)


COMMANDS = [check, compile_command, fmt, import_command, export_command]
