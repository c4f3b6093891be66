"""What every exscec command shares: error reporting, output."""

from __future__ import annotations

import copy
import functools
import os
import sys
import traceback
from collections import Counter
from collections.abc import Callable, Iterable
from enum import IntEnum
from pathlib import Path
from types import TracebackType
from typing import Any, TypeVar

import click

from exsce_dsl.errors import Diagnostic, ExsceError, ScenarioChoiceError
from exsce_dsl.remedies import (
    ADD_ITS_SPEC,
    ALLOW_FEDERATION,
    ALLOW_THE_HOST,
    ANOTHER_STORE,
    BUILD_A_BASELINE,
    BUILT_IN_OPTIONS,
    CHOOSE_A_CONVENTION,
    CLOSEST_RUNS,
    DEFINE_THE_TYPE,
    FAULTS_NEED_THE_STAND_IN,
    FIX_THE_STORE,
    GIVE_A_RUN_ID,
    GIVE_THE_SPECS,
    INSTALL_DASK,
    INSTALL_IRSIM,
    LEARN_FROM_EVERY_RUN,
    LIST_THE_QUERIES,
    MAKE_A_TOKEN,
    MIGRATE_THE_STORE,
    NO_RUNS_AT_ALL,
    ONE_EXECUTOR,
    POINT_MSG_PATH,
    READ_ONLY,
    REBUILD_THE_BASELINE,
    REPLACE_A_SHARED_ELEMENT,
    REPLACE_A_STORED_RUN,
    REPLACE_A_STORED_SPEC,
    REPLACE_FILES,
    REPLACE_THE_RUN,
    REPLAY_IN_IRSIM,
    REPLAY_IT,
    REPRODUCE_IT,
    ROS1_OPTIONS,
    SELECT_OR_ASK,
    SEND_THE_TOKEN,
    SERVE_A_FOLDER,
    SIMULATE_IT,
    STAND_IN_FOR_FAULTS,
    STAND_IN_ONLY,
    START_A_MASTER,
    STORE_THE_SCENARIO,
    STRICT_STORES_NONE,
    VERIFY_AGAIN,
    VERIFY_THE_RUN,
)

F = TypeVar("F", bound=Callable[..., Any])


class ExitCode(IntEnum):
    """The exit status of every exscec command: one meaning each, whatever the command.

    A command that judges nothing exits 0 or 2 (or 70); ``exscec fmt --check`` exits 1 when a
    file would change, as black does (a check of the files that failed), and ``exscec store
    check`` when the store has something left to mend.
    """

    PASSED = 0
    """Done, and every verdict passed."""
    FAILED = 1
    """A verdict failed: an oracle of ``verify``, a metamorphic relation of ``explore``."""
    BAD_INPUT = 2
    """Bad input or usage: a specification error, a scenario without oracles, an unknown run, a
    bag that cannot be read, a store that cannot be opened, a wrong option (click's own usage
    errors exit 2 too)."""
    INCONCLUSIVE = 3
    """No verdict failed, but one could not be made (the data a clause needs is missing or cut
    short): the run is neither passed nor failed."""
    INTERNAL_ERROR = 70
    """A bug of exsce (``EX_SOFTWARE`` of sysexits.h): an error it did not expect."""
    INTERRUPTED = 130
    """Stopped with Ctrl-C (128 + SIGINT, as shells report it)."""
    BROKEN_PIPE = 141
    """The reader of the output went away (``| head``): 128 + SIGPIPE, as shells report it."""


_MEANINGS = {
    ExitCode.PASSED: "done",
    ExitCode.FAILED: "a verdict failed",
    ExitCode.BAD_INPUT: "bad input or usage (a spec error, no oracles, an unknown run, an unreadable bag)",
    ExitCode.INCONCLUSIVE: "a judgement could not be made (none failed)",
    ExitCode.INTERNAL_ERROR: "an internal error (a bug of exsce: please report it)",
    ExitCode.INTERRUPTED: "interrupted (Ctrl-C)",
    ExitCode.BROKEN_PIPE: "the reader of the output went away (| head)",
}


def exit_status_table() -> str:
    """Every exit status and its meaning: the ``Exit status`` paragraph of ``exscec --help``."""
    lines = [f"  {int(code):<3} {meaning}" for code, meaning in _MEANINGS.items()]
    title = "Exit status, the same in every command (each command's --help says which it uses):"
    return "\b\n" + "\n".join([title, *lines])


