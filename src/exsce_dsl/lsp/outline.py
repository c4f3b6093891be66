"""Document symbols (a file's outline, nested as its declarations are) and workspace symbols."""

from __future__ import annotations

from collections.abc import Callable, Iterable

from lsprotocol import types

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang import FileIndex, Symbol
from exsce_dsl.lsp.convert import TextLines

_SYMBOL_KINDS = {
    "robot type": types.SymbolKind.Class,
    "environment": types.SymbolKind.Module,
    "area": types.SymbolKind.Namespace,
    "pose": types.SymbolKind.Constant,
    "obstacle": types.SymbolKind.Struct,
    "map": types.SymbolKind.File,
    "world": types.SymbolKind.File,
    "task": types.SymbolKind.Function,
    "scenario": types.SymbolKind.Module,
    "robot": types.SymbolKind.Variable,
    "mission": types.SymbolKind.Event,
    "metric": types.SymbolKind.Field,
    "acceptance": types.SymbolKind.Interface,
    "criterion": types.SymbolKind.Method,
}


def symbol_kind(symbol: Symbol) -> types.SymbolKind:
    return _SYMBOL_KINDS.get(symbol.kind, types.SymbolKind.Object)


def document_symbol(symbol: Symbol, lines: TextLines) -> types.DocumentSymbol:
    """``symbol`` and its children, placed in the text of ``lines``."""
    detail = symbol.fact("at") or symbol.fact("environment") or symbol.fact("derived from") or symbol.kind
    return types.DocumentSymbol(
        name=symbol.name,
        kind=symbol_kind(symbol),
        range=lines.range(symbol.extent),
        selection_range=lines.range(symbol.location),
        detail=detail,
        children=[document_symbol(child, lines) for child in symbol.children],
    )


def workspace_symbols(
    indexes: Iterable[FileIndex], query: str, location: Callable[[SourceLocation], types.Location]
) -> list[types.WorkspaceSymbol]:
    """Every declaration whose name holds ``query`` (ignoring case)."""
    wanted = query.lower()
    return [
        types.WorkspaceSymbol(
            name=symbol.name,
            kind=symbol_kind(symbol),
            location=location(symbol.location),
            container_name=symbol.scope or "",
        )
        for index in indexes
        for symbol in index.all_symbols()
        if wanted in symbol.name.lower()
    ]
