"""The protocol's features, each a thin handler over the modules of this package, and the
server that has them (``exscec lsp``)."""

from __future__ import annotations

import contextlib
import os

from lsprotocol import types

from exsce_dsl.errors import RenameError
from exsce_dsl.lang import comments, continuations_at, display_path, format_spec_document, import_target
from exsce_dsl.lsp.actions import quick_fixes
from exsce_dsl.lsp.completion import complete
from exsce_dsl.lsp.convert import path_of, uri_of
from exsce_dsl.lsp.fields import field_hover, offers
from exsce_dsl.lsp.hover import keyword_hover, symbol_hover, word_at
from exsce_dsl.lsp.navigation import RENAMEABLE, Names, import_at
from exsce_dsl.lsp.outline import document_symbol, workspace_symbols
from exsce_dsl.lsp.server import ExsceLanguageServer, failed, options_of

FIRST_ANALYSIS_WAIT = 5.0
"""Seconds a document's first completion waits for its first analysis (its imports' names)."""


async def _first_analysis(ls: ExsceLanguageServer, path: str) -> None:
    """Wait for a just-opened document's first analysis, which indexes what it imports (later
    completions answer at once from the last analysis, whatever is typed)."""
    if path not in ls.project.roots:
        with contextlib.suppress(TimeoutError):
            await ls.scheduler.settled(FIRST_ANALYSIS_WAIT)


def create_server() -> ExsceLanguageServer:
    """A server with every feature registered."""
    server = ExsceLanguageServer()
    register(server)
    return server


def serve(tcp: tuple[str, int] | None = None) -> None:
    """Run the server on stdio, or on TCP at ``tcp`` (host, port) for debugging."""
    server = create_server()
    try:
        if tcp is None:
            server.start_io()
        else:
            server.start_tcp(*tcp)
    finally:
        server.scheduler.shutdown()
        server.shape_checks.shutdown()


def register(server: ExsceLanguageServer) -> None:
    _documents(server)
    _editing(server)
    _navigation(server)
    _changes(server)


def _documents(server: ExsceLanguageServer) -> None:
    @server.feature(types.INITIALIZE)
    def initialize(ls: ExsceLanguageServer, params: types.InitializeParams) -> None:
        ls.shacl = bool(options_of(params).get("shacl", True))

    @server.feature(types.TEXT_DOCUMENT_DID_OPEN)
    def did_open(ls: ExsceLanguageServer, params: types.DidOpenTextDocumentParams) -> None:
        ls.scheduler.touch(path_of(params.text_document.uri), delay=0.0)

    @server.feature(types.TEXT_DOCUMENT_DID_CHANGE)
    def did_change(ls: ExsceLanguageServer, params: types.DidChangeTextDocumentParams) -> None:
        ls.scheduler.touch(path_of(params.text_document.uri))

    @server.feature(types.TEXT_DOCUMENT_DID_CLOSE)
    async def did_close(ls: ExsceLanguageServer, params: types.DidCloseTextDocumentParams) -> None:
        path = path_of(params.text_document.uri)
        ls.shape_checks.forget(path)
        await ls.scheduler.run(ls.project.close, path, ls.open_documents())
        ls.publish()
        ls.scheduler.touch(path)  # the documents that read it read the file on disk now

    @server.feature(types.INITIALIZED)
    async def initialized(ls: ExsceLanguageServer, params: types.InitializedParams) -> None:
        folders = [path_of(f.uri) for f in ls.workspace.folders.values()]
        if not folders and ls.workspace.root_path:
            folders = [ls.workspace.root_path]
        ls.project.workspace = tuple(os.path.abspath(f) for f in folders)
        await ls.scheduler.run(ls.project.scan, folders)


