"""The language server end to end, continued: go to definition, references, renaming,
formatting, quick fixes and symbols, driven by a real LSP client over stdio."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pytest_lsp import ClientServerConfig, LanguageClient

from tests.support.cli import run_exscec
from tests.support.lsp_helpers import (
    EXSCEC,
    close_document,
    copy_workspace,
    diagnostics_of,
    open_document,
    position,
    start_session,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return copy_workspace(tmp_path_factory, "lsp-nav")


@pytest_lsp.fixture(scope="module", config=ClientServerConfig(server_command=[EXSCEC, "lsp"]))
async def client(lsp_client: LanguageClient, workspace: Path) -> AsyncIterator[None]:
    await start_session(lsp_client, workspace, {"shacl": False})
    yield
    await lsp_client.shutdown_session()


def where(location: types.Location) -> tuple[str, int, int, int, int]:
    """A location as (file name relative to the workspace, start line, start char, end line, end char)."""
    r = location.range
    return (location.uri.rsplit("/bc/", 1)[-1], r.start.line, r.start.character, r.end.line, r.end.character)


def apply(text: str, edits: list[types.TextEdit]) -> str:
    """``text`` with ``edits`` made (LSP positions; ASCII text)."""
    lines = text.split("\n")
    starts = [0]
    for line in lines[:-1]:
        starts.append(starts[-1] + len(line) + 1)

    def offset(p: types.Position) -> int:
        return starts[p.line] + p.character

    for edit in sorted(edits, key=lambda e: offset(e.range.start), reverse=True):
        text = text[: offset(edit.range.start)] + edit.new_text + text[offset(edit.range.end) :]
    return text




# ------------------------------------------------------------------- definition
async def test_go_to_a_definition_in_an_imported_file(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "scenario_c.exsce"
    text = path.read_text()
    uri = open_document(client, path)
    doc = types.TextDocumentIdentifier(uri)
    task = await client.text_document_definition_async(
        types.DefinitionParams(doc, position(text, "does delivery_a", 7))
    )
    assert isinstance(task, list)
    assert [where(loc) for loc in task] == [("tasks/deliveries.exsce", 2, 5, 2, 15)]
    pose = await client.text_document_definition_async(
        types.DefinitionParams(doc, position(text, "classroom_c025-w002", 0))
    )
    assert isinstance(pose, list)
    assert [where(loc) for loc in pose] == [("environment.exsce", 6, 9, 6, 28)]
    robot = await client.text_document_definition_async(
        types.DefinitionParams(doc, position(text, "    tiago2 does delivery_b", 5))
    )
    assert isinstance(robot, list)
    assert [where(loc) for loc in robot] == [("scenario_c.exsce", 9, 4, 9, 10)]
    imported = await client.text_document_definition_async(
        types.DefinitionParams(doc, position(text, "robots.exsce"))
    )
    assert isinstance(imported, list)
    assert [where(loc)[0] for loc in imported] == ["robots.exsce"]
    close_document(client, uri)


async def test_a_robot_of_a_derived_scenario_is_its_base_s(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "scenario_c_alone.exsce"
    text = path.read_text()
    uri = open_document(client, path)
    found = await client.text_document_definition_async(
        types.DefinitionParams(types.TextDocumentIdentifier(uri), position(text, "reassign to tiago1", 13))
    )
    assert isinstance(found, list)
    assert [where(loc) for loc in found] == [("scenario_c.exsce", 8, 4, 8, 10)]
    close_document(client, uri)


# ------------------------------------------------------------------- references
async def test_find_references_of_a_pose_across_files(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "environment.exsce"
    text = path.read_text()
    uri = open_document(client, path)
    found = await client.text_document_references_async(
        types.ReferenceParams(
            context=types.ReferenceContext(include_declaration=True),
            text_document=types.TextDocumentIdentifier(uri),
            position=position(text, "pose classroom_c022-w001", 7),
        )
    )
    assert found is not None
    assert sorted(where(loc) for loc in found) == [
        ("environment.exsce", 10, 9, 10, 28),
        ("tasks/deliveries.exsce", 4, 8, 4, 27),
        ("tasks/deliveries.exsce", 16, 8, 16, 27),
        ("tasks/deliveries.exsce", 23, 10, 23, 29),
    ]
    close_document(client, uri)


# ----------------------------------------------------------------------- rename
async def test_rename_a_task_everywhere_it_is_named(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "tasks" / "deliveries.exsce"
    text = path.read_text()
    uri = open_document(client, path)
    edit = await client.text_document_rename_async(
        types.RenameParams(
            types.TextDocumentIdentifier(uri), position(text, "task delivery_a", 7), "first_delivery"
        )
    )
    assert edit is not None and edit.changes is not None
    by_file = {u.rsplit("/bc/", 1)[-1]: edits for u, edits in edit.changes.items()}
    assert sorted(by_file) == [
        "scenario_c.exsce",
        "scenario_c_alone.exsce",
        "scenario_d.exsce",
        "tasks/deliveries.exsce",
    ]
    renamed = apply((workspace / "scenario_c.exsce").read_text(), by_file["scenario_c.exsce"])
    assert renamed == (workspace / "scenario_c.exsce").read_text().replace("delivery_a", "first_delivery")
    assert "tiago1 does first_delivery\n" in renamed and "when tiago1 does first_delivery\n" in renamed
    assert apply(text, by_file["tasks/deliveries.exsce"]) == text.replace(
        "task delivery_a", "task first_delivery"
    )
    alone = apply((workspace / "scenario_c_alone.exsce").read_text(), by_file["scenario_c_alone.exsce"])
    assert "reverse waypoints of first_delivery\n" in alone
    close_document(client, uri)


async def test_rename_refuses_an_invalid_or_taken_name(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "tasks" / "deliveries.exsce"
    text = path.read_text()
    uri = open_document(client, path)
    at = position(text, "task delivery_a", 7)
    with pytest.raises(JsonRpcException, match="'visit' is not a valid id"):
        await client.text_document_rename_async(
            types.RenameParams(types.TextDocumentIdentifier(uri), at, "visit")
        )
    with pytest.raises(JsonRpcException, match="'2nd' is not a valid id"):
        await client.text_document_rename_async(
            types.RenameParams(types.TextDocumentIdentifier(uri), at, "2nd")
        )
    with pytest.raises(JsonRpcException, match="there is already a task 'delivery_b'"):
        await client.text_document_rename_async(
            types.RenameParams(types.TextDocumentIdentifier(uri), at, "delivery_b")
        )
    close_document(client, uri)


async def test_rename_a_robot_renames_it_in_its_scenario_only(
    client: LanguageClient, workspace: Path
) -> None:
    path = workspace / "scenario_c.exsce"
    text = path.read_text()
    uri = open_document(client, path)
    edit = await client.text_document_rename_async(
        types.RenameParams(types.TextDocumentIdentifier(uri), position(text, "tiago1: tiago"), "alpha")
    )
    assert edit is not None and edit.changes is not None
    by_file = {u.rsplit("/bc/", 1)[-1]: edits for u, edits in edit.changes.items()}
    assert sorted(by_file) == ["scenario_c.exsce", "scenario_c_alone.exsce"]  # not scenario_d's own tiago1
    assert apply(text, by_file["scenario_c.exsce"]).count("alpha") == text.count("tiago1")
    close_document(client, uri)


# ------------------------------------------------------------ formatting, fixes
async def test_formatting_gives_what_exscec_fmt_writes(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "robots.exsce"
    messy = "robot type tiago {   base pmb2\n torso yes }\n\n\n// a comment\nrobot type pmb2 { base pmb2 torso no }\n"
    uri = open_document(client, path, messy)
    edits = await client.text_document_formatting_async(
        types.DocumentFormattingParams(types.TextDocumentIdentifier(uri), types.FormattingOptions(2, True))
    )
    assert edits is not None
    copy = workspace.parent / "fmt" / "robots.exsce"
    copy.parent.mkdir(exist_ok=True)
    copy.write_text(messy)
    result = run_exscec("fmt", str(copy))
    assert result.returncode == 0, result.stderr
    assert apply(messy, list(edits)) == copy.read_text() != messy
    close_document(client, uri)


async def test_formatting_a_file_with_errors_is_refused(client: LanguageClient, workspace: Path) -> None:
    uri = open_document(client, workspace / "robots.exsce", "robot type tiago { base }\n")
    with pytest.raises(JsonRpcException, match="cannot format: the specification has 1 error"):
        await client.text_document_formatting_async(
            types.DocumentFormattingParams(
                types.TextDocumentIdentifier(uri), types.FormattingOptions(2, True)
            )
        )
    close_document(client, uri)


async def test_a_quick_fix_writes_the_suggested_name(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "tasks" / "navigation.exsce"
    text = path.read_text().replace("visit classroom_c025-w002", "visit c025-w02")
    uri = open_document(client, path, text)
    (diagnostic,) = await diagnostics_of(client, uri, lambda found: len(found) == 1)
    actions = await client.text_document_code_action_async(
        types.CodeActionParams(
            types.TextDocumentIdentifier(uri), diagnostic.range, types.CodeActionContext([diagnostic])
        )
    )
    assert actions is not None
    (action,) = actions
    assert isinstance(action, types.CodeAction)
    assert action.title == "Change 'c025-w02' to 'classroom_c025-w002'"
    assert action.kind == types.CodeActionKind.QuickFix
    assert action.edit is not None and action.edit.changes is not None
    assert apply(text, list(action.edit.changes[uri])) == path.read_text()
    close_document(client, uri)


# ---------------------------------------------------------------------- symbols
async def test_document_symbols_are_an_outline(client: LanguageClient, workspace: Path) -> None:
    uri = open_document(client, workspace / "environment.exsce")
    found = await client.text_document_document_symbol_async(
        types.DocumentSymbolParams(types.TextDocumentIdentifier(uri))
    )
    assert found is not None
    (environment,) = found
    assert isinstance(environment, types.DocumentSymbol) and environment.children is not None
    assert environment.name == "brsu_building_c_with_doors"
    assert environment.kind == types.SymbolKind.Module
    areas = [c for c in environment.children if c.kind == types.SymbolKind.Namespace]
    assert [a.name for a in areas] == [
        "classroom_c025",
        "classroom_c022",
        "classroom_c018",
        "classroom_c069",
        "right_long_corridor",
        "left_long_corridor",
    ]
    assert areas[0].children is not None
    assert [p.name for p in areas[0].children] == ["classroom_c025-w001", "classroom_c025-w002"]
    first = areas[0].children[0]
    assert (first.selection_range.start.line, first.selection_range.start.character) == (5, 9)
    assert (first.range.start.line, first.range.end.line) == (5, 5)
    close_document(client, uri)


async def test_workspace_symbols_find_declarations_in_every_file(
    client: LanguageClient, workspace: Path
) -> None:
    found = await client.workspace_symbol_async(types.WorkspaceSymbolParams("delivery_"))
    assert found is not None
    names = {
        (s.name, s.location.uri.rsplit("/bc/", 1)[-1])
        for s in found
        if isinstance(s.location, types.Location)
    }
    assert {("delivery_a", "tasks/deliveries.exsce"), ("delivery_d", "tasks/deliveries.exsce")} <= names


# -------------------------------------------------------------------------- tcp
async def test_exscec_lsp_listens_on_tcp_for_debugging(workspace: Path, unused_tcp_port: int) -> None:
    from pygls.lsp.client import LanguageClient as PlainClient

    server = await asyncio.create_subprocess_exec(EXSCEC, "lsp", "--tcp", f"127.0.0.1:{unused_tcp_port}")
    try:
        client = PlainClient("tcp-test", "1")
        for _ in range(100):  # until it listens
            try:
                await client.start_tcp("127.0.0.1", unused_tcp_port)
                break
            except OSError:
                await asyncio.sleep(0.1)
        result = await client.initialize_async(
            types.InitializeParams(capabilities=types.ClientCapabilities())
        )
        assert result.server_info is not None and result.server_info.name == "exsce"
        assert result.capabilities.rename_provider and result.capabilities.completion_provider
        await client.shutdown_async(None)
        client.exit(None)
        await client.stop()
    finally:
        if server.returncode is None:
            server.kill()
        await server.wait()


async def test_a_bad_tcp_address_is_a_usage_error() -> None:
    result = run_exscec("lsp", "--tcp", "nowhere")
    assert result.returncode == 2
    assert "expected HOST:PORT, got 'nowhere'" in result.stderr


async def test_a_built_in_metric_cannot_be_renamed(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "scenario_c.exsce"
    text = path.read_text()
    uri = open_document(client, path)
    at = position(text, "max_velocity", 2)
    with pytest.raises(JsonRpcException, match="'max_velocity' is one of exsce's built-in metrics"):
        await client.text_document_rename_async(types.RenameParams(types.TextDocumentIdentifier(uri), at, "speed"))
    close_document(client, uri)