def exit_status(**meanings: str) -> str:
    """The ``Exit status`` paragraph of a command's ``--help`` (its epilog): 0, then the codes the
    command uses with what they mean for it (``passed=``, ``failed=``, ``inconclusive=``; each
    code's general meaning when given as ''), then 2 and 70, which every command may exit with."""
    said = {ExitCode[name.upper()]: text for name, text in meanings.items()}
    said.setdefault(ExitCode.PASSED, _MEANINGS[ExitCode.PASSED])
    said.setdefault(ExitCode.BAD_INPUT, "")
    said.setdefault(ExitCode.INTERNAL_ERROR, "")
    lines = [f"  {int(code):<3} {said[code] or _MEANINGS[code]}" for code in sorted(said)]
    return "\b\nExit status (the same codes in every exscec command):\n" + "\n".join(lines)


class State:
    """Options of the group that commands need (set by ``exscec --debug``)."""

    debug = False


SHOWN_DIAGNOSTICS = 100
"""At most this many problems are printed: a file with thousands of errors is fixed from the top."""


def print_diagnostics(diagnostics: Iterable[Diagnostic]) -> None:
    found = list(diagnostics)
    for d in found[:SHOWN_DIAGNOSTICS]:
        click.echo(str(d.said(REMEDIES)), err=True)
    if len(found) > SHOWN_DIAGNOSTICS:
        hidden = Counter(str(d.severity) for d in found[SHOWN_DIAGNOSTICS:])
        total = sum(hidden.values())
        if set(hidden) == {"error"}:  # the usual case
            said = f"{total} more error{'s' if total != 1 else ''}"
        else:  # notes and warnings are not counted as errors
            kinds = ", ".join(f"{n} {kind}{'s' if n != 1 else ''}" for kind, n in sorted(hidden.items()))
            said = f"{total} more ({kinds})"
        click.echo(f"... and {said} (the first {SHOWN_DIAGNOSTICS} are shown)", err=True)


def _scenario_option() -> str:
    """How the running command spells its option that names a scenario (``--scenario`` or
    ``--scenario-id``: ``ingest`` and ``verify`` take the file as ``--scenario``)."""
    context = click.get_current_context(silent=True)
    params = context.command.params if context is not None else []
    spelt = [p.opts[0] for p in params if p.name == "scenario_id" and p.opts]
    return spelt[0] if spelt else "--scenario"


