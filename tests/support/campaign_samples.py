"""One sample campaign's trials and shrinkings, as the report and JUnit tests write them to a store:
trial 1 violates the duration relation, trial 2 nothing, trial 3 both, trial 4 checked nothing;
the duration relation could not be shrunk, the distance one shrank to one step in two tries."""

from __future__ import annotations

from collections.abc import Sequence

from exsce_dsl.model.campaign import CampaignTrial, CheckedRelation, Shrinking, ShrinkTry

DURATION = CheckedRelation("task_duration", "tiago1", "increasing", "scenario_c")
DISTANCE = CheckedRelation("distance_travelled", "tiago1", "invariant")
REMOVE = ("remove_robot", {"robot": "tiago2", "reassign": "tiago1"})
REVERSE = ("reverse_waypoint_order", {"task": "delivery_a"})


def sample_trials(runs: Sequence[tuple[str, str, str]]) -> tuple[CampaignTrial, ...]:
    """The four trials; ``runs``: the uuids of trials 1, 2 and 3's runs."""
    both = (DURATION, DISTANCE)
    return (
        CampaignTrial("c_explore", 1, "c_explore_0001", (REMOVE,), runs[0], both, (DURATION,)),
        CampaignTrial("c_explore", 2, "c_explore_0002", (REVERSE,), runs[1], both, ()),
        CampaignTrial("c_explore", 3, "c_explore_0003", (REVERSE, REMOVE), runs[2], both, both),
        CampaignTrial("c_explore", 4, "c_explore_0004", (REVERSE,), (), (), ()),
    )


SHRINKINGS = (
    Shrinking(
        "c_explore", 1, DURATION, 1, "c_explore_0001", "c_explore_0001", (REMOVE,),
        (ShrinkTry("scenario_c", (), False),),
    ),
    Shrinking(
        "c_explore", 2, DISTANCE, 3, "c_explore_0003", "c_explore_s2_1", (REMOVE,),
        (ShrinkTry("c_explore_s2_1", (REMOVE,), True), ShrinkTry("c_explore_s2_2", (REVERSE,), False)),
    ),
)  # fmt: skip
