"""Typed queries over the store: the SPARQL counterparts of the method's Neo4j questions.

Each function runs one file of the query library (:mod:`.library`, the ``.rq``
and ``.ru`` files next to this module), with its parameters bound as RDF terms
exactly as ``exscec query NAME -p key=value`` binds them, and returns plain
values or dataclasses, never raw bindings.  Aggregates (means, variances,
counts) are computed by the store; only the square root of a variance is
taken here (SPARQL 1.1 has none).

Identifiers are the DSL's: scenario, robot and metric ids, run uuids, and
poses either as :class:`~exsce_dsl.model.Pose` or as the local name of their
PROV entity (``classroom_c025-w001-R0.00_P0.00_Y0.00``).
"""

from __future__ import annotations

from exsce_dsl.store.queries.accounting import ValueAccount, run_problems, value_accounts
from exsce_dsl.store.queries.coverage import run_coverage, run_topic_rates
from exsce_dsl.store.queries.library import (
    KINDS,
    Query,
    QueryParameter,
    query,
    query_names,
    standard_prefixes,
)
from exsce_dsl.store.queries.run_ids import (
    MIN_PREFIX,
    AmbiguousRunError,
    RunCandidate,
    UnknownRunError,
    resolve_run,
    resolve_runs,
)
from exsce_dsl.store.queries.run_lineage import (
    ChainExecution,
    ChainGoal,
    ChainValue,
    ChainVerdict,
    RunChain,
    dispatched_runs,
    run_chain,
)
from exsce_dsl.store.queries.run_values import *  # noqa: F403
from exsce_dsl.store.queries.run_values import (
    ActionTimes,
    MetricReading,
    MetricSource,
    RunDefect,
    StoredRun,
    ViolationDuration,
    action_times,
    metric_sources,
    mission_metric,
    run_defects,
    run_metric,
    run_metric_values,
    run_scenarios,
    run_segment_values,
    runs,
    violation_duration,
    violation_durations,
)
from exsce_dsl.store.queries.scenarios import *  # noqa: F403
from exsce_dsl.store.queries.scenarios import (
    PathSegment,
    RobotFacts,
    derivation_of,
    derived_scenarios,
    lineage,
    path_segments,
    robots,
    scenario_ids,
)
from exsce_dsl.store.queries.segment_stats import *  # noqa: F403
from exsce_dsl.store.queries.segment_stats import (
    ValueStats,
    mission_duration,
    mission_metric_over_runs,
    robot_metric_over_runs,
    segment_metric,
    segment_metric_any,
    segment_metric_between,
    stats_of,
    waypoints_visited,
)
from exsce_dsl.store.queries.stored_oracles import *  # noqa: F403
from exsce_dsl.store.queries.stored_oracles import (
    hotspot_counts,
    oracles,
    safety_metrics,
    update_baseline,
)
from exsce_dsl.store.queries.terms import (
    Given,
    bool_of,
    datetime_of,
    float_of,
    int_of,
    pose_local_name,
    python_value,
    run_query,
    text_of,
)

__all__ = [
    "MIN_PREFIX",
    "ActionTimes",
    "ChainExecution",
    "ChainGoal",
    "ChainValue",
    "ChainVerdict",
    "AmbiguousRunError",
    "Given",
    "KINDS",
    "MetricReading",
    "MetricSource",
    "QueryParameter",
    "PathSegment",
    "Query",
    "RobotFacts",
    "RunCandidate",
    "RunChain",
    "RunDefect",
    "StoredRun",
    "ValueAccount",
    "ValueStats",
    "UnknownRunError",
    "ViolationDuration",
    "action_times",
    "bool_of",
    "datetime_of",
    "derivation_of",
    "derived_scenarios",
    "dispatched_runs",
    "float_of",
    "hotspot_counts",
    "int_of",
    "lineage",
    "metric_sources",
    "mission_duration",
    "mission_metric",
    "mission_metric_over_runs",
    "oracles",
    "path_segments",
    "pose_local_name",
    "python_value",
    "query",
    "query_names",
    "resolve_run",
    "resolve_runs",
    "robot_metric_over_runs",
    "robots",
    "run_metric",
    "run_chain",
    "run_coverage",
    "run_defects",
    "run_problems",
    "run_metric_values",
    "run_query",
    "run_scenarios",
    "run_segment_values",
    "run_topic_rates",
    "runs",
    "safety_metrics",
    "scenario_ids",
    "value_accounts",
    "segment_metric",
    "segment_metric_any",
    "segment_metric_between",
    "standard_prefixes",
    "stats_of",
    "text_of",
    "update_baseline",
    "violation_duration",
    "violation_durations",
    "waypoints_visited",
]
