"""``exscec generate TARGET``: the code generators, one subcommand per entry of the target registry."""

from __future__ import annotations

import click

from exsce_dsl.api import TARGETS, GenerationTarget
from exsce_dsl.cli.common import reports_errors

EXAMPLE_SPEC = "examples/brsu_building_c/scenario_c.exsce"


class _TargetGroup(click.Group):
    """Lists the targets with their whole descriptions (click would cut them to one short line)."""

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(name, TARGETS[name].description) for name in self.list_commands(ctx) if name in TARGETS]
        if rows:
            with formatter.section("Targets"):
                formatter.write_dl(rows)

    def resolve_command(
        self, ctx: click.Context, args: list[str]
    ) -> tuple[str | None, click.Command | None, list[str]]:
        name = args[0] if args else ""
        if name and not name.startswith("-") and self.get_command(ctx, name) is None:
            ctx.fail(f"unknown target '{name}'; the targets are {', '.join(self.list_commands(ctx))}")
        return super().resolve_command(ctx, args)


@click.group(cls=_TargetGroup, subcommand_metavar="TARGET SPEC -o DIR [--scenario ID] [--force]")
def generate() -> None:
    """Generate files from a scenario: monitors, runtime monitor nodes, dispatcher configuration.

    Each target writes its files below the folder given with -o and refuses
    to replace files that exist unless told with --force.  It never writes
    through a symbolic link inside that folder, and writes nothing when a
    file it made would not read back in its language (Python, YAML, XML,
    CMake): both are errors (exit 2).

    \b
    Example:
      exscec generate dispatcher-config examples/brsu_building_c/scenario_c.exsce -o dispatcher/
    """


def _target_command(target: GenerationTarget) -> click.Command:
    @click.command(
        name=target.name,
        short_help=target.description,
        help=f"Generate {target.description}, for a scenario of SPEC.\n\n"
        f"\b\nExample:\n  exscec generate {target.name} {EXAMPLE_SPEC} -o {target.name}/\n",
    )
    @click.argument("spec", type=click.Path(dir_okay=False))
    @click.option(
        "-o",
        "--output",
        "out_dir",
        required=True,
        type=click.Path(file_okay=False),
        help="Folder for the generated files (made if missing).",
    )
    @click.option(
        "--scenario", "scenario_id", help="Which scenario (needed when SPEC declares more than one)."
    )
    @click.option("--force", is_flag=True, help="Replace files that exist.")
    @reports_errors
    def command(spec: str, out_dir: str, scenario_id: str | None, force: bool) -> None:
        from exsce_dsl.api import generate as generate_files

        for path in generate_files(target.name, spec, out_dir, scenario_id, force=force):
            click.echo(f"wrote {path}", err=True)

    return command


for _target in TARGETS.values():
    generate.add_command(_target_command(_target))

COMMANDS = [generate]