REMEDIES = {
    REPLACE_FILES: "{problem}; use --force to replace",
    MAKE_A_TOKEN: "{problem} (leave --token and EXSCE_STORE_TOKEN unset to have one made)",
    START_A_MASTER: "{problem}: start roscore and export it, or pass --start-master",
    SIMULATE_IT: "{problem} (exscec simulate does)",
    INSTALL_IRSIM: "{problem}: pip install 'exsce[irsim]' (or, in a clone, pip install -e '.[irsim]')",
    CHOOSE_A_CONVENTION: "{problem}; the executor writes one for the whole run: choose it with --convention",
    DEFINE_THE_TYPE: (
        "{problem} (to check them now, give exsce the type's .msg or .idl file: exscec --msg-path DIR, "
        "or EXSCE_MSG_PATH)"
    ),
    POINT_MSG_PATH: "{problem}; point EXSCE_MSG_PATH (or exscec --msg-path) at a folder of message packages",
    REPLACE_THE_RUN: "{problem}; pass --replace to analyse it again under this spec",
    STRICT_STORES_NONE: "{problem}, and --strict stores no run with a missing metric{about}",
    REPLACE_A_STORED_RUN: (
        "{problem}: to analyse the run again and replace it, ingest its bag with replace "
        "(`exscec ingest BAG --scenario SPEC --replace`)"
    ),
    REPLACE_A_STORED_SPEC: (
        "{problem}\nto replace it, add it again with replace (`exscec compile SPEC --store --replace`): "
        "the old version is kept as a revision (prov:wasRevisionOf)"
    ),
    REPLACE_A_SHARED_ELEMENT: (
        "{problem}\nto replace it, add it again with replace (`exscec compile SPEC --store --replace`): "
        "the old version is kept as a revision (prov:wasRevisionOf); but {about} named by id alone, "
        "shared by every scenario of the store that names one so: if another scenario declares it "
        "otherwise, give this scenario's another id (--replace would change the other scenario's too)"
    ),
    FIX_THE_STORE: "{problem} ({about} can be fixed with --fix)",
    REBUILD_THE_BASELINE: "{problem} (build it again: exscec baseline SPEC)",
    STORE_THE_SCENARIO: "{problem} (add it: exscec compile SPEC --store)",
    ANOTHER_STORE: (
        "{problem}: stop that process, or point --store at a SPARQL endpoint "
        "(for example `exscec serve` over this store)"
    ),
    LIST_THE_QUERIES: "{problem} (`exscec query --list` shows them all)",
    GIVE_A_RUN_ID: (
        "{problem}: give a run's uuid, a prefix of it ({about} characters at least, as `exscec runs` "
        "prints them) or its IRI"
    ),
    NO_RUNS_AT_ALL: "{problem} (it holds no runs at all: `exscec ingest BAG...` adds them)",
    MIGRATE_THE_STORE: "{problem}: `exscec store migrate` writes them from its runs' own statements",
    CLOSEST_RUNS: "{problem}; the closest ids (`exscec runs` lists every run):\n{about}",
    SELECT_OR_ASK: "exscec sparql runs SELECT and ASK queries",
    SERVE_A_FOLDER: "{problem}; exscec serve serves an embedded store",
    LEARN_FROM_EVERY_RUN: "{problem}; ingest runs that pass, or include every run (--all-runs)",
    BUILD_A_BASELINE: "{problem}: build its baseline first (exscec baseline <spec> --scenario-id {about})",
    VERIFY_THE_RUN: "{problem} (exscec verify RUN)",
    VERIFY_AGAIN: "{problem} (exscec verify judges it again){about}",
    REPRODUCE_IT: "{problem}: exscec verify {about[0]} --scenario {about[1]}",
    REPLAY_IT: "{problem}: exscec simulate {about[0]} --seed {about[1]} --runs {about[2]} -o DIR",
    REPLAY_IN_IRSIM: (
        "{problem}: exscec simulate {about[0]} --seed {about[1]} --runs {about[2]} --simulator irsim "
        "--behaviour {about[3]} --scans {about[4]} -o DIR"
    ),
    INSTALL_DASK: "--cluster needs Dask's distributed package: pip install 'exsce[dask]'",
    BUILT_IN_OPTIONS: (
        "--fault, --stand-in, --start-master and --speed-up are for the built-in executors {about}"
    ),
    ONE_EXECUTOR: "give one of --fault (the simulator), --executor-command and --executor",
    ROS1_OPTIONS: "--stand-in, --start-master and --speed-up go with --executor ros1 (--stand-in and "
    "--speed-up with ros2 too)",
    FAULTS_NEED_THE_STAND_IN: (
        "--fault with --executor ros1 plants the fault in exsce's stand-in robots: give --stand-in"
    ),
    STAND_IN_ONLY: (
        "{problem}: give --stand-in (a campaign starts each derived scenario from its own start poses, "
        "and exsce cannot yet move a real stack's robots there between runs; a script that resets your "
        "simulator and runs exscec execute --ros1 can be an --executor-command)"
    ),
    STAND_IN_FOR_FAULTS: "{problem}: give stand_in=True (--stand-in) with them",
    READ_ONLY: (
        "{problem} (exscec serve without --allow-updates): stop the server to write to its store "
        "directly, or restart it with --allow-updates and send its bearer token (exscec commands: "
        "EXSCE_STORE_TOKEN)"
    ),
    SEND_THE_TOKEN: "{problem}; exscec commands send EXSCE_STORE_TOKEN",
    ALLOW_THE_HOST: "{problem}: ask it by the address it listens on, or start it with --allowed-host NAME",
    ALLOW_FEDERATION: "{problem} (exscec serve --allow-federation HOST lets the endpoint reach HOST)",
    GIVE_THE_SPECS: (
        "no occupancy grid: no --spec was given: pass the scenarios' files with exscec report --spec "
        "FILE.exsce to draw paths on their maps"
    ),
    ADD_ITS_SPEC: (
        "no occupancy grid: no file given with --spec declares scenario '{about}' (or one it was derived "
        "from): add its file to exscec report --spec"
    ),
}
"""Each remedy the library says in words (:mod:`exsce_dsl.remedies`), as the command line says it:
with the option or command that does it (``str.format`` templates of ``{problem}`` and
``{about}``: :meth:`~exsce_dsl.errors.Remedied.said`).  What the user sees is what the library
said with these options before it said them in words (issue 49)."""


def said_with_options(exc: ExsceError) -> str:
    """``exc``'s message, its remedy said as the command line's option (for a command that prints
    an error itself, as ``error: message``)."""
    return _with_options(exc).message


def _with_options(exc: ExsceError) -> ExsceError:
    """``exc`` with its remedy said as the command line's option, when it has one."""
    if exc.remedied is None or exc.remedied.remedy not in REMEDIES:
        return exc
    worded = copy.copy(exc)
    worded.message = exc.remedied.said(REMEDIES)
    return worded


