"""``exscec``: the command line, a thin click layer over the library.

The group lives here; each family of commands is a module of its own that
adds its commands to :data:`main`.
"""

from __future__ import annotations

import os

import click

from exsce_dsl import __version__
from exsce_dsl.cli.common import State


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="exscec")
@click.option("--debug", is_flag=True, help="Show Python tracebacks for errors.")
@click.option(
    "--msg-path",
    "msg_paths",
    multiple=True,
    type=click.Path(exists=True, file_okay=False),
    metavar="DIR",
    help="A folder of your own message definitions (<pkg>/msg/Name.msg, .idl files), searched "
    "before the standard ROS packages; repeatable, the first wins.  Added in front of the "
    "folders of $EXSCE_MSG_PATH (separated by the system's path separator).",
)
def main(debug: bool, msg_paths: tuple[str, ...]) -> None:
    """exsce: executable scenarios for robot testing.

    Write scenarios in the exsce language, check them, and compile them to
    W3C PROV.

    A metric reads any message type of the standard ROS 1 and ROS 2 packages;
    the definitions of other types come from --msg-path, $EXSCE_MSG_PATH, or
    the bag itself.

    `exscec demo` runs the whole method on the shipped example, and
    docs/tutorial.md walks it command by command.  The examples of every
    command's --help run as written, one after the other, in a folder holding
    a copy of the project's examples/ (check, compile, export and import
    first, then simulate, ingest, baseline, verify, derive, the queries...).

    \b
    Example:
      exscec check examples/brsu_building_c
      exscec compile examples/brsu_building_c/scenario_c.exsce -f provn
    """
    State.debug = debug
    if msg_paths:  # in the environment, so that worker processes see them too
        from exsce_dsl.messages.user import MSG_PATH

        folders = [os.path.abspath(p) for p in msg_paths]
        os.environ[MSG_PATH] = os.pathsep.join([*folders, *filter(None, [os.environ.get(MSG_PATH)])])


def _register() -> None:
    from exsce_dsl.cli import (
        demo_commands,
        derive_commands,
        explore_commands,
        generate_commands,
        lsp_commands,
        mcp_commands,
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
        *explore_commands.COMMANDS,
        *similarity_commands.COMMANDS,
        *report_commands.COMMANDS,
        *generate_commands.COMMANDS,
        *demo_commands.COMMANDS,
        *lsp_commands.COMMANDS,
        *mcp_commands.COMMANDS,
    ]:
        main.add_command(command)


_register()
