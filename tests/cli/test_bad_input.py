"""Every command that reads a file, given a bad one: a clear message, a non-zero exit, never a traceback.

Run in-process with click's runner (the same code path as the console script,
without a Python start-up per case); ``reports_errors`` turns a bug into an
"internal error" line, which these tests count as a failure too.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from exsce_dsl.cli.main import main

from tests.support.paths import EXAMPLES

SPEC = str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")

# each command, with {} where the bad file goes (and what else it needs to get as far as reading it)
COMMANDS = {
    "check": ["check", "{}"],
    "compile": ["compile", "{}", "-f", "provn"],
    "fmt": ["fmt", "--check", "{}"],
    "export": ["export", "{}", "--to", "yaml", "-o", "out"],
    "import": ["import", "{}", "-o", "out.exsce"],
    "simulate": ["simulate", "{}", "-o", "runs"],
    "ingest-spec": ["ingest", "{}", "--scenario", "{}"],
    "ingest-bag": ["ingest", "{}", "--scenario", SPEC],
    "baseline": ["baseline", "{}"],
    "verify-spec": ["verify", "00000000-0000-0000-0000-000000000000", "--scenario", "{}"],
    "verify-bag": ["verify", "{}", "--scenario", SPEC, "--no-record"],
    "derive": ["derive", "{}", "-t", "remove_robot", "--robot", "tiago2"],
    "expect": ["expect", "{}"],
    "generate": ["generate", "monitors", "{}", "-o", "gen"],
    "report-spec": ["report", "-o", "rep", "--spec", "{}"],
    "sparql-file": ["sparql", "@{}"],
}


def _bad_inputs(folder: Path) -> dict[str, Path]:
    (folder / "empty.exsce").write_text("")
    (folder / "garbage.exsce").write_bytes(bytes(range(256)) * 40)
    (folder / "folder.exsce").mkdir()
    (folder / "latin1.exsce").write_bytes("scenario caf\xe9 {".encode("latin-1"))
    return {
        "missing": folder / "missing.exsce",
        "directory": folder / "folder.exsce",
        "empty": folder / "empty.exsce",
        "garbage": folder / "garbage.exsce",
        "not utf-8": folder / "latin1.exsce",
    }


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_bad_files_get_a_message_and_an_exit_code_not_a_traceback(
    command: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("EXSCE_STORE", str(tmp_path / "store"))
    runner = CliRunner()
    for kind, path in _bad_inputs(tmp_path).items():
        args = [a.replace("{}", str(path)) for a in COMMANDS[command]]
        result = runner.invoke(main, args)
        said = result.output + (result.stderr if result.stderr_bytes is not None else "")
        assert result.exit_code not in (0, None), f"{command} accepted a {kind} file:\n{said}"
        assert result.exception is None or isinstance(result.exception, SystemExit), (
            f"{command} on a {kind} file raised {result.exception!r}"
        )
        assert "Traceback" not in said and "internal error" not in said, f"{command}, {kind}:\n{said}"
        assert said.strip(), f"{command} said nothing about a {kind} file"
        assert len(said) < 5000, f"{command}, {kind}: {len(said)} characters of output"


def test_ten_thousand_errors_give_bounded_output(tmp_path: Path) -> None:
    lines = ['import "robots.exsce"', "", "scenario many in nowhere {", "  robots {"]
    lines += [f"    r{i}: no_such_type starts at no_such_pose_{i}" for i in range(10_000)]
    lines += ["  }", "}"]
    spec = tmp_path / "many.exsce"
    spec.write_text("\n".join(lines) + "\n")
    (tmp_path / "robots.exsce").write_text((EXAMPLES / "brsu_building_c" / "robots.exsce").read_text())
    result = CliRunner().invoke(main, ["check", str(spec)])
    said = result.output
    assert result.exit_code == 2 and "Traceback" not in said
    assert said.count("error:") >= 50  # several errors are shown ...
    assert len(said.splitlines()) <= 250 and len(said) < 60_000  # ... but not ten thousand of them
    from exsce_dsl.lang import analyse

    total = len(analyse(spec).diagnostics)
    assert f"... and {total - 100} more errors (the first 100 are shown)" in said.splitlines()


def test_hidden_diagnostics_are_counted_by_severity(capsys: pytest.CaptureFixture[str]) -> None:
    from exsce_dsl.cli.common import SHOWN_DIAGNOSTICS, print_diagnostics
    from exsce_dsl.errors import Diagnostic, Severity

    shown = [Diagnostic(f"e{i}") for i in range(SHOWN_DIAGNOSTICS)]
    hidden = [Diagnostic("late"), Diagnostic("why", severity=Severity.NOTE), Diagnostic("x", severity="note")]
    print_diagnostics(shown + hidden)
    last = capsys.readouterr().err.splitlines()[-1]
    assert last == f"... and 3 more (1 error, 2 notes) (the first {SHOWN_DIAGNOSTICS} are shown)"


def test_a_spec_that_is_not_valid_utf8_is_reported_at_its_file(tmp_path: Path) -> None:
    spec = tmp_path / "latin1.exsce"
    spec.write_bytes("// caf\xe9\n".encode("latin-1"))
    result = CliRunner().invoke(main, ["check", str(spec)])
    assert result.exit_code == 2 and str(spec) in result.output and "UTF-8" in result.output


def test_no_command_reads_from_a_fifo_forever(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.exsce"
    os.mkfifo(fifo)
    result = CliRunner().invoke(main, ["check", str(fifo)])
    assert result.exit_code != 0 and "Traceback" not in result.output


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["runs", "--store", "a-file"], "it is a file, not a store folder"),
        (["runs", "--store", "junk"], "holds no Oxigraph store"),
        (["cluster", "--store", "junk"], "holds no Oxigraph store"),
        (["report", "-o", "a-file"], "is a file"),
        (["generate", "monitors", SPEC, "-o", "a-file"], "is a file"),
        (["simulate", SPEC, "-o", "a-file"], "is a file"),
    ],
)
def test_a_store_or_output_folder_that_is_not_one_is_refused(
    args: list[str], said: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a-file").write_text("not a folder\n")
    (tmp_path / "junk").mkdir()
    (tmp_path / "junk" / "notes.txt").write_text("mine\n")
    result = CliRunner().invoke(main, args)
    assert result.exit_code in (1, 2) and said in result.output, result.output
    assert (tmp_path / "junk" / "notes.txt").read_text() == "mine\n"  # nothing of the user's is touched
