"""Covering draws of scenario_c: they send robots into every area of the environment early."""

from __future__ import annotations

import pytest

from exsce_dsl.explore.cover import areas_driven, covering_derivations
from exsce_dsl.model import Scenario, Task
from exsce_dsl.transform.derivation import derive

ROOMS_C = {"classroom_c025", "classroom_c022", "classroom_c018"}
"""Where scenario_c's robots start and drive: they start in c025 and deliver from c022 to c018."""


def test_the_areas_a_scenario_drives_in(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    assert areas_driven(base) == ROOMS_C
    elsewhere = derive(
        base, [("replace_robot", {"robot": "tiago2", "by": "tiago3", "start": "classroom_c069-w001"})], tasks=tasks
    ).scenario
    assert areas_driven(elsewhere) == ROOMS_C | {"classroom_c069"}
    idle = derive(base, [("add_robot", {"robot": "tiago3", "like": "tiago1", "start": "classroom_c069-w001"})],
                  tasks=tasks).scenario
    assert areas_driven(idle) == ROOMS_C  # a robot without tasks drives nowhere


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fifteen_draws_drive_in_every_area(spec_c: tuple[Scenario, dict[str, Task]], seed: int) -> None:
    """Each of the environment's six areas is driven in by some derivation among fifteen: a
    fault that lives in one room (slow-area) is met within a small budget."""
    base, tasks = spec_c
    drawn = covering_derivations(base, tasks, 15, seed)
    assert len(drawn) == 15
    reached = set().union(*(areas_driven(c.scenario) for c in drawn))
    assert reached == {a.id for a in base.environment.areas if a.poses}
    assert len(reached) == 6
