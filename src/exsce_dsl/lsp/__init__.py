"""The exsce language server: ``exscec lsp`` (pygls, on stdio)."""

from __future__ import annotations

from exsce_dsl.lsp.features import create_server, serve

__all__ = ["create_server", "serve"]
