"""The one exception hierarchy of exsce.

Library code raises these; only the CLI prints them and picks the exit code.
An error may carry the source location it concerns, so that it can be printed
as ``file:line:col: error: message`` and underlined by an editor.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field


@dataclass(frozen=True, order=True)
class SourceLocation:
    """A span of text in a source file: 1-based line and column, end exclusive."""

    file: str
    line: int
    column: int
    end_line: int = 0
    end_column: int = 0

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


@dataclass(frozen=True)
class Diagnostic:
    """One problem found in a specification."""

    message: str
    location: SourceLocation | None = None
    severity: str = "error"
    code: str = "exsce"
    hint: str | None = field(default=None, compare=False)

    def __str__(self) -> str:
        where = f"{self.location}: " if self.location else ""
        return f"{where}{self.severity}: {self.message}"


class ExsceError(Exception):
    """Base of every error exsce raises on purpose."""

    def __init__(self, message: str, location: SourceLocation | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.location = location

    @property
    def diagnostics(self) -> Sequence[Diagnostic]:
        return (Diagnostic(self.message, self.location),)

    def __str__(self) -> str:
        return "\n".join(str(d) for d in self.diagnostics)


class SpecError(ExsceError):
    """A specification is not valid; holds every diagnostic that was found."""

    def __init__(self, diagnostics: Iterable[Diagnostic]) -> None:
        found = tuple(sorted(diagnostics, key=_diagnostic_order))
        first = found[0] if found else Diagnostic("invalid specification")
        super().__init__(first.message, first.location)
        self._diagnostics = found

    @property
    def diagnostics(self) -> Sequence[Diagnostic]:
        return self._diagnostics


class ExsceSyntaxError(SpecError):
    """The text does not follow the grammar."""


class ImportFormatError(ExsceError):
    """A file in the method's YAML format cannot be imported."""


class ExportError(ExsceError):
    """A specification cannot be written in the requested format."""


def _diagnostic_order(d: Diagnostic) -> tuple[str, int, int, str]:
    loc = d.location
    return (loc.file, loc.line, loc.column, d.message) if loc else ("", 0, 0, d.message)
