"""A small yard with two robots of one robot type (r1 at the root namespace, r2 in /r2), whose
type's lines the tests fill in: the scene of the signal and stack-run tests."""

from __future__ import annotations

YARD = """
environment yard {
  area yard {
    pose yard-a at (0.0, 0.0)
    pose yard-b at (5.0, 0.0)
    pose yard-c at (5.0, 4.0) facing 90.0 deg
    pose yard-d at (0.0, 8.0)
    pose yard-e at (5.0, 8.0)
  }
}

robot type rover {
  base diff_drive
ROBOT_TYPE}

task round_1 {
  visit yard-b
  visit yard-c
}

task round_2 {
  visit yard-e
}

scenario yard_run in yard {
  robots {
    r1: rover namespace "" starts at yard-a
    r2: rover starts at yard-d
  }
  mission yard_mission parallel {
    r1 does round_1
    r2 does round_2
  }
}
"""


def yard_text(robot_type: str) -> str:
    """The yard's specification, its robot type saying ``robot_type`` (lines, unindented)."""
    return YARD.replace("ROBOT_TYPE", "".join(f"  {line}\n" for line in robot_type.splitlines()))
