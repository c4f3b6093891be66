"""``exscec lsp``: the language server, for editors."""

from __future__ import annotations

import click

from exsce_dsl.cli.common import reports_errors


def _address(text: str) -> tuple[str, int]:
    host, _, port = text.rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise click.BadParameter(f"expected HOST:PORT, got {text!r}", param_hint="--tcp")
    return host, int(port)


@click.command()
@click.option("--tcp", "tcp", metavar="HOST:PORT", help="Listen on TCP instead of stdio (for debugging).")
@click.option("--stdio", is_flag=True, hidden=True, help="Talk on stdin and stdout (the default).")
@reports_errors
def lsp(tcp: str | None, stdio: bool) -> None:
    """Run the exsce language server: diagnostics (syntax, semantic, SHACL), completion,
    hover, go to definition, references, renaming, formatting and quick fixes.

    Editors start it and talk to it on stdin and stdout (--tcp HOST:PORT
    listens there instead, to debug the server).

    \b
    Example:
      exscec lsp
    """
    from exsce_dsl.api import serve_lsp

    serve_lsp(_address(tcp) if tcp else None)


COMMANDS = [lsp]
