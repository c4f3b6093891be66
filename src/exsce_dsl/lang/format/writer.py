"""Write documents of the semantic model as formatted ``.exsce`` files."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path, PurePosixPath

from exsce_dsl.errors import ExportError
from exsce_dsl.lang.format.document import declared_poses, format_document
from exsce_dsl.model import Document, Environment
from exsce_dsl.remedies import REPLACE_FILES


def write_documents(documents: Sequence[Document], out_dir: Path, overwrite: bool = False) -> list[Path]:
    """Write each document at its relative path below ``out_dir``; return the paths written.

    Paths come from user data (ids), so each must stay below ``out_dir``.
    Nothing is written if any target exists and ``overwrite`` is false.
    """
    environments = [d for doc in documents for d in doc.declarations if isinstance(d, Environment)]
    poses = declared_poses(environments)
    targets = [(doc, _target(out_dir, doc.path)) for doc in documents]
    existing = [str(t) for _, t in targets if t.exists()]
    if existing and not overwrite:
        raise ExportError(f"would overwrite {', '.join(existing)}", remedy=REPLACE_FILES)
    written = []
    for doc, target in targets:
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(format_document(doc, poses), encoding="utf-8")
        written.append(target)
    return written


def _target(out_dir: Path, relative: str) -> Path:
    rel = PurePosixPath(relative)
    if rel.is_absolute() or ".." in rel.parts or not rel.parts:
        raise ExportError(f"refusing to write outside the output folder: {relative}")
    return out_dir.joinpath(*rel.parts)
