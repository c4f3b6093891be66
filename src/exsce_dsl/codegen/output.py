"""Write generated files: every path stays below the output folder, nothing is half-written,
no link below it is followed, and every file reads back in its language before any is written."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from pathlib import Path

from exsce_dsl.codegen.readback import check_generated
from exsce_dsl.errors import GenerationError
from exsce_dsl.output_folder import existing, relative_parts, write_below
from exsce_dsl.remedies import REPLACE_FILES


def write_files(
    out_dir: Path, files: Mapping[str, str], overwrite: bool = False, executable: Collection[str] = ()
) -> list[Path]:
    """Write ``files`` (relative POSIX path → text) below ``out_dir``; return the paths written.

    Relative paths may be built from ids in a user's file, so each is checked to
    stay below ``out_dir``; a symbolic link on the way to one is refused.  If any
    target exists and ``overwrite`` is false, or a file does not read back in its
    language (:func:`~exsce_dsl.codegen.readback.check_generated`), nothing is
    written.  The files of ``executable`` are written executable (mode 0755).
    """
    for relative, text in files.items():
        relative_parts(relative)
        check_generated(str(out_dir.joinpath(relative)), text)
    found = sorted(str(out_dir.joinpath(rel)) for rel in files if existing(out_dir, rel))
    if found and not overwrite:
        raise GenerationError(f"would overwrite {', '.join(found)}", remedy=REPLACE_FILES)
    return [
        write_below(out_dir, rel, text.encode("utf-8"), 0o777 if rel in executable else 0o666)
        for rel, text in files.items()
    ]
