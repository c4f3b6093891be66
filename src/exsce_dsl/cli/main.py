"""``exscec``: the command line, a thin click layer over the library.

The group lives here; each family of commands is a module of its own that
adds its commands to :data:`main`.
"""

from __future__ import annotations

import click

from exsce_dsl import __version__
from exsce_dsl.cli.common import State


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="exscec")
@click.option("--debug", is_flag=True, help="Show Python tracebacks for errors.")
def main(debug: bool) -> None:
    """exsce: executable scenarios for robot testing.

    Write scenarios in the exsce language, check them, and compile them to
    W3C PROV.

    \b
    Example:
      exscec check examples/brsu_building_c/scenario_c.exsce
      exscec compile examples/brsu_building_c/scenario_c.exsce -f provn
    """
    State.debug = debug


def _register() -> None:
    from exsce_dsl.cli import (
        demo_commands,
        derive_commands,
        generate_commands,
        lsp_commands,
        oracle_commands,
        query_commands,
        report_commands,
        run_commands,
        similarity_commands,
        spec_commands,
        store_commands,
    )

    for command in [
        *spec_commands.COMMANDS,
        *run_commands.COMMANDS,
        *store_commands.COMMANDS,
        *query_commands.COMMANDS,
        *oracle_commands.COMMANDS,
        *derive_commands.COMMANDS,
        *similarity_commands.COMMANDS,
        *report_commands.COMMANDS,
        *generate_commands.COMMANDS,
        *demo_commands.COMMANDS,
        *lsp_commands.COMMANDS,
    ]:
        main.add_command(command)


_register()
