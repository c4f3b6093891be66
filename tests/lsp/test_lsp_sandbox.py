"""Issue 46: the language server reads no file outside its workspace, and never goes silent.  A
real LSP client (pytest-lsp) drives ``exscec lsp`` over stdio on a copy of brsu_building_c."""

from __future__ import annotations

from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pytest_lsp import ClientServerConfig, LanguageClient

from tests.support.lsp_helpers import (
    EXSCEC,
    change_document,
    close_document,
    copy_workspace,
    diagnostics_of,
    open_document,
    start_session,
    uri_of,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")

SECRET = "hunter2_secret_name"


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return copy_workspace(tmp_path_factory, "lsp-sandbox")


@pytest_lsp.fixture(scope="module", config=ClientServerConfig(server_command=[EXSCEC, "lsp"]))
async def client(lsp_client: LanguageClient, workspace: Path) -> AsyncIterator[None]:
    await start_session(lsp_client, workspace)
    yield
    await lsp_client.shutdown_session()


async def test_lsp_import_outside_workspace_refused(client: LanguageClient, workspace: Path) -> None:
    outside = workspace.parent / "outside"
    outside.mkdir()
    secret = outside / "secret.exsce"
    secret.write_text(f"robot type {SECRET} {{\n  %%% {SECRET}\n}}\n", encoding="utf-8")
    text = f'import "../outside/secret.exsce"\nimport "{secret}"\nimport "../outside/missing.exsce"\n'
    uri = open_document(client, workspace / "importer.exsce", text)
    found = await diagnostics_of(client, uri, lambda ds: len(ds) >= 3)
    assert sorted(d.range.start.line for d in found) == [0, 1, 2]
    for d in found:
        assert "is outside the workspace" in d.message and d.code == "import", d.message
        assert SECRET not in d.message
    # the words are the same whether the file exists or not: only the name written differs
    assert len({d.message.split("'")[2] for d in found}) == 1
    assert uri_of(secret) not in client.diagnostics  # it was never read, so it has no syntax error
    close_document(client, uri)


async def test_lsp_import_inside_workspace_still_read(client: LanguageClient, workspace: Path) -> None:
    uri = open_document(client, workspace / "scenario_c.exsce")
    assert await diagnostics_of(client, uri) == []
    close_document(client, uri)


async def test_lsp_publishes_internal_error(client: LanguageClient, workspace: Path) -> None:
    depth = 1000
    text = (
        "metric deep for each robot {\n"
        '  "nested"\n'
        "  unit s\n"
        '  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"\n'
        f"  value mean({'(' * depth}vel.angular.z{')' * depth})\n"
        "}\n"
    )
    uri = open_document(client, workspace / "deep.exsce", text)
    found = await diagnostics_of(client, uri, lambda ds: len(ds) > 0)
    assert any(d.severity == types.DiagnosticSeverity.Error for d in found)
    for d in found:
        if "internal error" in d.message:  # no better place known: the start of the document
            assert (d.range.start.line, d.range.start.character) == (0, 0)
            assert "nested too deeply" in d.message
    # the document fixed: the error goes
    change_document(client, uri, 2, text.replace("(" * depth, "(").replace(")" * depth, ")"))
    assert await diagnostics_of(client, uri, lambda ds: len(ds) == 0) == []
    close_document(client, uri)
