"""What the language server's end-to-end tests share: a workspace, a session, documents, waiting."""

from __future__ import annotations

import asyncio
import shutil
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.uris import from_fs_path
from pytest_lsp import LanguageClient

from tests.support.paths import EXAMPLES

EXSCEC = str(Path(sys.executable).with_name("exscec"))


def copy_workspace(tmp_path_factory: pytest.TempPathFactory, name: str) -> Path:
    """A copy of the brsu_building_c example, in a folder called ``bc``."""
    folder = tmp_path_factory.mktemp(name) / "bc"
    shutil.copytree(EXAMPLES / "brsu_building_c", folder)
    return folder


async def start_session(client: LanguageClient, workspace: Path, options: Any = None) -> None:
    uri = from_fs_path(str(workspace))
    await client.initialize_session(
        types.InitializeParams(
            capabilities=pytest_lsp.client_capabilities("visual-studio-code"),
            root_uri=uri,
            workspace_folders=[types.WorkspaceFolder(uri, "bc")],
            initialization_options=options,
        )
    )


def uri_of(path: Path) -> str:
    return from_fs_path(str(path)) or ""


def open_document(client: LanguageClient, path: Path, text: str | None = None) -> str:
    uri = uri_of(path)
    client.diagnostics.pop(uri, None)
    source = path.read_text() if text is None else text
    client.text_document_did_open(
        types.DidOpenTextDocumentParams(types.TextDocumentItem(uri, "exsce", 1, source))
    )
    return uri


def change_document(client: LanguageClient, uri: str, version: int, text: str) -> None:
    client.diagnostics.pop(uri, None)
    client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            types.VersionedTextDocumentIdentifier(version=version, uri=uri),
            [types.TextDocumentContentChangeWholeDocument(text)],
        )
    )


def close_document(client: LanguageClient, uri: str) -> None:
    client.text_document_did_close(types.DidCloseTextDocumentParams(types.TextDocumentIdentifier(uri)))


async def diagnostics_of(
    client: LanguageClient,
    uri: str,
    until: Callable[[Sequence[types.Diagnostic]], bool] = lambda found: True,
    timeout: float = 20.0,
) -> list[types.Diagnostic]:
    """The diagnostics published for ``uri`` once they satisfy ``until``."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    while True:
        found = client.diagnostics.get(uri)
        if found is not None and until(found):
            return list(found)
        if loop.time() > deadline:
            raise AssertionError(f"no such diagnostics for {uri}; last: {found}")
        await asyncio.sleep(0.02)


def position(text: str, needle: str, after: int = 0) -> types.Position:
    """The position ``after`` characters into the first ``needle`` of ``text``."""
    offset = text.index(needle) + after
    line = text.count("\n", 0, offset)
    return types.Position(line, offset - (text.rfind("\n", 0, offset) + 1))
