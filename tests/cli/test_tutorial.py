"""docs/tutorial.md is exscec demo's steps, typed by hand, and how the demo reports them.

The tutorial's commands are the demo's, line for line, exit statuses included (the first test
here), so they run where the demo runs, as a process of its own and checked step by step: the live
chapter of the help examples (test_help_examples_live.py), which also runs the tutorial's
``exscec demo my-project --setup-only``; on Nav2's topics against a remote endpoint:
test_demo_remote.py; on move_base's, live: tests/execute/test_live_loop.py."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from exsce_dsl.api.demo import STEPS, DemoStep, command_hint, run_steps, set_up, summary_lines
from exsce_dsl.cli.demo_commands import run_in_process

from tests.support.paths import ROOT

TUTORIAL = ROOT / "docs" / "tutorial.md"


def _shell_lines() -> list[str]:
    blocks = re.findall(r"```sh\n(.*?)```", TUTORIAL.read_text(encoding="utf-8"), flags=re.S)
    return [line.strip() for block in blocks for line in block.splitlines() if line.strip()]


def _expected_exit(line: str) -> int:
    found = re.search(r"#\s*exits (\d+)\s*$", line)
    return int(found.group(1)) if found else 0


def _without_comment(line: str) -> str:
    return re.sub(r"\s+#.*$", "", line)


def test_the_demo_runs_the_commands_of_the_tutorial() -> None:
    lines = _shell_lines()
    assert lines[:2] == ["exscec demo my-project --setup-only", "cd my-project"]
    assert [_without_comment(line) for line in lines[2:]] == [step.command for step in STEPS]
    assert [_expected_exit(line) for line in lines[2:]] == [step.expected_exit for step in STEPS]


def test_a_verdict_other_than_expected_is_reported_and_the_demo_goes_on(tmp_path: Path) -> None:
    """A verify step whose runs pass where they should fail: the outcome is named, the steps after it
    still run, and the demo as a whole did not go as expected."""
    folder = tmp_path / "demo"
    set_up(folder)
    good, missing = "exscec check scenarios/scenario_c.exsce", "exscec check scenarios/missing.exsce"
    steps = (
        DemoStep("check", good),
        DemoStep("should fail", good, expected_exit=1, verdict="a good spec"),
        DemoStep("refused, as it should", missing, expected_exit=2, verdict="no spec"),
    )
    run = run_steps(folder, run_in_process, steps=steps)
    assert [o.exit_code for o in run.outcomes] == [0, 0, 2]
    assert run.unexpected == (run.outcomes[1],) and run.stopped is None and not run.as_expected
    lines = summary_lines(run)
    shown = "\n".join(lines)
    assert lines[0].endswith("NOT every step ended as expected")
    assert re.search(r"^  passed, NOT as expected \(expected: failed\)\s+a good spec$", shown, re.M)
    assert re.search(r"^  refused \(bad input\), as expected\s+no spec$", shown, re.M)
    assert lines[-1] == f"error: {good}: passed, NOT as expected (expected: failed)"


def test_a_step_the_next_ones_need_stops_the_demo_when_it_fails(tmp_path: Path) -> None:
    folder = tmp_path / "demo"
    set_up(folder)
    steps = (
        DemoStep("compile a missing file", "exscec compile scenarios/missing.exsce --store"),
        DemoStep("never run", "exscec check scenarios/scenario_c.exsce"),
    )
    run = run_steps(folder, run_in_process, steps=steps)
    assert len(run.outcomes) == 1 and run.stopped == run.outcomes[0] and not run.as_expected
    assert summary_lines(run)[-1] == (
        "error: step 1 (exscec compile scenarios/missing.exsce --store): exited 2, NOT as expected "
        "(expected: exited 0); the steps after it need it, so the demo stopped"
    )


def test_exscec_demo_exits_1_when_an_outcome_is_not_the_expected_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from click.testing import CliRunner

    import exsce_dsl.api.demo as demo
    from exsce_dsl.cli.main import main

    monkeypatch.chdir(tmp_path)
    command = "exscec check scenarios/scenario_c.exsce"
    monkeypatch.setattr(demo, "STEPS", (DemoStep("verify, as it were", command, verdict="the example"),))
    passed = CliRunner().invoke(main, ["demo", "as-expected"])
    assert passed.exit_code == 0, passed.output
    assert re.search(r"passed, as expected\s+the example", passed.stderr)
    monkeypatch.setattr(demo, "STEPS", (DemoStep("verify, as it were", command, 1, verdict="the example"),))
    failed = CliRunner().invoke(main, ["demo", "not-as-expected"])
    assert failed.exit_code == 1, failed.output
    assert "[1/1] verify, as it were" in failed.stderr
    lines = failed.stderr.splitlines()
    assert f"error: {command}: passed, NOT as expected (expected: failed)" in lines


def test_the_demo_says_how_to_type_its_commands_when_exscec_is_not_on_path(tmp_path: Path) -> None:
    """After the README's first command exscec is in .venv/bin, not on PATH: the demo says to activate
    the environment, by the path that works from where the user is."""
    exscec = Path(sys.executable).with_name("exscec")
    here = exscec.parent.absolute()
    elsewhere = [p for p in os.environ["PATH"].split(os.pathsep) if Path(p).absolute() != here]
    for folder, path in (("without", elsewhere), ("with", [str(exscec.parent), *elsewhere])):
        done = subprocess.run(
            [str(exscec), "demo", folder, "--setup-only"], cwd=tmp_path, capture_output=True, text=True,
            env={**os.environ, "PATH": os.pathsep.join(path)}, timeout=120,
        )
        assert done.returncode == 0, done.stderr
        hinted = f"first run '. {here}/activate'" in done.stderr
        assert hinted == (folder == "without"), done.stderr


def test_the_hint_names_the_environment_relative_to_the_users_folder(tmp_path: Path) -> None:
    scripts = tmp_path / ".venv" / "bin"
    scripts.mkdir(parents=True)
    (scripts / "exscec").write_text("#!/bin/sh\n")
    (scripts / "exscec").chmod(0o755)
    assert command_hint(tmp_path, search_path=str(scripts), bin_dir=scripts) is None
    assert command_hint(tmp_path, search_path="", bin_dir=scripts) == (
        f"exscec is not on your PATH: type {scripts / 'exscec'} instead of exscec"
    )
    (scripts / "activate").write_text("")
    activate = "exscec is not on your PATH: to type the demo's commands yourself, first run"
    assert str(command_hint(tmp_path, search_path="", bin_dir=scripts)).startswith(
        f"{activate} '. .venv/bin/activate'"
    )
    assert str(command_hint(tmp_path / "elsewhere", search_path="", bin_dir=scripts)).startswith(
        f"{activate} '. {scripts}/activate'"
    )
    assert command_hint(tmp_path, search_path="", bin_dir=tmp_path / "no-such-bin") is None
