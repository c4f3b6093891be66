"""``exscec_here`` (tests/support/cli.py) runs a command in the test's process where the process
is not what a test checks: it must print and exit as the console script does, and leave the
test's working folder and environment as they were."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tests.support.cli import exscec_here, run_exscec
from tests.support.paths import EXAMPLES

SPEC = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"


@pytest.mark.parametrize(
    ("args", "status"),
    [
        (["check", "broken.exsce"], 2),  # a DSL error: file:line:col
        (["check", str(SPEC)], 0),
        (["runs", "-f", "json", "--store", "store"], 0),  # an empty store
        (["query", "nonesuch", "--store", "store"], 2),  # an unknown query
        (["verify", "--scenario", str(SPEC)], 2),  # click's own usage error
    ],
    ids=["dsl-error", "check", "runs", "unknown-query", "usage"],
)
def test_a_command_here_prints_and_exits_as_the_console_script(
    args: list[str], status: int, tmp_path: Path
) -> None:
    (tmp_path / "broken.exsce").write_text("robot tiago1 {\n  type: nonesuch\n", encoding="utf-8")
    alone = run_exscec(*args, cwd=tmp_path)
    here = exscec_here(*args, cwd=tmp_path)
    assert alone.returncode == status and (alone.stdout or alone.stderr)
    assert (here.returncode, here.stdout, here.stderr) == (alone.returncode, alone.stdout, alone.stderr)


def test_the_working_folder_and_environment_are_the_tests_again(tmp_path: Path) -> None:
    before = (Path.cwd(), dict(os.environ))
    done = exscec_here("--msg-path", str(tmp_path), "check", str(SPEC), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (Path.cwd(), dict(os.environ)) == before  # --msg-path set $EXSCE_MSG_PATH while it ran
