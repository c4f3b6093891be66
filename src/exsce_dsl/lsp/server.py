"""The exsce language server's state (pygls 2): the project, the analysis scheduler, the
SHACL checks and the diagnostics published, with the conversions handlers share.

The handlers (:mod:`exsce_dsl.lsp.features`) are thin: they turn protocol positions
into exsce's, ask the project (:mod:`exsce_dsl.lsp.project`) or the modules beside
this one, and turn the answer back.  Analysis runs on a thread
(:mod:`exsce_dsl.lsp.scheduler`) and SHACL in a process (:mod:`exsce_dsl.lsp.shapes`),
so the event loop stays free.
"""

from __future__ import annotations

import os
from typing import Any

from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pygls.lsp.server import LanguageServer

from exsce_dsl import __version__
from exsce_dsl.errors import Diagnostic, ExsceError, SourceLocation
from exsce_dsl.lang import FileIndex
from exsce_dsl.lsp.convert import TextLines, lsp_diagnostic, path_of, uri_of
from exsce_dsl.lsp.navigation import NameAtPoint, Names
from exsce_dsl.lsp.project import OpenDocument, Project, RootAnalysis
from exsce_dsl.lsp.scheduler import Scheduler
from exsce_dsl.lsp.shapes import ShapeChecks
from exsce_dsl.textfiles import read_text

REQUEST_FAILED = -32803
"""LSP's error code for a request that is valid but cannot be done."""


class ExsceLanguageServer(LanguageServer):
    """The server's state: the project, the scheduler, SHACL checks and what was published."""

    def __init__(self) -> None:
        super().__init__("exsce", __version__, text_document_sync_kind=types.TextDocumentSyncKind.Incremental)
        self.project = Project()
        self.scheduler = Scheduler(self.project, self.open_documents, self.analysed)
        self.shape_checks = ShapeChecks(self.shapes_checked)
        self.shacl = True
        self.published: dict[str, list[Diagnostic]] = {}

    # --------------------------------------------------------------- documents
    def open_documents(self) -> dict[str, OpenDocument]:
        return {
            path_of(uri): OpenDocument(doc.source, doc.version)
            for uri, doc in self.workspace.text_documents.items()
            if uri.startswith("file:")
        }

    def text_of(self, path: str) -> str:
        """The text a path's positions refer to: the editor's, the analysed one, or the file's."""
        doc = self.workspace.text_documents.get(uri_of(path))
        if doc is not None:
            return str(doc.source)
        known = self.project.texts.get(path)
        if known is not None:
            return known
        try:
            return read_text(path)
        except ExsceError:
            return ""

    def lines_of(self, path: str) -> TextLines:
        return self.text_lines(self.text_of(path))

    def text_lines(self, text: str) -> TextLines:
        """``text``'s lines, converting columns in the position encoding agreed with the client."""
        return TextLines(text, str(self.workspace.position_encoding or "utf-16"))

    def location(self, loc: SourceLocation) -> types.Location:
        path = os.path.abspath(loc.file)
        return types.Location(uri_of(path), self.lines_of(path).range(loc))

    # ------------------------------------------------------------- diagnostics
    def analysed(self, results: list[RootAnalysis]) -> None:
        """After an analysis: publish (for each document analysed, even without news), then
        start the SHACL checks."""
        self.publish({a.root for a in results})
        if not self.shacl:
            return
        for analysis in results:
            if analysis.spec is not None:
                self.shape_checks.request(analysis.root, analysis.generation, analysis.spec)

    def shapes_checked(self, root: str, generation: int, found: list[Diagnostic]) -> None:
        if self.project.set_shapes(root, generation, found):
            self.publish()

    def publish(self, always: set[str] | None = None) -> None:
        """Publish every file's diagnostics that changed (and those of ``always``)."""
        current = self.project.diagnostics()
        versions = self.project.latest_versions()
        for path in sorted(set(current) | set(self.published) | (always or set())):
            found = current.get(path, [])
            if found == self.published.get(path, []) and path not in (always or set()):
                continue
            lines = self.text_lines(self.project.texts.get(path, ""))
            self.text_document_publish_diagnostics(
                types.PublishDiagnosticsParams(
                    uri=uri_of(path),
                    diagnostics=[lsp_diagnostic(d, lines) for d in found],
                    version=versions.get(path),
                )
            )
            if found:
                self.published[path] = found
            else:
                self.published.pop(path, None)

    # --------------------------------------------------------------- positions
    def index_of(self, uri: str) -> tuple[str, FileIndex | None]:
        path = path_of(uri)
        return path, self.project.indexes.get(path)

    def point(self, uri: str, position: types.Position) -> tuple[int, int]:
        """1-based (line, column) in characters of an LSP position."""
        lines = self.lines_of(path_of(uri))
        return lines.location(lines.offset(position))

    async def target(self, uri: str, position: types.Position) -> tuple[Names, NameAtPoint | None]:
        """The name at a point, once the latest text is analysed."""
        await self.scheduler.settled()
        path, index = self.index_of(uri)
        names = Names(self.project.visible_indexes(path), self.project.reachable(path))
        if index is None:
            return names, None
        return names, names.target_at(index, *self.point(uri, position))

    def source(self, loc: SourceLocation) -> str | None:
        path = os.path.abspath(loc.file)
        text = self.text_of(path)
        return TextLines(text).slice(loc) if text else None


def failed(message: str) -> JsonRpcException:
    """An error the client shows: the request cannot be done, and why."""
    return JsonRpcException(message, code=REQUEST_FAILED)


def options_of(params: types.InitializeParams) -> dict[str, Any]:
    options = params.initialization_options
    return options if isinstance(options, dict) else {}
