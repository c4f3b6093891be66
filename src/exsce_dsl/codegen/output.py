"""Write generated files: every path stays below the output folder, nothing is half-written."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path, PurePosixPath

from exsce_dsl.templating import GenerationError


def write_files(out_dir: Path, files: Mapping[str, str], overwrite: bool = False) -> list[Path]:
    """Write ``files`` (relative POSIX path → text) below ``out_dir``; return the paths written.

    Relative paths may be built from ids in a user's file, so each is checked to
    stay below ``out_dir``.  If any target exists and ``overwrite`` is false,
    nothing is written.
    """
    targets = {_target(out_dir, rel): text for rel, text in files.items()}
    existing = sorted(str(t) for t in targets if t.exists())
    if existing and not overwrite:
        raise GenerationError(f"would overwrite {', '.join(existing)}; use --force to replace")
    for target, text in targets.items():
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    return list(targets)


def _target(out_dir: Path, relative: str) -> Path:
    rel = PurePosixPath(relative)
    if rel.is_absolute() or not rel.parts or any(p in ("..", "") or "\\" in p for p in rel.parts):
        raise GenerationError(f"refusing to write outside the output folder: {relative}")
    return out_dir.joinpath(*rel.parts)
