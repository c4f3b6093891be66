"""Where the user's own message definitions are: the folders of ``EXSCE_MSG_PATH``
(``os.pathsep``-separated, as ``exscec --msg-path`` sets it) and the ``.msg`` and ``.idl``
files below them.  Apart from :mod:`exsce_dsl.messages.user`, which reads them, so that
finding them needs no parser of message definitions (the specification cache asks).
"""

from __future__ import annotations

import os
from pathlib import Path

MSG_PATH = "EXSCE_MSG_PATH"


def msg_path_folders() -> list[Path]:
    """The folders of ``EXSCE_MSG_PATH``, in order (empty entries left out)."""
    return [Path(entry) for entry in os.environ.get(MSG_PATH, "").split(os.pathsep) if entry]


def msg_path_files() -> list[Path]:
    """Every definition file the folders of ``EXSCE_MSG_PATH`` hold, folder by folder (what
    :func:`exsce_dsl.messages.user.configured_catalogue` reads)."""
    return [path for folder in msg_path_folders() for path in definition_files(folder)]


def definition_files(folder: Path) -> list[Path]:
    """The ``.msg`` and ``.idl`` files below ``folder``, in name order (none if it is no folder)."""
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.rglob("*") if p.suffix in (".msg", ".idl") and p.is_file())
