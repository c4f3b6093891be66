"""The provenance store: named graphs per PROV bundle, SPARQL, typed queries."""

# mypy: implicit-reexport
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from exsce_dsl.store.answers import results_json
    from exsce_dsl.store.base import MAX_QUERY, QUERY_TIMEOUT, Bindings, Rows, Store, Term
    from exsce_dsl.store.batch_writing import RunWriter, Written
    from exsce_dsl.store.checking import check_store
    from exsce_dsl.store.embedded import EmbeddedStore
    from exsce_dsl.store.federation import refuse_federation
    from exsce_dsl.store.indexes import is_index_graph
    from exsce_dsl.store.literals import canonical_rows, literal_text, literal_value
    from exsce_dsl.store.migrating import migrate_store
    from exsce_dsl.store.open import StoreOpening, open_store, store_url
    from exsce_dsl.store.queries import (
        MetricReading,
        MetricSource,
        QueryParameter,
        RunChain,
        RunDefect,
        StoredRun,
        ValueAccount,
        ValueStats,
        action_times,
        derivation_of,
        derived_scenarios,
        dispatched_runs,
        lineage,
        metric_sources,
        oracles,
        query_names,
        resolve_runs,
        robot_metric_over_runs,
        robots,
        run_chain,
        run_coverage,
        run_defects,
        run_metric_values,
        run_problems,
        run_query,
        run_scenarios,
        run_segment_values,
        run_topic_rates,
        runs,
        scenario_ids,
        segment_metric_between,
        standard_prefixes,
        value_accounts,
    )
    from exsce_dsl.store.queries.campaigns import campaign_record, campaigns
    from exsce_dsl.store.queries.library import Query, query
    from exsce_dsl.store.queries.results import hotspots, pose_positions, verdicts
    from exsce_dsl.store.queries.run_ids import is_full_uuid, names_a_prefix, resolve_run
    from exsce_dsl.store.queries.run_values import violation_duration
    from exsce_dsl.store.queries.scenarios import path_segments
    from exsce_dsl.store.queries.segment_stats import mission_metric_over_runs
    from exsce_dsl.store.queries.stored_names import unknown_names
    from exsce_dsl.store.queries.stored_oracles import hotspot_counts, safety_metrics
    from exsce_dsl.store.remote import RemoteStore
    from exsce_dsl.store.run_replacing import replace_run, verdict_graphs
    from exsce_dsl.store.serve_info import ServeInfo, serve_info_path, write_serve_info
    from exsce_dsl.store.sparql import declared_prefixes, query_form
    from exsce_dsl.store.timing import QueryTimes, timing_queries
    from exsce_dsl.store.writing import WriteReport, add_prov, is_revision
else:
    from exsce_dsl.faces import lazy_face

    __getattr__, __dir__ = lazy_face(__name__, __file__)
