"""Writing files below an output folder without ever following a symbolic link out of it.

``-o DIR`` of ``init``, ``generate`` and ``report`` names a folder the user chose
(itself followed if it is a link: that is the user's choice), but what lies
below it may have been planted: a link ``DIR/setup.py -> ~/.bashrc`` must not
make exsce write to ``~/.bashrc``.  Every folder below ``DIR`` is opened
without following links (``O_NOFOLLOW``, relative to its parent's descriptor),
a link met on the way is refused, and each file is written to a fresh name
beside its target and renamed over it: a rename replaces whatever is at the
target (even a link put there meanwhile) and never writes through it, and a
reader never sees a half-written file.  A set of files written as one piece
(the report) is written into a new hidden folder first and renamed into its
place when complete (:func:`written_whole`).
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import shutil
import stat
from collections.abc import Iterator
from pathlib import Path, PurePosixPath

from exsce_dsl.errors import ExsceError

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_DIRECTORY = getattr(os, "O_DIRECTORY", 0)


def relative_parts(relative: str) -> tuple[str, ...]:
    """The parts of a relative POSIX path that stays below its folder; an error otherwise
    (absolute, empty, ``..``, a backslash)."""
    rel = PurePosixPath(relative)
    if rel.is_absolute() or not rel.parts or any(p in ("..", "") or "\\" in p for p in rel.parts):
        raise ExsceError(f"refusing to write outside the output folder: {relative}")
    return rel.parts


def _refuse_link(path: Path) -> ExsceError:
    return ExsceError(
        f"{path} is a symbolic link: exsce does not write through links inside its output folder; "
        "remove it or choose another folder"
    )


def existing(folder: Path, relative: str) -> bool:
    """Whether ``folder/relative`` exists (a link counts, even a broken one); an error if a
    folder on the way below ``folder`` is a link, or the target is a link or a folder."""
    path = folder
    parts = relative_parts(relative)
    for index, part in enumerate(parts):
        path = path / part
        try:
            mode = path.lstat().st_mode
        except FileNotFoundError:
            return False
        except OSError as exc:
            raise ExsceError(f"cannot write {path}: {exc.strerror or exc}") from None
        if stat.S_ISLNK(mode):
            raise _refuse_link(path)
        last = index == len(parts) - 1
        if last and stat.S_ISDIR(mode):
            raise ExsceError(f"cannot write {path}: it is a folder")
        if not last and not stat.S_ISDIR(mode):
            raise ExsceError(f"cannot write below {path}: it is not a folder")
    return True


@contextlib.contextmanager
def _opened_folder(folder: Path, parts: tuple[str, ...]) -> Iterator[int]:
    """A descriptor of ``folder/parts...``, each part made if missing and opened without
    following a link."""
    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder, os.O_RDONLY | _DIRECTORY)
    path = folder
    try:
        for part in parts:
            path = path / part
            with contextlib.suppress(FileExistsError):
                os.mkdir(part, dir_fd=fd)
            try:
                inner = os.open(part, os.O_RDONLY | _DIRECTORY | _NOFOLLOW, dir_fd=fd)
            except OSError as exc:
                if exc.errno in (errno.ELOOP, errno.ENOTDIR) and os.path.islink(path):
                    raise _refuse_link(path) from None
                raise
            os.close(fd)
            fd = inner
        yield fd
    finally:
        os.close(fd)


def write_below(folder: Path, relative: str, data: bytes, mode: int = 0o666) -> Path:
    """Write ``data`` to ``folder/relative`` (folders made as needed) and return that path;
    ``mode`` is masked by the umask as ``open`` masks it.  A link below ``folder`` is refused."""
    *inside, name = relative_parts(relative)
    target = folder.joinpath(*inside, name)
    try:
        with _opened_folder(folder, tuple(inside)) as fd:
            try:
                found = os.stat(name, dir_fd=fd, follow_symlinks=False).st_mode
            except FileNotFoundError:
                found = None
            if found is not None and stat.S_ISLNK(found):
                raise _refuse_link(target)
            if found is not None and stat.S_ISDIR(found):
                raise ExsceError(f"cannot write {target}: it is a folder")
            temporary = f".{name}.{secrets.token_hex(6)}.tmp"
            flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW
            out = os.open(temporary, flags, mode, dir_fd=fd)  # the umask applies, as to open()
            try:
                with os.fdopen(out, "wb") as stream:
                    stream.write(data)
                os.replace(temporary, name, src_dir_fd=fd, dst_dir_fd=fd)
            except BaseException:
                with contextlib.suppress(OSError):
                    os.unlink(temporary, dir_fd=fd)
                raise
    except OSError as exc:
        raise ExsceError(f"cannot write {target}: {exc.strerror or exc}") from None
    return target


@contextlib.contextmanager
def written_whole(folder: Path) -> Iterator[Path]:
    """A new hidden folder to write a set of files into; when the block ends, what it holds
    takes its place in ``folder`` (made if missing), and on an error it is removed and
    ``folder`` is left as it was.

    A new ``folder`` is the written one, renamed.  In an existing one, each entry is renamed
    into place (a folder of the same name is replaced whole, a file or a link there is replaced
    by the rename, never written through); files of ``folder`` that were not written stay.
    """
    target = Path(os.path.abspath(folder))
    try:
        mode: int | None = target.stat().st_mode  # the folder itself may be a link: the user's
    except FileNotFoundError:
        mode = None
    except OSError as exc:
        raise ExsceError(f"cannot write into {folder}: {exc.strerror or exc}") from None
    if mode is not None and not stat.S_ISDIR(mode):
        raise ExsceError(f"{folder} is a file, not a folder")
    try:
        if mode is None:
            target.parent.mkdir(parents=True, exist_ok=True)
        where = target if mode is not None else target.parent
        staging = where / f".{target.name}.{secrets.token_hex(8)}.partial"
        staging.mkdir(0o777)  # new (an existing name is an error), with the umask's permissions
    except OSError as exc:
        raise ExsceError(f"cannot write into {folder}: {exc.strerror or exc}") from None
    try:
        yield staging
        if mode is None:
            _rename(staging, target)
        else:
            _install(staging, target)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def _rename(source: Path, target: Path) -> None:
    try:
        os.rename(source, target)
    except OSError as exc:
        raise ExsceError(f"cannot write into {target}: {exc.strerror or exc}") from None


def _install(staging: Path, target: Path) -> None:
    """Rename each entry of ``staging`` into ``target`` (checked first: a file is not put where
    a folder is); folders they replace are moved aside, then removed."""
    entries = sorted(staging.iterdir())
    for entry in entries:
        place = target / entry.name
        if not entry.is_dir() and place.is_dir() and not place.is_symlink():
            raise ExsceError(f"cannot write {place}: it is a folder")
    aside = []
    for entry in entries:
        place = target / entry.name
        if entry.is_dir() and (place.is_symlink() or place.exists()):
            if place.is_dir() and not place.is_symlink():
                aside.append(target / f".{entry.name}.{secrets.token_hex(6)}.old")
                _rename(place, aside[-1])
            else:
                try:
                    place.unlink()  # a file or a link where the folder goes: the link, not its target
                except OSError as exc:
                    raise ExsceError(f"cannot write {place}: {exc.strerror or exc}") from None
        _rename(entry, place)  # over a file or a link: replaces it, never writes through it
    for old in aside:
        shutil.rmtree(old, ignore_errors=True)
