"""exscec demo with the robots on Nav2's topics: the whole method, the same verdicts as on the
method's topics (tests/cli/test_help_examples_live.py runs the demo itself; move_base's topics:
tests/cli/test_demo_remote.py, which runs that demo against a remote store)."""

from __future__ import annotations

from pathlib import Path

from tests.support.cli import run_exscec
from tests.support.stack_demo import check_stack_demo


def test_the_whole_method_runs_on_nav2s_runs(tmp_path: Path) -> None:
    """The demo with the robots on Nav2's topics: the same verdicts, and its bags, metric sources
    and report are Nav2's."""
    done = run_exscec("demo", "demo", "--convention", "nav2", cwd=tmp_path, timeout=600)
    check_stack_demo(done, tmp_path / "demo", "nav2")
