"""The error of a file with several scenarios names the option of the command that ran (issue 47,
item 8): ``ingest`` and ``verify`` take the file as ``--scenario``, so the scenario is chosen with
``--scenario-id`` there, and the error used to say ``--scenario`` everywhere."""

from __future__ import annotations

from pathlib import Path

from tests.support.cli import exscec_here
from tests.support.paths import ROOT

TWO = """
environment pond {
  area water {
    pose start at (5.5, 5.5)
    pose far at (40.0, 40.0)
  }
}
task swim {
  visit far
}
robot type turtle {
  base diff_drive
}
scenario first in pond {
  robots {
    t: turtle namespace "turtle1" starts at start
  }
  mission swim_first sequential {
    t does swim
  }
}
scenario second in pond {
  robots {
    t: turtle namespace "turtle1" starts at start
  }
  mission swim_second sequential {
    t does swim
  }
}
"""
BAG = ROOT / "tests" / "fixtures" / "realbags" / "rosbag.js" / "example.bag"


def test_scenario_choice_error_names_scenario_id_option(tmp_path: Path) -> None:
    (tmp_path / "two.exsce").write_text(TWO)
    said = "two.exsce declares 2 scenarios (first, second); name one with "
    for command in (
        ["ingest", str(BAG), "--scenario", "two.exsce"],
        ["verify", str(BAG), "--scenario", "two.exsce"],
    ):
        done = exscec_here(*command, cwd=tmp_path)
        assert done.returncode == 2, done.stderr
        assert said + "--scenario-id" in done.stderr, done.stderr
    # where the file is an argument, the option that names a scenario is --scenario
    done = exscec_here("generate", "dispatcher-config", "two.exsce", "-o", "out", cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip().endswith(said + "--scenario"), done.stderr
