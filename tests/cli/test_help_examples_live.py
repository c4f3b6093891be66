"""The ``--help`` examples of the live graph: execute, the stand-in, the demo: each runs as written, in order, on the state the chapter's
earlier examples made (tests/support/help_examples.py).  ``exscec demo exsce-demo`` is the whole
tutorial (a minute of work), so this is also where the demo's own outcome is checked, and the
tutorial's: its commands are the demo's steps (tests/cli/test_tutorial.py)."""

from __future__ import annotations

import re
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

from exsce_dsl.api.demo import STEPS, example_folder

from tests.support.cli import run_exscec
from tests.support.help_examples import walk


def test_every_help_example_of_the_live_chapter_runs_as_written(tmp_path: Path) -> None:
    walked = walk("live", tmp_path)
    _check_the_demo(walked.ended["exscec demo exsce-demo"], walked.scratch / "exsce-demo")
    _check_the_setup(walked.scratch / "my-project")


def _check_the_demo(done: subprocess.CompletedProcess[str], project: Path) -> None:
    """The demo shows the fault run failing and the others passing, a campaign and a report; a
    second demo into the same folder is refused."""
    stderr = done.stderr
    summary = stderr[stderr.index("Summary") :]
    assert summary.startswith("Summary") and "every step ended as expected" in summary.splitlines()[0]
    assert re.search(r"passed, as expected\s+new run of scenario_c", summary)
    assert re.search(r"failed, as expected\s+run of scenario_c with the over-speed fault", summary)
    assert re.search(r"passed, as expected\s+run of derived c_one", summary)
    assert (project / "campaign.xml").is_file() and list((project / "explore").rglob("minimal/*.exsce"))
    assert "NOT" not in summary and "error" not in summary
    assert (project / "report" / "index.html").is_file() and (project / "clusters.svg").is_file()
    junit = ET.parse(project / "verdicts-new.xml").getroot()
    assert int(junit.get("failures", junit.find("testsuite").get("failures"))) == 0  # type: ignore[union-attr]
    assert (project / "scenario_c.provn").read_text(encoding="utf-8").startswith("document")
    assert f"[{len(STEPS)}/{len(STEPS)}]" in stderr and "$ exscec verify runs/faulty/" in stderr
    again = run_exscec("demo", project.name, cwd=project.parent)
    assert again.returncode == 2 and "is not empty" in again.stderr and "Traceback" not in again.stderr


def _check_the_setup(project: Path) -> None:
    """``--setup-only`` leaves what the tutorial starts from: the example's files in
    ``scenarios/``, as shipped, and nothing else."""
    shipped = example_folder()
    files = sorted(p.relative_to(shipped) for p in shipped.rglob("*") if p.is_file())
    copied = sorted(p.relative_to(project / "scenarios") for p in project.rglob("*") if p.is_file())
    assert files and copied == files
    for file in files:
        assert (project / "scenarios" / file).read_bytes() == (shipped / file).read_bytes(), file
