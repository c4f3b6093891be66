"""Every kind of library parameter has a JSON schema in the MCP tools: a kind without one would
reach the library as any string (a run id with a brace, say) and fail there, not at the door."""

from __future__ import annotations

from exsce_dsl.mcp_server.library_tools import _KIND_SCHEMAS, query_tool
from exsce_dsl.store.queries.library import FROM_RUNS, KINDS, query


def test_every_parameter_kind_has_a_schema_and_ids_have_a_pattern() -> None:
    assert set(KINDS) - FROM_RUNS == set(_KIND_SCHEMAS)
    free = {"string", "double"}  # any text, any number
    for kind, schema in _KIND_SCHEMAS.items():
        assert kind in free or "pattern" in schema, kind


def test_a_runs_graphs_are_never_offered_only_its_runs() -> None:
    """run_lineage names its run's bundle: bound from the run given, not a tool parameter."""
    schema = query_tool(query("run_lineage")).input_schema
    assert set(schema["properties"]) == {"run"} and schema["required"] == ["run"]
