"""``exscec``: the command line, a thin click layer over the library.

The group lives here; each family of commands is a module of its own, whose
``COMMANDS`` the group lists in :data:`COMMAND_MODULES`.  A module is imported
when one of its commands runs (or ``--help`` lists them all), not for every
command: ``exscec ingest`` does not pay for the imports of ``exscec report``.
"""

from __future__ import annotations

import importlib
import os
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TextIO

import click

from exsce_dsl.api import __version__
from exsce_dsl.cli.common import State, exit_status_table

COMMAND_MODULES: dict[str, str] = {
    "check": "spec_commands",
    "compile": "spec_commands",
    "fmt": "spec_commands",
    "import": "spec_commands",
    "export": "spec_commands",
    "simulate": "run_commands",
    "ingest": "run_commands",
    "execute": "execute_commands",
    "bag": "bag_commands",
    "init": "bag_commands",
    "store": "store_commands",
    "serve": "store_commands",
    "query": "query_commands",
    "sparql": "query_commands",
    "runs": "query_commands",
    "explain": "query_commands",
    "baseline": "oracle_commands",
    "verify": "oracle_commands",
    "flaky": "trial_commands",
    "derive": "derive_commands",
    "lineage": "derive_commands",
    "expect": "derive_commands",
    "explore": "explore_commands",
    "stand-in": "stand_in_commands",
    "cluster": "similarity_commands",
    "report": "report_commands",
    "generate": "generate_commands",
    "demo": "demo_commands",
    "lsp": "lsp_commands",
    "mcp": "mcp_commands",
}
"""Each command of ``exscec`` and the module of ``exsce_dsl.cli`` whose ``COMMANDS`` holds it."""


class LazyGroup(click.Group):
    """A group whose commands are imported when they are used (click's lazy loading)."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(set(COMMAND_MODULES) | set(self.commands))

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands and cmd_name in COMMAND_MODULES:
            module = importlib.import_module(f"exsce_dsl.cli.{COMMAND_MODULES[cmd_name]}")
            for command in module.COMMANDS:
                self.add_command(command)
        return self.commands.get(cmd_name)


@click.group(
    cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]}, epilog=exit_status_table()
)
@click.version_option(__version__, prog_name="exscec")
@click.option("--debug", is_flag=True, help="Show Python tracebacks for errors.")
@click.option(
    "--timings",
    is_flag=True,
    help="At the command's end, print to stderr each store query it ran: how many times, total and "
    "longest time, rows; the slowest first (see which question is slow on your store).",
)
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
def main(debug: bool, timings: bool, msg_paths: tuple[str, ...]) -> None:
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

    `exscec --timings CMD` prints, at CMD's end, the time of each store query
    it ran.

    \b
    Example:
      exscec check examples/brsu_building_c
      exscec compile examples/brsu_building_c/scenario_c.exsce -f provn
    """
    State.debug = debug
    if timings:
        click.get_current_context().with_resource(_printed_timings())
    if warnings.showwarning is not _show_warning:
        warnings.showwarning = _show_warning
    if msg_paths:  # in the environment, so that worker processes see them too
        from exsce_dsl.api import MSG_PATH

        folders = [os.path.abspath(p) for p in msg_paths]
        os.environ[MSG_PATH] = os.pathsep.join([*folders, *filter(None, [os.environ.get(MSG_PATH)])])


@contextmanager
def _printed_timings() -> Iterator[None]:
    """Time the store queries of the command, and print them to stderr at its end (also when it fails)."""
    from exsce_dsl.api import timing_queries

    with timing_queries() as times:
        try:
            yield
        finally:
            if times.calls:
                click.echo("timings: the store queries of this command, slowest first", err=True)
                for line in times.lines():
                    click.echo(f"  {line}", err=True)
            else:
                click.echo("timings: no store query", err=True)


_python_show_warning = warnings.showwarning


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: TextIO | None = None,
    line: str | None = None,
) -> None:
    """exsce's own warnings (an untrusted cache folder) as ``warning: ...`` lines; others as Python
    shows them."""
    from exsce_dsl.errors import CacheWarning

    if issubclass(category, CacheWarning):
        click.echo(f"warning: {message}", err=True)
    else:
        _python_show_warning(message, category, filename, lineno, file, line)
