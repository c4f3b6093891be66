"""A document's first completion, asked the moment it is opened with a syntax error in it.

Regression: ``test_completion_in_a_mission_and_in_criteria`` failed on a loaded CI machine. The
completion came before the document's first analysis, so the metrics of the file it imports were
not offered; and once that analysis had read the broken text, its own robots were gone too (the
workspace scan kept no index "without syntax errors" to fall back on).  Here the server is fresh
for each test, so nothing an earlier test opened can hide either.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pytest_lsp import ClientServerConfig, LanguageClient

from tests.support.lsp_helpers import (
    EXSCEC,
    copy_workspace,
    diagnostics_of,
    open_document,
    position,
    start_session,
)

pytestmark = pytest.mark.asyncio(loop_scope="function")


@pytest.fixture
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return copy_workspace(tmp_path_factory, "first")


@pytest_lsp.fixture(config=ClientServerConfig(server_command=[EXSCEC, "lsp"]))
async def client(lsp_client: LanguageClient, workspace: Path) -> AsyncIterator[None]:
    await start_session(lsp_client, workspace)
    yield
    await lsp_client.shutdown_session()


async def _labels(client: LanguageClient, uri: str, text: str, needle: str) -> set[str]:
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), position(text, needle, len(needle)))
    )
    assert isinstance(result, types.CompletionList)
    return {item.label for item in result.items}


async def test_the_first_completion_offers_the_imported_metrics(
    client: LanguageClient, workspace: Path
) -> None:
    path = workspace / "scenario_c.exsce"
    text = path.read_text().replace(
        "    then tiago1 max_velocity stays below 0.8 m/s", "    then each robot "
    )
    uri = open_document(client, path, text)
    metrics = await _labels(client, uri, text, "    then each robot ")
    assert "fast_driving_time" in metrics  # declared in metrics.exsce, which scenario_c imports
    assert "max_velocity" in metrics


async def test_a_broken_first_version_still_completes_its_own_robots(
    client: LanguageClient, workspace: Path
) -> None:
    path = workspace / "scenario_c.exsce"
    text = path.read_text().replace(
        "    tiago2 does navigate_home_2\n", "    tiago2 does navigate_home_2\n    ti\n"
    )
    uri = open_document(client, path, text)
    assert await diagnostics_of(client, uri, lambda found: len(found) > 0)  # analysed: broken
    assert await _labels(client, uri, text, "navigate_home_2\n    ti") == {"tiago1", "tiago2"}