def reports_errors(func: F) -> F:
    """Turn library errors into ``file:line:col: error: message`` and exit status 2 (bad input);
    an unexpected exception is a bug of ours: exit status 70 (see :class:`ExitCode`)."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except ExsceError as exc:
            if State.debug:  # the traceback, and the exit status it has without --debug
                traceback.print_exc()
            if isinstance(exc, ScenarioChoiceError):
                exc = exc.naming(_scenario_option())
            exc = _with_options(exc)
            print_diagnostics(exc.diagnostics)
            sys.exit(ExitCode.BAD_INPUT)
        except click.UsageError:  # exit 2, with the usage line
            raise
        except click.ClickException as exc:  # click's other errors exit 1: a failed verdict's code
            exc.show()
            sys.exit(ExitCode.BAD_INPUT)
        except click.Abort:  # a prompt answered with Ctrl-C or Ctrl-D
            click.echo("Aborted!", err=True)
            sys.exit(ExitCode.INTERRUPTED)
        except (click.exceptions.Exit, SystemExit):
            raise
        except KeyboardInterrupt:
            click.echo("interrupted", err=True)
            sys.exit(ExitCode.INTERRUPTED)
        except BrokenPipeError:  # the reader went away (`| head`): stop quietly, as Unix tools do
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            sys.exit(ExitCode.BROKEN_PIPE)
        except Exception as exc:  # a bug of ours: say so briefly, trace with --debug
            if State.debug:
                traceback.print_exc()
            click.echo(
                f"internal error: {type(exc).__name__}: {exc} (run with --debug for a traceback)", err=True
            )
            sys.exit(ExitCode.INTERNAL_ERROR)

    return wrapper  # type: ignore[return-value]


def bag_arguments(args: Iterable[str]) -> list[str]:
    """The arguments that may be bags: not the ``.prov.json`` files the recorder writes beside them
    (so that ``runs/*`` works)."""
    return [a for a in args if not a.endswith(".prov.json")]


def write_text(text: str, output: str | None) -> None:
    """Print ``text``, or write it to ``output`` and say so on stderr."""
    if output is None:
        click.echo(text, nl=not text.endswith("\n"))
    else:
        Path(output).write_text(text, encoding="utf-8")
        click.echo(f"wrote {output}", err=True)


def spec_files(paths: Iterable[str]) -> list[str]:
    """``paths`` with each folder replaced by the ``.exsce`` files below it, recursively and
    sorted (hidden folders, such as ``.exsce`` or ``.venv``, left out)."""
    found: list[str] = []
    for given in paths:
        folder = Path(given)
        if not folder.is_dir():
            found.append(given)
            continue
        inside = sorted(
            (f for f in folder.rglob("*.exsce") if f.is_file()),
            key=lambda f: f.relative_to(folder).parts,
        )
        inside = [f for f in inside if not any(part.startswith(".") for part in f.relative_to(folder).parts)]
        if not inside:
            raise click.UsageError(f"{given} is a folder without .exsce files")
        found += [str(f) for f in inside]
    return found


class Progress:
    """A progress bar on stderr when stderr is a terminal; anywhere else (a CI log, a file) no
    bar, only the lines said through :meth:`say`, with no blank lines or escape codes."""

    def __init__(self, length: int, label: str) -> None:
        self._bar = (
            click.progressbar(length=length, label=label, file=sys.stderr) if sys.stderr.isatty() else None
        )

    def __enter__(self) -> Progress:
        if self._bar is not None:
            self._bar.__enter__()
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        if self._bar is not None:
            self._bar.__exit__(kind, error, trace)

    def update(self, steps: int = 1) -> None:
        if self._bar is not None:
            self._bar.update(steps)

    def say(self, line: str) -> None:
        """Print a line on stderr (on a terminal: over the bar, which is drawn again below it)."""
        if self._bar is None:
            click.echo(line, err=True)
            return
        click.echo(f"\r\x1b[2K{line}", err=True)
        self._bar._last_line = None  # click draws only a changed bar: this one was just erased
        self._bar.render_progress()


all_runs_option = click.option(
    "--all-runs",
    "include_all",
    is_flag=True,
    help="Learn from every stored run. By default only good runs count: a run is left out when its "
    "last verification failed or was inconclusive, its mission was cancelled or stopped, or it broke "
    "a safety limit (measured at ingest).",
)
"""The option of the commands that learn from stored runs (baselines, expected values)."""


def simulator_options(func: F) -> F:
    """``--simulator``, ``--behaviour`` and ``--scans``: what plays simulated runs."""
    for option in reversed(
        (
            click.option(
                "--simulator",
                default="kinematic",
                show_default=True,
                metavar="NAME",
                help="What plays the runs: kinematic (exsce's own executor) or irsim (IR-SIM, "
                "pip install 'exsce[irsim]'), or a simulator plug-in.",
            ),
            click.option(
                "--behaviour",
                type=click.Choice(["dash", "rvo", "orca", "sfm"]),
                help="irsim: IR-SIM's behaviour between the path's points [default: rvo] (orca needs pyrvo).",
            ),
            click.option(
                "--scans",
                type=click.Choice(["exsce", "irsim", "none"]),
                help="irsim: who measures the scans: exsce's laser model on IR-SIM's robot poses, "
                "IR-SIM's lidar2d (slow on a building's map), or none [default: exsce].",
            ),
        )
    ):
        func = option(func)
    return func
