"""exsce from Python: the workflows of ``exscec``, with typed results, and the store's numbers as
pandas DataFrames.  This is the entry module; ``docs/python.md`` walks through it.

    from exsce_dsl import api as exsce

    spec = exsce.load("examples/brsu_building_c/scenario_c.exsce")
    with exsce.open_store("memory:") as store:
        runs = exsce.simulate(spec, "runs", runs=3, seed=1)
        exsce.ingest(store, spec, [r.bag for r in runs])
        table = exsce.metrics(store, "scenario_c")

Each function says which command it is; errors are :class:`~exsce_dsl.errors.ExsceError`\\ s with
the same messages the command prints.
"""

from exsce_dsl.api.commands import (
    add_derived,
    baseline,
    check,
    cluster,
    compile_prov,
    derive,
    expect,
    ingest,
    load,
    open_store,
    simulate,
    verify,
)
from exsce_dsl.api.drafts import init_from_bag
from exsce_dsl.api.execution import execute_ros1
from exsce_dsl.api.explain import explain
from exsce_dsl.api.lineage import run_lineage
from exsce_dsl.api.stand_in import stand_in
from exsce_dsl.api.tables import metrics, query, rows_frame, segments, sparql, verdicts
from exsce_dsl.api.trials import flaky, verify_trial
from exsce_dsl.errors import RosGraphError
from exsce_dsl.store.checking import check_store
from exsce_dsl.store.migrating import migrate_store
from exsce_dsl.store.queries.run_ids import AmbiguousRunError, UnknownRunError, resolve_run

__all__ = [
    "AmbiguousRunError",
    "RosGraphError",
    "UnknownRunError",
    "add_derived",
    "baseline",
    "check",
    "check_store",
    "cluster",
    "compile_prov",
    "derive",
    "execute_ros1",
    "expect",
    "explain",
    "flaky",
    "ingest",
    "init_from_bag",
    "load",
    "metrics",
    "migrate_store",
    "open_store",
    "query",
    "resolve_run",
    "rows_frame",
    "run_lineage",
    "segments",
    "simulate",
    "sparql",
    "stand_in",
    "verdicts",
    "verify",
    "verify_trial",
]
