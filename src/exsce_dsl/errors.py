"""The one exception hierarchy of exsce.

Library code raises these; only the CLI prints them and picks the exit code.
An error may carry the source location it concerns, so that it can be printed
as ``file:line:col: error: message`` and underlined by an editor.

Every error class of the package is defined here, whatever layer raises it
(this module imports nothing of exsce, so every layer can import it); the
modules that raise them import them from here, so the old names still work
(``exsce_dsl.store.base.StoreError`` is this module's :class:`StoreError`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from enum import Enum
from http import HTTPStatus
from pathlib import Path
from typing import Any

__all__ = [
    "AmbiguousRunError",
    "ArgumentError",
    "BagError",
    "CacheWarning",
    "DecodeError",
    "Diagnostic",
    "ExecutionInterrupted",
    "ExportError",
    "ExsceError",
    "ExsceSyntaxError",
    "FederationRefused",
    "GenerationError",
    "ImportFormatError",
    "IncompleteRunError",
    "MessageTypeError",
    "PlanningError",
    "RelationError",
    "Remedied",
    "RenameError",
    "RosGraphError",
    "ScenarioChoiceError",
    "SegmentError",
    "Severity",
    "SourceLocation",
    "SpecError",
    "StoreConflictError",
    "StoreError",
    "StoreLockedError",
    "StoreUnwritableError",
    "TfError",
    "TimeLimitError",
    "UnknownNameWarning",
    "UnknownRunError",
    "UnknownValueError",
]


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


class Severity(str, Enum):
    """How bad a diagnostic is; prints as its value (``f"{Severity.ERROR}"`` is ``error``).

    Only errors make a specification invalid.  A note says something about another
    diagnostic (errors that may follow from a syntax error, and were not shown).
    """

    ERROR = "error"
    WARNING = "warning"
    NOTE = "note"
    INFO = "info"
    HINT = "hint"

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)

    @property
    def rank(self) -> int:
        """Errors first, then warnings, then the rest (to order diagnostics at one place)."""
        return list(Severity).index(self)


@dataclass(frozen=True, init=False)
class Diagnostic:
    """One problem found in a specification.

    ``severity`` may be given as its text (``"warning"``); it is kept as a :class:`Severity`.
    """

    message: str
    location: SourceLocation | None = None
    severity: Severity = Severity.ERROR
    code: str = "exsce"
    hint: str | None = field(default=None, compare=False)
    remedied: Remedied | None = field(default=None, compare=False)
    """The message as a problem and its remedy, when it has one (:meth:`said`)."""

    def __init__(
        self,
        message: str,
        location: SourceLocation | None = None,
        severity: Severity | str = Severity.ERROR,
        code: str = "exsce",
        hint: str | None = None,
        remedied: Remedied | None = None,
    ) -> None:
        object.__setattr__(self, "remedied", remedied)
        object.__setattr__(self, "message", message)
        object.__setattr__(self, "location", location)
        object.__setattr__(self, "severity", Severity(severity))
        object.__setattr__(self, "code", code)
        object.__setattr__(self, "hint", hint)

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR

    def said(self, wording: Mapping[str, str]) -> Diagnostic:
        """This diagnostic with its remedy in ``wording`` (the command line's)."""
        if self.remedied is None:
            return self
        return Diagnostic(self.remedied.said(wording), self.location, self.severity, self.code, self.hint)

    def __str__(self) -> str:
        where = f"{self.location}: " if self.location else ""
        return f"{where}{self.severity}: {self.message}"


def diagnostic_order(d: Diagnostic) -> tuple[str, int, int, int, str]:
    """Diagnostics by file, line and column; at one place errors before notes about them."""
    loc = d.location
    where = (loc.file, loc.line, loc.column) if loc else ("", 0, 0)
    return (*where, d.severity.rank, d.message)


@dataclass(frozen=True)
class Remedied:
    """A problem and what to do about it (a remedy of :mod:`exsce_dsl.remedies`, in words).

    :meth:`said` puts them together, in a front end's ``wording`` when it has one for the remedy
    (``cli.common.REMEDIES``: the command line's, with its options), else as ``problem; remedy``.
    A wording is a ``str.format`` template of ``{problem}`` and ``{about}``: what the remedy is about
    (a scenario's id, the element a replace would change)."""

    problem: str
    remedy: str
    about: str | tuple[str, ...] = ""

    def __str__(self) -> str:
        return self.said()

    def said(self, wording: Mapping[str, str] | None = None) -> str:
        template = (wording or {}).get(self.remedy)
        if template is None:
            return f"{self.problem}; {self.remedy.format(about=self.about)}"
        return template.format(problem=self.problem, about=self.about)


class ExsceError(Exception):
    """Base of every error exsce raises on purpose.

    ``remedy``: what the user can do about it, in words (:mod:`exsce_dsl.remedies`), after the
    problem in the message; ``about``: what the remedy is about (:class:`Remedied`).  The library
    never names an option of the command line, which says a remedy such as ``REPLACE_FILES`` with
    its own option (``use --force to replace``)."""

    def __init__(
        self,
        message: str,
        location: SourceLocation | None = None,
        *,
        remedy: str | None = None,
        about: str | tuple[str, ...] = "",
    ) -> None:
        self.remedied = Remedied(message, remedy, about) if remedy else None
        said = self.remedied.said() if self.remedied else message
        super().__init__(said)
        self.message = said
        self.location = location
        self.problem = message
        self.remedy = remedy

    @property
    def diagnostics(self) -> Sequence[Diagnostic]:
        return (Diagnostic(self.message, self.location, remedied=self.remedied),)

    def __str__(self) -> str:
        return "\n".join(str(d) for d in self.diagnostics)


class SpecError(ExsceError):
    """A specification is not valid; holds every diagnostic that was found."""

    def __init__(self, diagnostics: Iterable[Diagnostic]) -> None:
        found = tuple(sorted(diagnostics, key=diagnostic_order))
        first = next((d for d in found if d.is_error), found[0] if found else None)
        first = first or Diagnostic("invalid specification")
        super().__init__(first.message, first.location)
        self._diagnostics = found

    @property
    def diagnostics(self) -> Sequence[Diagnostic]:
        return self._diagnostics


class ExsceSyntaxError(SpecError):
    """The text does not follow the grammar."""


class ScenarioChoiceError(ExsceError):
    """A file declares no scenario or several, and none was named.  The command line names the
    option that chooses one (:meth:`naming`), which each command spells its own way
    (``--scenario`` where the file is an argument, ``--scenario-id`` where ``--scenario`` is the
    file); the library names none."""

    def __init__(self, root: str, found: Sequence[str], option: str | None = None) -> None:
        listed = ", ".join(found) or "none"
        with_option = f" with {option}" if option else ""
        super().__init__(f"{root} declares {len(found)} scenarios ({listed}); name one{with_option}")
        self.root, self.found, self.option = root, tuple(found), option

    def naming(self, option: str) -> ScenarioChoiceError:
        """The same error, naming ``option``."""
        return ScenarioChoiceError(self.root, self.found, option)


class ImportFormatError(ExsceError):
    """A file in the method's YAML format cannot be imported."""


class ExportError(ExsceError):
    """A specification cannot be written in the requested format."""


# ------------------------------------------------- errors of the upper layers
# Defined here rather than re-exported: importing their modules from here would
# make every layer import the store, the bag readers and the language server.


class MessageTypeError(ExsceError):
    """A message type that is unknown, or whose definition cannot be used (``messages``)."""


class GenerationError(ExsceError):
    """A model that cannot be turned into the requested code (templates, ``codegen``)."""


class RelationError(ExsceError):
    """A relation that does not exist, or was given the wrong parameters (``oracles``)."""


class PlanningError(ExsceError):
    """No path exists between two poses on the map (``sim``)."""


class BagError(ExsceError):
    """A bag that cannot be used: unreadable, truncated, empty, of an unexpected type (``runs``)."""


class IncompleteRunError(BagError):
    """A run that would lack a metric value, which ``exscec ingest --strict`` does not store."""


class DecodeError(ExsceError):
    """Raw bytes that are not the message type they claim to be (``runs``)."""


class TfError(ExsceError):
    """The TF data cannot give the pose asked for, or is not a tree (``runs``)."""


class SegmentError(ExsceError):
    """The dispatcher's statuses do not fit the scenario (``runs``)."""


class StoreError(ExsceError):
    """The store cannot do what was asked (unreachable, locked, refused, conflicting)."""


class FederationRefused(StoreError):
    """A query or update would reach another server (SERVICE, LOAD) that no flag allows."""


class StoreLockedError(StoreError):
    """An embedded store's folder is open in another process (RocksDB allows one)."""

    def __init__(self, message: str, path: str, *, remedy: str | None = None) -> None:
        super().__init__(message, remedy=remedy)
        self.path = path


class StoreUnwritableError(StoreError):
    """The store folder can be read but not opened for writing (read-only mount, no permission,
    full disk): reads use a read-only view, and a write raises this."""


class StoreConflictError(StoreError):
    """A document differs from what the store holds under the same names."""

    def __init__(
        self, message: str, graphs: Sequence[str] = (), *, remedy: str | None = None, about: str = ""
    ) -> None:
        super().__init__(message, remedy=remedy, about=about)
        self.graphs = tuple(graphs)
        """The names of the graphs that differ (a copy gets them with the rest of its state)."""


class UnknownRunError(ExsceError):
    """No stored run has this id (``exsce_dsl.store.queries.run_ids``)."""

    def __init__(
        self, message: str, closest: Sequence[Any] = (), *, remedy: str | None = None, about: str = ""
    ) -> None:
        super().__init__(message, remedy=remedy, about=about)
        self.closest = tuple(closest)
        """The stored runs whose ids are closest (``RunCandidate``: uuid, scenario, bag)."""


class AmbiguousRunError(ExsceError):
    """Several stored runs start with this prefix (``exsce_dsl.store.queries.run_ids``)."""

    def __init__(self, message: str, candidates: Sequence[Any]) -> None:
        super().__init__(message)
        self.candidates = tuple(candidates)
        """The runs it may mean (``RunCandidate``: uuid, scenario, bag)."""


class ArgumentError(ExsceError):
    """A tool was called with arguments its input schema does not allow (``mcp_server``)."""


class UnknownValueError(ExsceError):
    """A stored run has no value, nor a problem, of the metric, robot or segment asked for."""


class TimeLimitError(ExsceError):
    """A request ran over the server's time limit (``mcp_server``)."""


class RosGraphError(ExsceError):
    """A live ROS graph cannot do what a run needs (``execute``): no master at the URI, no Python
    with rospy, an action server that never answered, a node of ours that died; the message names
    what is missing."""


class ExecutionInterrupted(ExsceError):
    """A run on a live graph was cut short (Ctrl-C, SIGTERM): its goals were cancelled and its
    files kept apart from the whole runs (``execute``); the CLI exits 130."""

    def __init__(self, incomplete: Path | None, complete: Sequence[Path] = ()) -> None:
        if incomplete is None:
            said = "interrupted before the run began: no goal was sent and no bag written"
        else:
            said = (
                f"interrupted: the goals were cancelled; the run cut short is kept apart in "
                f"{incomplete.parent} ({incomplete.name}, its .prov.json and .rosparams), where "
                "ingest DIR/*.bag does not take it"
            )
        super().__init__(said)
        self.incomplete = incomplete
        self.complete = tuple(complete)


class RenameError(ValueError):
    """A rename an editor asked for that cannot be done, and why (``lsp``).

    A refusal sent back to the editor as it is (``str(error)`` is the reason), not a
    problem of a specification: hence a ``ValueError`` rather than an :class:`ExsceError`.
    """


class UnknownNameWarning(UserWarning):
    """A query's parameter names a metric, robot or scenario the store does not hold (``store``;
    ``api.query`` warns with it, ``exscec query`` prints it)."""


class CacheWarning(UserWarning):
    """The user's cache folder cannot be trusted (another user's, or writable by others), so it is
    not used (``user_cache``)."""


class NoGoodRuns(ExsceError):
    """Every stored run of a scenario was left out: there is nothing to learn from."""


class NotEnoughRuns(ExsceError):
    """A baseline was asked for before the scenario had the runs its criteria require."""


class IngestFailed(ExsceError):
    """A bag given to :func:`verify_runs` could not be ingested, so nothing was judged."""


class CorruptBag(ExsceError):
    """Bytes that are not what the bag's own checksums say was recorded: no reader should read them."""


class ResourceNotFound(ExsceError):
    """No resource has the URI asked for."""


class OracleFileErrors(ImportFormatError):
    """Every problem found in one oracle file, reported together (first one as the message)."""

    def __init__(self, problems: Sequence[ImportFormatError]) -> None:
        found = sorted(problems, key=lambda p: p.location or SourceLocation("", 0, 0))
        super().__init__(found[0].message, found[0].location)
        self._diagnostics = tuple(d for p in found for d in p.diagnostics)

    @property
    def diagnostics(self) -> Sequence[Diagnostic]:
        return self._diagnostics


# -- signals inside the library: each is caught by the caller of what raised it, which says what
# went wrong in an ExsceError of its own (or answers an HTTP request with it)


class Unparsable(Exception):
    """The text does not parse as SPARQL 1.1 (it may still be Oxigraph's SPARQL)."""


class RefusedRequest(Exception):
    """A request answered with ``status`` and ``message`` (plain text) and these ``headers``."""

    def __init__(self, status: HTTPStatus, message: str, headers: dict[str, str] | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.message = message
        self.headers = headers or {}


class AnswerCut(Exception):
    """An answer stopped after its headers were sent (over a limit, or the worker failed)."""


class FieldProblem(Exception):
    """What is wrong with a path (the caller knows where it is written)."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


class FileProblem(Exception):
    """What is wrong with one file, in words; :func:`~exsce_dsl.runs.bags.files.check_bag_file`
    says which bag it is."""


class UnsupportedBag(Exception):
    """This reader cannot read the bag; use the next (rosbags, at the end)."""
