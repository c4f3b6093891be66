"""Checking a specification as ``exscec check`` does: the language's checks, then SHACL.

The language's checks (syntax, names, types, free space on the map, ...) come first; only a
specification that passes them is compiled and its PROV-O validated against exsce's shapes, each
violation reported at the DSL element it concerns.  The CLI, the language server's callers, the
MCP server and the Python API all check through :func:`check_spec`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from exsce_dsl.errors import Diagnostic
from exsce_dsl.lang import analyse
from exsce_dsl.model.document import Specification
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.rdf.shacl import check_spec_shapes


@dataclass(frozen=True)
class SpecCheck:
    """What checking one file found: every diagnostic, and the model when there was no error."""

    path: Path
    diagnostics: tuple[Diagnostic, ...]
    spec: Specification | None

    @property
    def errors(self) -> tuple[Diagnostic, ...]:
        return tuple(d for d in self.diagnostics if d.is_error)

    @property
    def ok(self) -> bool:
        return self.spec is not None and not self.errors


def check_spec(
    path: str | Path, overlay: Mapping[str, str] | None = None, namespace: str = DEFAULT_NAMESPACE
) -> SpecCheck:
    """Check the specification at ``path`` (``overlay``: file texts that replace what is on disk,
    by path, as an editor's unsaved buffers)."""
    analysis = analyse(path, overlay)
    diagnostics = list(analysis.diagnostics)
    spec = analysis.spec
    if not analysis.errors and spec is not None:
        diagnostics.extend(check_spec_shapes(spec, namespace))
    found = tuple(diagnostics)
    has_errors = any(d.is_error for d in found)
    return SpecCheck(Path(path), found, None if has_errors else spec)
