"""Two small yards as ``.exsce`` text.

- :data:`YARD` with two robots of one robot type (r1 at the root namespace, r2 in /r2), whose
  type's lines the tests fill in: the scene of the signal and stack-run tests;
- :data:`YARD_SPEC`, two robots patrolling a 10 m square: the scene of the verify tests;
- :data:`FAR_YARD`, a yard whose one task goes to a pose no recorded robot reaches (50 m away),
  and a robot type of nothing but its base: the scene of the tests of one bag's shape."""

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


# The yard of tests/oracles/test_verify_e2e (its docstring says what each fault should fail):
# two robots whose paths never meet in a 10 m square (map: tests.support.map_files.write_map(folder, size=200)).
YARD_SPEC = """\
robot type tiago {
  base pmb2
  torso yes
}

environment yard {
  map yard file "map.yaml"
  area field {
    pose field-a at (1.0, 1.0)
    pose field-b at (1.0, 8.0)
    pose field-c at (8.0, 8.0)
    pose field-d at (8.0, 1.0)
    pose field-e at (4.5, 4.5)
  }
}

task patrol_1 {
  visit field-b, field-e
}

task patrol_2 {
  visit field-c
}

scenario yard_run in yard {
  robots {
    r1: tiago starts at field-a
    r2: tiago starts at field-d
  }
  mission yard_mission parallel {
    r1 does patrol_1
    r2 does patrol_2
  }
}

acceptance for yard_run {
  scenario "moves safely" {
    when yard_mission runs
    then each robot max_velocity stays below 1.0 m/s
     and each robot distance_to_obstacles stays above 0.1 m
     and distance_between_robots stays above 0.5 m
  }
  scenario "performs as before" {
    given at least 4 baseline runs
    when yard_mission runs
    then each robot waypoints_visited is invariant within 0
     and each robot task_duration is invariant within 20 %
     and each robot distance_travelled is invariant within 10 %
  }
}
"""

FAR_YARD = """
environment yard {
  area ground {
    pose start at (0.0, 0.0)
    pose far at (50.0, 50.0)
  }
}
task go {
  visit far
}
robot type bot {
  base diff_drive
}
"""