def _editing(server: ExsceLanguageServer) -> None:
    @server.feature(
        types.TEXT_DOCUMENT_COMPLETION,
        types.CompletionOptions(trigger_characters=[" ", ",", ":", ".", "["]),
    )
    async def completion(ls: ExsceLanguageServer, params: types.CompletionParams) -> types.CompletionList:
        path = path_of(params.text_document.uri)
        await _first_analysis(ls, path)
        text = ls.workspace.get_text_document(params.text_document.uri).source
        lines = ls.text_lines(text)
        offset = lines.offset(params.position)
        allowed = continuations_at(text, offset)
        if allowed is None:
            return types.CompletionList(is_incomplete=False, items=[])
        names = Names(ls.project.visible_indexes(path, last_complete=True), ls.project.reachable(path))
        start = lines.position(*lines.location(allowed.word_start))
        capabilities = ls.client_capabilities.text_document
        item = capabilities.completion.completion_item if capabilities and capabilities.completion else None
        snippets = bool(item and item.snippet_support)
        typed = text[allowed.word_start : offset]
        offer = None
        if allowed.declaration == "metric":
            offer = offers(text, offset, allowed.word_start, "message type" in allowed.others)
        if offer is not None and offer.start != allowed.word_start:  # a message type holds '/'
            start = lines.position(*lines.location(offer.start))
            typed = text[offer.start : offset]
        offered = offer.items if offer is not None else []
        return complete(allowed, names, typed, types.Range(start, params.position), snippets, offered)

    @server.feature(types.TEXT_DOCUMENT_HOVER)
    async def hover(ls: ExsceLanguageServer, params: types.HoverParams) -> types.Hover | None:
        names, target = await ls.target(params.text_document.uri, params.position)
        path = path_of(params.text_document.uri)
        lines = ls.lines_of(path)
        if target is not None:
            text = symbol_hover(names, target, ls.source)
            where = lines.range(target.location)
        else:
            word = word_at(lines.text, lines.offset(params.position))
            if word is None:
                return None
            text = field_hover(lines.text, word[1], word[2]) or keyword_hover(word[0])
            where = types.Range(
                lines.position(*lines.location(word[1])), lines.position(*lines.location(word[2]))
            )
        if text is None:
            return None
        return types.Hover(types.MarkupContent(types.MarkupKind.Markdown, text), where)

    @server.feature(types.TEXT_DOCUMENT_FORMATTING)
    async def formatting(
        ls: ExsceLanguageServer, params: types.DocumentFormattingParams
    ) -> list[types.TextEdit]:
        await ls.scheduler.settled()
        path = path_of(params.text_document.uri)
        document = ls.workspace.get_text_document(params.text_document.uri)
        analysis = ls.project.roots.get(path)
        if analysis is None or analysis.versions.get(path) != document.version:
            raise failed("the document is not analysed yet; try again")
        if analysis.spec is None:
            errors = sum(d.is_error for ds in analysis.diagnostics.values() for d in ds)
            raise failed(f"cannot format: the specification has {errors} error{'s' if errors != 1 else ''}")
        shown = display_path(path)
        text = document.source
        formatted = format_spec_document(analysis.spec, shown, comments(text, shown))
        if formatted == text:
            return []
        lines = ls.text_lines(text)
        end = lines.position(*lines.location(len(text)))
        return [types.TextEdit(types.Range(types.Position(0, 0), end), formatted)]

    @server.feature(
        types.TEXT_DOCUMENT_CODE_ACTION,
        types.CodeActionOptions(code_action_kinds=[types.CodeActionKind.QuickFix]),
    )
    def code_action(ls: ExsceLanguageServer, params: types.CodeActionParams) -> list[types.CodeAction]:
        text = ls.workspace.get_text_document(params.text_document.uri).source
        return quick_fixes(params.text_document.uri, ls.text_lines(text), list(params.context.diagnostics))


def _navigation(server: ExsceLanguageServer) -> None:
    @server.feature(types.TEXT_DOCUMENT_DEFINITION)
    async def definition(ls: ExsceLanguageServer, params: types.DefinitionParams) -> list[types.Location]:
        names, target = await ls.target(params.text_document.uri, params.position)
        if target is None:
            path, index = ls.index_of(params.text_document.uri)
            written = (
                import_at(index, *ls.point(params.text_document.uri, params.position)) if index else None
            )
            if written is None:
                return []
            imported = os.path.abspath(import_target(display_path(path), written))
            start = types.Position(0, 0)
            return [types.Location(uri_of(imported), types.Range(start, start))]
        return [ls.location(s.location) for s in names.definitions(target)]

    @server.feature(types.TEXT_DOCUMENT_REFERENCES)
    async def references(ls: ExsceLanguageServer, params: types.ReferenceParams) -> list[types.Location]:
        names, target = await ls.target(params.text_document.uri, params.position)
        if target is None:
            return []
        return [ls.location(loc) for loc in names.references(target, params.context.include_declaration)]

    @server.feature(types.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
    async def document_symbols(
        ls: ExsceLanguageServer, params: types.DocumentSymbolParams
    ) -> list[types.DocumentSymbol]:
        await ls.scheduler.settled()
        path, index = ls.index_of(params.text_document.uri)
        lines = ls.lines_of(path)
        return [document_symbol(s, lines) for s in index.symbols] if index else []

    @server.feature(types.WORKSPACE_SYMBOL)
    async def symbols(
        ls: ExsceLanguageServer, params: types.WorkspaceSymbolParams
    ) -> list[types.WorkspaceSymbol]:
        await ls.scheduler.settled()
        return workspace_symbols(ls.project.visible_indexes(), params.query, ls.location)


def _changes(server: ExsceLanguageServer) -> None:
    @server.feature(types.TEXT_DOCUMENT_PREPARE_RENAME)
    async def prepare_rename(
        ls: ExsceLanguageServer, params: types.PrepareRenameParams
    ) -> types.PrepareRenamePlaceholder | None:
        _, target = await ls.target(params.text_document.uri, params.position)
        if target is None or target.kind not in RENAMEABLE:
            return None
        lines = ls.lines_of(path_of(params.text_document.uri))
        return types.PrepareRenamePlaceholder(lines.range(target.location), target.name)

    @server.feature(types.TEXT_DOCUMENT_RENAME)
    async def rename(ls: ExsceLanguageServer, params: types.RenameParams) -> types.WorkspaceEdit:
        names, target = await ls.target(params.text_document.uri, params.position)
        if target is None:
            raise failed("there is no name to rename here")
        try:
            places = names.rename(target, params.new_name, ls.project.library)
        except RenameError as exc:
            raise failed(str(exc)) from None
        changes: dict[str, list[types.TextEdit]] = {}
        for loc in places:
            where = ls.location(loc)
            changes.setdefault(where.uri, []).append(types.TextEdit(where.range, params.new_name))
        return types.WorkspaceEdit(changes=changes)
