"""exsce from Python: the workflows of ``exscec``, with typed results, and the store's numbers as
pandas DataFrames.  This is the entry module; ``docs/python.md`` walks through it.

    from exsce_dsl import api as exsce

    spec = exsce.load("examples/brsu_building_c/scenario_c.exsce")
    with exsce.open_store("memory:") as store:
        runs = exsce.simulate(spec, "runs", runs=3, seed=1)
        exsce.ingest(store, spec, [r.bag for r in runs])
        table = exsce.metrics(store, "scenario_c")

Each function says which command it is; errors are :class:`~exsce_dsl.errors.ExsceError`\\ s with
the same messages the command prints.  ``exscec`` itself is a thin layer over this module: its
commands import nothing of exsce but this face, the errors and the model
(``tests/project/test_cli_imports.py``).

Each name is imported from its module the first time it is asked for, so that a command pays only
for what it uses (``exscec ingest`` does not import the SHACL shapes or pandas).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from exsce_dsl import __version__
    from exsce_dsl.api.answers import (
        ANSWER_FORMATS,
        QueryAnswer,
        answer_query,
        answer_sparql,
        answer_text,
        library_queries,
        results_csv,
        results_json,
        stored_runs,
    )
    from exsce_dsl.api.bags import describe_bags
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
        prov_text,
        simulate,
        simulating,
        verify,
    )
    from exsce_dsl.api.drafts import init_from_bag
    from exsce_dsl.api.execution import execute_ros1
    from exsce_dsl.api.explain import explain
    from exsce_dsl.api.exploring import Exploration, ExploreRequest, explore
    from exsce_dsl.api.ingesting import IngestTally, ingest_files, load_cached
    from exsce_dsl.api.lineage import RunLineage, ScenarioLineage, lineage_of, run_lineage
    from exsce_dsl.api.reporting import gather_report, write_report
    from exsce_dsl.api.serving import (
        UpdateToken,
        is_loopback,
        serve_endpoint,
        serve_lsp,
        serve_mcp,
        update_token,
    )
    from exsce_dsl.api.specs import (
        FormattedFile,
        export_spec,
        format_file,
        generate,
        import_oracle_file,
        import_scenario_file,
        is_oracle_file,
    )
    from exsce_dsl.api.stand_in import stand_in
    from exsce_dsl.api.store import (
        ClearedStore,
        StoreGraphs,
        StoreInfo,
        add_to_store,
        clear_store,
        export_store,
        open_store,
        store_graphs,
        store_info,
        store_url,
    )
    from exsce_dsl.api.tables import metrics, query, rows_frame, segments, sparql, verdicts
    from exsce_dsl.api.trials import flaky, verify_trial
    from exsce_dsl.codegen.targets import TARGETS, Target
    from exsce_dsl.errors import AmbiguousRunError, IngestFailed, RosGraphError, UnknownRunError
    from exsce_dsl.messages.msg_path import MSG_PATH
    from exsce_dsl.oracles import (
        REPEAT_FOLDER,
        REPEAT_SEED,
        Verification,
        junit_xml,
        pass_rate_table,
        pass_rates_csv,
        pass_rates_json,
        percent,
        trial_junit_xml,
        trial_of,
        verdict_table,
        verdicts_json,
    )
    from exsce_dsl.parallel.dask_client import dask_address
    from exsce_dsl.runs import BagInfo, IngestResult
    from exsce_dsl.similarity.dendrogram import save_dendrogram
    from exsce_dsl.store import QUERY_TIMEOUT, Rows, Store, check_store, migrate_store, resolve_run
    from exsce_dsl.tables import aligned
    from exsce_dsl.textfiles import read_text
    from exsce_dsl.transform import TRANSFORMATIONS
    from exsce_dsl.wording import counted

_SESSION: dict[str, str] = {
    # the workflows, as docs/python.md walks through them
    "load": "api.commands",
    "check": "api.commands",
    "compile_prov": "api.commands",
    "simulate": "api.commands",
    "ingest": "api.commands",
    "baseline": "api.commands",
    "verify": "api.commands",
    "derive": "api.commands",
    "add_derived": "api.commands",
    "expect": "api.commands",
    "cluster": "api.commands",
    "open_store": "api.store",
    "init_from_bag": "api.drafts",
    "execute_ros1": "api.execution",
    "explain": "api.explain",
    "run_lineage": "api.lineage",
    "stand_in": "api.stand_in",
    "metrics": "api.tables",
    "query": "api.tables",
    "rows_frame": "api.tables",
    "segments": "api.tables",
    "sparql": "api.tables",
    "verdicts": "api.tables",
    "flaky": "api.trials",
    "verify_trial": "api.trials",
    "check_store": "store",
    "migrate_store": "store",
    "resolve_run": "store",
    "AmbiguousRunError": "errors",
    "RosGraphError": "errors",
    "UnknownRunError": "errors",
}
"""The functions of a Python session (each shown on docs/python.md), and the module of each."""

_COMMAND_LINE: dict[str, str] = {
    # a command each, with typed results
    "simulating": "api.commands",
    "prov_text": "api.commands",
    "describe_bags": "api.bags",
    "store_info": "api.store",
    "StoreInfo": "api.store",
    "store_graphs": "api.store",
    "StoreGraphs": "api.store",
    "export_store": "api.store",
    "clear_store": "api.store",
    "ClearedStore": "api.store",
    "add_to_store": "api.store",
    "store_url": "api.store",
    "answer_query": "api.answers",
    "answer_sparql": "api.answers",
    "stored_runs": "api.answers",
    "library_queries": "api.answers",
    "QueryAnswer": "api.answers",
    "update_token": "api.serving",
    "UpdateToken": "api.serving",
    "is_loopback": "api.serving",
    "serve_endpoint": "api.serving",
    "serve_mcp": "api.serving",
    "serve_lsp": "api.serving",
    "lineage_of": "api.lineage",
    "RunLineage": "api.lineage",
    "ScenarioLineage": "api.lineage",
    "format_file": "api.specs",
    "is_oracle_file": "api.specs",
    "FormattedFile": "api.specs",
    "import_scenario_file": "api.specs",
    "import_oracle_file": "api.specs",
    "export_spec": "api.specs",
    "generate": "api.specs",
    "load_cached": "api.ingesting",
    "ingest_files": "api.ingesting",
    "IngestTally": "api.ingesting",
    "explore": "api.exploring",
    "ExploreRequest": "api.exploring",
    "Exploration": "api.exploring",
    "gather_report": "api.reporting",
    "write_report": "api.reporting",
    # what the commands print answers, verdicts and trials with
    "ANSWER_FORMATS": "api.answers",
    "answer_text": "api.answers",
    "results_csv": "api.answers",
    "results_json": "api.answers",
    "verdict_table": "oracles",
    "verdicts_json": "oracles",
    "junit_xml": "oracles",
    "pass_rate_table": "oracles",
    "pass_rates_csv": "oracles",
    "pass_rates_json": "oracles",
    "trial_junit_xml": "oracles",
    "percent": "oracles",
    "trial_of": "oracles",
    "save_dendrogram": "similarity.dendrogram",
    "aligned": "tables",
    "counted": "wording",
    "read_text": "textfiles",
    # the library's tables and constants the commands name in their options and help
    "__version__": "",
    "BagInfo": "runs",
    "IngestFailed": "errors",
    "MSG_PATH": "messages.msg_path",
    "QUERY_TIMEOUT": "store",
    "REPEAT_FOLDER": "oracles",
    "REPEAT_SEED": "oracles",
    "TARGETS": "codegen.targets",
    "Target": "codegen.targets",
    "TRANSFORMATIONS": "transform",
    "dask_address": "parallel.dask_client",
    # the types the commands' signatures name
    "IngestResult": "runs",
    "Rows": "store",
    "Store": "store",
    "Verification": "oracles",
}
"""What ``exscec``'s commands use besides the session's functions: a function per command with
its typed result, the renderers of answers, verdicts and trials, and the library's tables the
options name; each with its module (below ``exsce_dsl``)."""

_WHERE = {**_SESSION, **_COMMAND_LINE}

FOR_THE_COMMAND_LINE = frozenset(_COMMAND_LINE)
"""The names of :data:`__all__` that are there for ``exscec`` (docs/python.md shows the others)."""

__all__ = [
    "ANSWER_FORMATS",
    "AmbiguousRunError",
    "BagInfo",
    "ClearedStore",
    "Exploration",
    "ExploreRequest",
    "FormattedFile",
    "IngestFailed",
    "IngestResult",
    "IngestTally",
    "MSG_PATH",
    "QUERY_TIMEOUT",
    "QueryAnswer",
    "REPEAT_FOLDER",
    "REPEAT_SEED",
    "RosGraphError",
    "Rows",
    "RunLineage",
    "ScenarioLineage",
    "Store",
    "StoreGraphs",
    "StoreInfo",
    "TARGETS",
    "TRANSFORMATIONS",
    "Target",
    "UnknownRunError",
    "UpdateToken",
    "Verification",
    "__version__",
    "add_derived",
    "add_to_store",
    "aligned",
    "answer_query",
    "answer_sparql",
    "answer_text",
    "baseline",
    "check",
    "check_store",
    "clear_store",
    "cluster",
    "compile_prov",
    "counted",
    "dask_address",
    "derive",
    "describe_bags",
    "execute_ros1",
    "expect",
    "explain",
    "explore",
    "export_spec",
    "export_store",
    "flaky",
    "format_file",
    "gather_report",
    "generate",
    "import_oracle_file",
    "import_scenario_file",
    "ingest",
    "ingest_files",
    "init_from_bag",
    "is_loopback",
    "is_oracle_file",
    "junit_xml",
    "library_queries",
    "lineage_of",
    "load",
    "load_cached",
    "metrics",
    "migrate_store",
    "open_store",
    "pass_rate_table",
    "pass_rates_csv",
    "pass_rates_json",
    "percent",
    "prov_text",
    "query",
    "read_text",
    "resolve_run",
    "results_csv",
    "results_json",
    "rows_frame",
    "run_lineage",
    "save_dendrogram",
    "segments",
    "serve_endpoint",
    "serve_lsp",
    "serve_mcp",
    "simulate",
    "simulating",
    "sparql",
    "stand_in",
    "store_graphs",
    "store_info",
    "store_url",
    "stored_runs",
    "trial_junit_xml",
    "trial_of",
    "update_token",
    "verdict_table",
    "verdicts",
    "verdicts_json",
    "verify",
    "verify_trial",
    "write_report",
]
"""The face's index: every name of :data:`_WHERE`."""


def __getattr__(name: str) -> Any:
    """A name of the face, imported from its module when first asked for."""
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"exsce_dsl.{module}".rstrip(".")), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
