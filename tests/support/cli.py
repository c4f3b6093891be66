"""The real ``exscec`` of this environment: run as a user runs it (a process of its own), or
in this process through click's test runner where the process is not what a test checks."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from click.testing import CliRunner


def run_exscec(*args: str, cwd: Path | None = None, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    """Run the real ``exscec`` console script of this environment."""
    exe = Path(sys.executable).with_name("exscec")
    return subprocess.run(
        [str(exe), *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, "COLUMNS": "120"},
    )


def exscec_here(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """``exscec ARGS`` run in this process: the console script's own command (``main``), its
    output, error output and exit status, without starting an interpreter and importing the
    libraries again (0.4 s of CPU a command).  The working folder and the environment are the
    caller's again afterwards (``--msg-path`` sets ``$EXSCE_MSG_PATH`` for worker processes);
    an exception the command does not handle fails the test with its traceback."""
    from exsce_dsl.cli.main import main

    folder, environment = Path.cwd(), dict(os.environ)
    try:
        if cwd is not None:
            os.chdir(cwd)
        done = CliRunner(env={"COLUMNS": "120"}).invoke(
            main, list(args), prog_name="exscec", catch_exceptions=False
        )
    finally:
        os.chdir(folder)
        os.environ.clear()
        os.environ.update(environment)
    return subprocess.CompletedProcess(["exscec", *args], done.exit_code, done.stdout, done.stderr)
