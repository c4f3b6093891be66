"""What every exscec command shares: error reporting, output."""

from __future__ import annotations

import functools
import os
import sys
from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path
from types import TracebackType
from typing import Any, TypeVar

import click

from exsce_dsl.errors import Diagnostic, ExsceError

F = TypeVar("F", bound=Callable[..., Any])


class State:
    """Options of the group that commands need (set by ``exscec --debug``)."""

    debug = False


SHOWN_DIAGNOSTICS = 100
"""At most this many problems are printed: a file with thousands of errors is fixed from the top."""


def print_diagnostics(diagnostics: Iterable[Diagnostic]) -> None:
    found = list(diagnostics)
    for d in found[:SHOWN_DIAGNOSTICS]:
        click.echo(str(d), err=True)
    if len(found) > SHOWN_DIAGNOSTICS:
        hidden = Counter(str(d.severity) for d in found[SHOWN_DIAGNOSTICS:])
        total = sum(hidden.values())
        if set(hidden) == {"error"}:  # the usual case
            said = f"{total} more error{'s' if total != 1 else ''}"
        else:  # notes and warnings are not counted as errors
            kinds = ", ".join(f"{n} {kind}{'s' if n != 1 else ''}" for kind, n in sorted(hidden.items()))
            said = f"{total} more ({kinds})"
        click.echo(f"... and {said} (the first {SHOWN_DIAGNOSTICS} are shown)", err=True)


def reports_errors(func: F) -> F:
    """Turn library errors into ``file:line:col: error: message`` and exit status 1."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except ExsceError as exc:
            if State.debug:
                raise
            print_diagnostics(exc.diagnostics)
            sys.exit(1)
        except (click.ClickException, click.exceptions.Exit, click.Abort, SystemExit):
            raise
        except BrokenPipeError:  # the reader went away (`| head`): stop quietly, as Unix tools do
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            sys.exit(1)
        except Exception as exc:  # a bug of ours: say so briefly, trace with --debug
            if State.debug:
                raise
            click.echo(
                f"internal error: {type(exc).__name__}: {exc} (run with --debug for a traceback)", err=True
            )
            sys.exit(1)

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
