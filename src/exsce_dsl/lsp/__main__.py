"""``python -m exsce_dsl.lsp``: the language server on stdio."""

from exsce_dsl.lsp.features import serve

serve()
