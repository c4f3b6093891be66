"""Every kind of library parameter has a JSON schema in the MCP tools: a kind without one would
reach the library as any string (a run id with a brace, say) and fail there, not at the door."""

from __future__ import annotations

from exsce_dsl.mcp_server.library_tools import _KIND_SCHEMAS
from exsce_dsl.store.queries.library import KINDS


def test_every_parameter_kind_has_a_schema_and_ids_have_a_pattern() -> None:
    assert set(KINDS) == set(_KIND_SCHEMAS)
    free = {"string", "double"}  # any text, any number
    for kind, schema in _KIND_SCHEMAS.items():
        assert kind in free or "pattern" in schema, kind
