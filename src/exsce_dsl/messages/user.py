"""The user's own message definitions: ``.msg`` and ``.idl`` files in the folders of
``EXSCE_MSG_PATH`` (``os.pathsep``-separated, as ``exscec --msg-path`` sets it).

A ``.msg`` file at ``<pkg>/msg/Name.msg`` (or ``<pkg>/Name.msg``) defines
``pkg/msg/Name``; an ``.idl`` file names its types itself.  An earlier folder's
definition of a type wins over a later one's, and the user's over the standard
packages'.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from pathlib import Path

from exsce_dsl.errors import ExsceError, MessageTypeError
from exsce_dsl.messages.catalogue import MessageCatalogue, Source, parse_definition, standard_catalogue
from exsce_dsl.messages.msg_path import definition_files as _definition_files
from exsce_dsl.messages.msg_path import msg_path_folders
from exsce_dsl.textfiles import read_text


def user_catalogue(folders: Iterable[str | Path]) -> MessageCatalogue:
    """The definitions of every ``.msg`` and ``.idl`` file below ``folders``; a file that does not
    parse is a :class:`~exsce_dsl.messages.catalogue.MessageTypeError` naming it."""
    catalogue = MessageCatalogue()
    for folder in folders:
        for path in _definition_files(Path(folder)):
            source = Source(str(path))
            try:
                text = read_text(path, "message definition")  # a regular file, bounded
            except ExsceError as exc:
                raise MessageTypeError(f"{path}: cannot read the message definition: {exc.message}") from None
            kind = path.suffix[1:]
            name = _msg_type(path) if kind == "msg" else path.stem
            catalogue.add(parse_definition(text, name, kind, source).definitions, source)
    return catalogue


def configured_catalogue() -> MessageCatalogue:
    """The user's types (``EXSCE_MSG_PATH``) over the standard ones."""
    return _configured()[1]


def configured_user_catalogue() -> MessageCatalogue:
    """The user's types (``EXSCE_MSG_PATH``) alone, empty when there are none."""
    return _configured()[0]


def _configured() -> tuple[MessageCatalogue, MessageCatalogue]:
    """The user's catalogue, and it over the standard one: read again when a file of those
    folders changes (an editor's session outlives many edits)."""
    folders = tuple(str(f) for f in msg_path_folders())
    signature = tuple(
        (str(path), stat.st_mtime_ns, stat.st_size)
        for folder in folders
        for path in _definition_files(Path(folder))
        for stat in [path.stat()]
    )
    return _catalogues(folders, signature)


@functools.lru_cache(maxsize=4)
def _catalogues(
    folders: tuple[str, ...], signature: tuple[tuple[str, int, int], ...]
) -> tuple[MessageCatalogue, MessageCatalogue]:
    user = user_catalogue(folders)
    return user, user.layered(standard_catalogue()) if user.definitions else standard_catalogue()


def _msg_type(path: Path) -> str:
    """``<pkg>/msg/Name.msg`` (or ``<pkg>/Name.msg``) → ``pkg/msg/Name``."""
    package = path.parent.parent.name if path.parent.name == "msg" else path.parent.name
    return f"{package}/msg/{path.stem}"
