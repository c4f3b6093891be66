"""The ``check`` tool: ``exscec check`` of a specification's text, with located diagnostics.

The same checks as the command: parse, the language's semantic checks (every
error, with did-you-mean), then SHACL on each scenario's PROV-O.  The text is
checked as the file ``name`` in ``folder``, without writing there: imports are
resolved relative to the folder, from the files on disk, as they would be for
the file itself, but only ``.exsce`` files inside the server's folder (where it
started, or its ``--root``) are read, and ``folder`` must be inside it too;
no other file outside it is read either (a map the text names).
Without a folder, the text is checked in a scratch folder of its own, and every
import is refused where it is written: a text given alone imports nothing.

Each diagnostic keeps its place (file, line, column, end) and reads as the
command prints it, ``file:line:col: error: message``; paths are relative to the
folder.
"""

from __future__ import annotations

import os
import tempfile
import threading
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import mcp_types as types

from exsce_dsl.errors import ArgumentError, Diagnostic, Severity
from exsce_dsl.mcp_server.access import Access
from exsce_dsl.mcp_server.answers import READ_ONLY, ToolEntry
from exsce_dsl.mcp_server.arguments import object_schema
from exsce_dsl.textfiles import reading_inside

if TYPE_CHECKING:
    from exsce_dsl.lang import ImportScope

__all__ = ["check_text", "check_tool"]

MAX_SPEC = 1024 * 1024
"""The longest specification text checked (characters)."""
FILE_NAME = r"^[A-Za-z0-9_][A-Za-z0-9_.-]*\.exsce$"
DEFAULT_NAME = "spec.exsce"

_ONE_AT_A_TIME = threading.Lock()  # the language's metamodel is shared; analyses take turns


NO_IMPORTS = "imports are not read for a text given to check (give 'folder' to check it among its files)"


def check_text(
    text: str, folder: str | None = None, name: str = DEFAULT_NAME, root: str | Path | None = None
) -> dict[str, Any]:
    """The diagnostics of specification ``text`` checked as ``folder/name`` (a scratch folder
    without ``folder``, and no imports), with the counts of errors and warnings; imports and
    ``folder`` only inside ``root`` (the working directory by default)."""
    from exsce_dsl.lang import ImportScope

    workspace = Path(os.path.realpath(root if root is not None else os.getcwd()))
    if folder is None:
        with tempfile.TemporaryDirectory(prefix="exsce-check-") as scratch:
            base = Path(os.path.realpath(scratch))
            return _check(text, base, name, ImportScope.nowhere(NO_IMPORTS), workspace)
    base = Path(folder).expanduser()
    scope = ImportScope.inside(workspace)
    if not scope.holds(str(base.absolute())):
        raise ArgumentError(f"folder '{folder}' is outside the server's folder {workspace}")
    if not base.is_dir():
        raise ArgumentError(
            f"folder '{folder}' is not a folder (imports are resolved relative to it; "
            f"a relative folder is taken from {os.getcwd()})"
        )
    return _check(text, Path(os.path.realpath(base)), name, scope, workspace)


def _check(text: str, base: Path, name: str, scope: ImportScope, workspace: Path) -> dict[str, Any]:
    """The check of ``text`` as ``base/name``, reading no file outside ``workspace`` (a map)."""
    from exsce_dsl.lang import analyse
    from exsce_dsl.rdf.shacl import check_spec_shapes

    root = str(base / name)
    with _ONE_AT_A_TIME, reading_inside(workspace):
        analysis = analyse(root, {root: text}, scope)
        diagnostics = list(analysis.diagnostics)
        if not analysis.errors and analysis.spec is not None:
            diagnostics.extend(check_spec_shapes(analysis.spec))
    errors = sum(d.is_error for d in diagnostics)
    answer: dict[str, Any] = {
        "ok": errors == 0 and analysis.spec is not None,
        "errors": errors,
        "warnings": sum(d.severity is Severity.WARNING for d in diagnostics),
        "diagnostics": [_diagnostic_json(d, base) for d in diagnostics],
    }
    if analysis.spec is not None:
        answer["scenarios"] = [s.id for s in analysis.spec.scenarios]
    return answer


def _diagnostic_json(d: Diagnostic, base: Path) -> dict[str, Any]:
    message = _relative_text(d.message, base)
    found: dict[str, Any] = {"severity": str(d.severity), "message": message, "code": d.code}
    where = ""
    if d.location is not None:
        file = _relative_path(d.location.file, base)
        found.update(
            file=file,
            line=d.location.line,
            column=d.location.column,
            end_line=d.location.end_line or None,
            end_column=d.location.end_column or None,
        )
        where = f"{file}:{d.location.line}:{d.location.column}: "
    if d.hint:
        found["hint"] = _relative_text(d.hint, base)
    found["text"] = f"{where}{str(d.severity)}: {message}"
    return found


def _relative_path(file: str, base: Path) -> str:
    """``file`` relative to ``base`` when it is below it; as given otherwise."""
    try:
        return str(Path(os.path.realpath(file)).relative_to(base))
    except ValueError:
        return file


def _relative_text(text: str, base: Path) -> str:
    """A message with the paths below ``base`` written relative to it (an import not found)."""
    for prefix in {str(base), os.path.relpath(base)}:
        text = text.replace(prefix + os.sep, "")
    return text


def _answer(access: Access, arguments: Mapping[str, Any]) -> dict[str, Any]:
    folder = arguments.get("folder")
    return check_text(str(arguments["text"]), folder, str(arguments.get("name", DEFAULT_NAME)), access.root)


def check_tool() -> ToolEntry:
    tool = types.Tool(
        name="check",
        title="Check an exsce specification",
        description=(
            "Check the text of an exsce specification as `exscec check` does: syntax, the language's "
            "semantic checks (unknown names with did-you-mean, free space on the map...) and SHACL on "
            "each scenario's provenance.  Answers every diagnostic with its place (file, line, column, "
            "end) and as 'file:line:col: severity: message'; 'ok' is true when there is no error.  "
            "Imports are resolved relative to 'folder' (nothing is written there), and only .exsce "
            "files inside the server's folder are imported; without it the text is checked alone and "
            "imports nothing."
        ),
        input_schema=object_schema(
            {
                "text": {"type": "string", "maxLength": MAX_SPEC, "description": "the specification"},
                "folder": {
                    "type": "string",
                    "maxLength": 4096,
                    "description": "an existing folder inside the server's folder that the text "
                    "belongs in: its imports are resolved from there (a relative folder is relative "
                    "to where the server runs)",
                },
                "name": {
                    "type": "string",
                    "pattern": FILE_NAME,
                    "description": f"the file name the diagnostics give the text (default {DEFAULT_NAME})",
                },
            },
            ("text",),
        ),
        annotations=READ_ONLY,
    )
    return ToolEntry(tool, _answer)
