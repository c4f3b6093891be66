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

# mypy: implicit-reexport
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the functions of a Python session, as docs/python.md walks through them
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
        simulate,
        verify,
    )
    from exsce_dsl.api.drafts import init_from_bag
    from exsce_dsl.api.execution import execute_ros1, execute_ros2
    from exsce_dsl.api.explain import explain
    from exsce_dsl.api.lineage import run_lineage
    from exsce_dsl.api.stand_in import stand_in, stand_in_ros2
    from exsce_dsl.api.store import open_store
    from exsce_dsl.api.tables import metrics, query, rows_frame, segments, sparql, verdicts
    from exsce_dsl.api.trials import flaky, verify_trial
    from exsce_dsl.errors import AmbiguousRunError, RosGraphError, UnknownRunError
    from exsce_dsl.store import check_store, migrate_store, resolve_run

if TYPE_CHECKING:  # what exscec's commands use besides (docs/python.md need not show these)
    # a function per command with its typed result, the renderers of answers, verdicts and
    # trials, the library's tables and constants the options name, the types of the signatures
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
    from exsce_dsl.api.commands import prov_text, simulating
    from exsce_dsl.api.exploring import Exploration, ExploreRequest, explore
    from exsce_dsl.api.ingesting import IngestTally, ingest_files, load_cached
    from exsce_dsl.api.lineage import RunLineage, ScenarioLineage, lineage_of
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
    from exsce_dsl.api.store import (
        ClearedStore,
        StoreGraphs,
        StoreInfo,
        add_to_store,
        clear_store,
        export_store,
        store_graphs,
        store_info,
        store_url,
    )
    from exsce_dsl.codegen.targets import TARGETS, GenerationTarget
    from exsce_dsl.errors import IngestFailed
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
    from exsce_dsl.store import QUERY_TIMEOUT, QueryTimes, Rows, Store, timing_queries
    from exsce_dsl.tables import aligned
    from exsce_dsl.textfiles import read_text
    from exsce_dsl.transform import TRANSFORMATIONS
    from exsce_dsl.wording import counted
else:
    from exsce_dsl.faces import lazy_face

    __getattr__, __dir__ = lazy_face(__name__, __file__)
