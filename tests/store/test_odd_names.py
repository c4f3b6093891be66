"""Topics and bag files named as real bags name them (relative, with '-', spaces, '%', '@', non-ASCII)
go through run PROV, oracle PROV and the store, and come back from the queries spelt as the bag
spells them."""

from __future__ import annotations

import datetime

from exsce_dsl.model.oracles import Oracle, OracleType
from exsce_dsl.model.runs import Action, ActionId, Bag, MetricScope, MetricValue, Run, TaskExecution
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.oracle import compile_oracles
from exsce_dsl.prov.run import compile_run
from exsce_dsl.rdf import to_quads, validate
from exsce_dsl.store import queries as q
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.writing import add_prov

from tests.support.scenario_builders import C022_W001, C025_W001, scenario_c

ODD_TOPICS = ("groundtruth", "ORB-SLAM", "/tiago1/my scan", "/50%@x", "/r\u00e9seau/\u20ac", "/tiago1/nav_vel")
BAG_NAME = "run #1 (copy) 50%.bag"
UUID = "0d7c6f0e-0000-4000-8000-000000000001"


def odd_run() -> Run:
    action = Action(ActionId("tiago1", 1, 1, 1), C025_W001, C022_W001)
    return Run(
        UUID,
        "scenario_c",
        datetime.datetime(2024, 5, 1, 10),
        datetime.datetime(2024, 5, 1, 10, 5),
        Bag(BAG_NAME, ODD_TOPICS),
        (TaskExecution("tiago1", 1, (action,)),),
        (
            MetricValue("distance_travelled", MetricScope.ROBOT, 7.0, ODD_TOPICS[:3], robot="tiago1"),
            MetricValue("max_velocity", MetricScope.SEGMENT, 0.5, ODD_TOPICS[3:], action=action.id),
        ),
    )


def test_odd_names_make_valid_run_graphs() -> None:
    assert validate(to_quads(compile_run(odd_run(), scenario_c())), ["runs"]) == []


def test_the_store_gives_back_the_bags_names() -> None:
    scenario = scenario_c()
    oracle = Oracle("max_velocity", "tiago1", "below_max", OracleType.BASELINE, "scenario_c", ODD_TOPICS, limit=1.0)
    with EmbeddedStore(None) as store:
        add_prov(store, compile_scenario(scenario))
        add_prov(store, compile_run(odd_run(), scenario))
        add_prov(store, compile_oracles("scenario_c", [oracle]))
        (robot_value,) = q.metric_sources(store, UUID, "distance_travelled")
        (segment_value,) = q.metric_sources(store, UUID, "max_velocity")
        (stored,) = q.oracles(store, "scenario_c")
    assert robot_value.topics == tuple(sorted(ODD_TOPICS[:3])) and robot_value.bag == BAG_NAME
    assert segment_value.topics == tuple(sorted(ODD_TOPICS[3:])) and segment_value.bag == BAG_NAME
    assert stored.topics == tuple(sorted(ODD_TOPICS))
