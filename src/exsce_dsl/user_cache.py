"""The user's cache folder: what is pure and expensive to make, kept between processes.

Like ``__pycache__``, an entry is only ever found under a digest of everything
it was made from, so it cannot go stale: a change to any of its inputs gives
another name, and the old entry is simply not found again.  Entries are
written whole or not at all (a reader never sees half a file), and a cache
that cannot be read or written only makes exsce slower.

``$EXSCE_CACHE`` names the folder; set empty, nothing is cached.  Otherwise it
is ``$XDG_CACHE_HOME/exsce``, else ``~/.cache/exsce``.

Some entries are run (generated monitors) or unpickled (checked specifications),
so the cache trusts nothing it did not write itself (issue 46):

- the folder and its subfolders are made ``0700``; a folder that another user owns,
  or that its group or everyone may write, is refused with one
  :class:`~exsce_dsl.errors.CacheWarning` and exsce works without a cache;
- an entry is read only if it is a regular file (a symbolic link is not followed)
  owned by the user and writable by no one else, in such a folder;
- each entry starts with an HMAC-SHA256 of its name and content under a key of the
  user's, made with :mod:`secrets` on first use and kept ``0600`` in the folder
  (:data:`KEY_NAME`); an entry whose code does not match is no entry, so its bytes are
  never used.
"""

from __future__ import annotations

import hashlib
import hmac
import os
import stat
import warnings
from pathlib import Path

from exsce_dsl.errors import CacheWarning

MAGIC = b"exsce cache hmac-sha256 1\n"
"""The first bytes of every entry, followed by its 32-byte code, then its content."""

KEY_NAME = "hmac-key"
"""The file in the cache folder holding the user's key (``0600``)."""

KEY_BYTES = 32

_NO_LINK = getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
"""Open flags: a link at the entry's name is not followed (and no child process inherits it)."""

_warned: set[str] = set()
"""The folders already refused in this process, with why (each is warned about once)."""


def cache_folder() -> Path | None:
    """``$EXSCE_CACHE``, else ``$XDG_CACHE_HOME/exsce`` (``~/.cache/exsce``); None when set
    empty, or when the folder exists but is not private to the user (then with a warning)."""
    configured = os.environ.get("EXSCE_CACHE")
    if configured is not None:
        if not configured:
            return None
        folder = Path(configured)
    else:
        base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
        folder = Path(base) / "exsce"
    try:
        status = os.stat(folder)
    except OSError:
        return folder  # not made yet: nothing is found, and writing makes it private
    problem = _unsafe(status, directory=True)
    if problem is not None:
        _refuse(folder, problem)
        return None
    return folder


def read_cached(path: Path) -> bytes | None:
    """The content of the entry at ``path`` (inside :func:`cache_folder`), or None when there is
    none, it cannot be read, it is not the user's own, or its code does not match."""
    root = cache_folder()
    name = _entry_name(root, path)
    if root is None or name is None or not _private_folders(root, path.parent):
        return None
    key = _read_key(root)
    if key is None:
        return None
    data = _read_private_file(path)
    if data is None or not data.startswith(MAGIC):
        return None
    code = data[len(MAGIC) : len(MAGIC) + hashlib.sha256().digest_size]
    content = data[len(MAGIC) + len(code) :]
    if not hmac.compare_digest(code, _code(key, name, content)):
        return None
    return content


def write_cached(path: Path, data: bytes) -> None:
    """Write an entry whole (a reader never sees half a file), with its code; a folder that cannot
    be written, or is not private, is no error, only no cache."""
    root = cache_folder()
    name = _entry_name(root, path)
    if root is None or name is None:
        return
    try:
        _make_private(root, path.parent)
        if not _private_folders(root, path.parent):
            return
        key = _read_key(root) or _make_key(root)
        if key is None:
            return
        partial = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        _write_new(partial, MAGIC + _code(key, name, data) + data)
        partial.replace(path)
    except OSError:
        pass


def _code(key: bytes, name: str, content: bytes) -> bytes:
    """The HMAC of an entry: its name (so an entry cannot pass for another) and its content."""
    return hmac.digest(key, name.encode("utf-8", "surrogateescape") + b"\0" + content, "sha256")


def _entry_name(root: Path | None, path: Path) -> str | None:
    """``path`` relative to the cache folder, or None when it is not inside it."""
    if root is None:
        return None
    try:
        relative = Path(os.path.abspath(path)).relative_to(os.path.abspath(root))
    except ValueError:
        return None
    if not relative.parts or ".." in relative.parts:
        return None
    return relative.as_posix()


def _unsafe(status: os.stat_result, *, directory: bool) -> str | None:
    """Why a file or folder with ``status`` cannot be trusted, or None."""
    wanted = stat.S_ISDIR(status.st_mode) if directory else stat.S_ISREG(status.st_mode)
    if not wanted:
        return "is not a folder" if directory else "is not a regular file"
    if hasattr(os, "geteuid") and status.st_uid != os.geteuid():
        return "belongs to another user"
    if status.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return "may be written by other users"
    return None


def _refuse(folder: Path, problem: str) -> None:
    if f"{folder} {problem}" in _warned:
        return
    _warned.add(f"{folder} {problem}")
    warnings.warn(
        f"the cache folder {folder} {problem}: it is not used (make it yours and 0700, "
        "or choose another with $EXSCE_CACHE)",
        CacheWarning,
        stacklevel=3,
    )


def _private_folders(root: Path, folder: Path) -> bool:
    """Whether each folder from below ``root`` down to ``folder`` is a real folder (not a link)
    private to the user (``root`` itself is checked by :func:`cache_folder`)."""
    try:
        relative = Path(os.path.abspath(folder)).relative_to(os.path.abspath(root))
    except ValueError:
        return False
    current = root
    for part in relative.parts:
        current = current / part
        try:
            if _unsafe(os.lstat(current), directory=True) is not None:
                return False
        except OSError:
            return False
    return True


def _make_private(root: Path, folder: Path) -> None:
    """Make ``root`` and the folders down to ``folder`` that do not exist yet, each ``0700``."""
    if not root.exists():
        root.mkdir(mode=0o700, parents=True)
        os.chmod(root, 0o700)  # whatever the umask
    current = root
    for part in Path(os.path.abspath(folder)).relative_to(os.path.abspath(root)).parts:
        current = current / part
        try:
            current.mkdir(mode=0o700)
            os.chmod(current, 0o700)
        except FileExistsError:
            pass


def _read_private_file(path: Path) -> bytes | None:
    """The bytes of ``path`` if it is a regular file (not a link) of the user's that no one else
    may write; checked on the open file, so it cannot be swapped between check and read."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | _NO_LINK
    try:
        descriptor = os.open(path, flags)
    except OSError:
        return None
    try:
        if _unsafe(os.fstat(descriptor), directory=False) is not None:
            return None
        with os.fdopen(descriptor, "rb", closefd=False) as file:
            return file.read()
    except OSError:
        return None
    finally:
        os.close(descriptor)


def _read_key(root: Path) -> bytes | None:
    """The user's key, if it exists and is private (``0600``); a key others may read is refused."""
    key_path = root / KEY_NAME
    try:
        status = os.lstat(key_path)
    except OSError:
        return None
    if stat.S_ISREG(status.st_mode) and status.st_mode & (stat.S_IRWXG | stat.S_IRWXO):
        _refuse(root, f"holds a key ({KEY_NAME}) that other users may read")
        return None
    key = _read_private_file(key_path)
    return key if key is not None and len(key) == KEY_BYTES else None


def _make_key(root: Path) -> bytes | None:
    """A new key, written ``0600`` beside the entries; when another process made one first, that one."""
    import secrets

    key = secrets.token_bytes(KEY_BYTES)
    partial = root / f"{KEY_NAME}.{os.getpid()}.tmp"
    _write_new(partial, key)
    try:
        os.link(partial, root / KEY_NAME)  # never replaces a key another process made
    except FileExistsError:
        return _read_key(root)
    finally:
        partial.unlink(missing_ok=True)
    return key


def _write_new(path: Path, data: bytes) -> None:
    """Write a new file ``0600`` (a stale one of the same name, or a link there, is removed first)."""
    path.unlink(missing_ok=True)
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NO_LINK
    descriptor = os.open(path, flags, 0o600)
    with os.fdopen(descriptor, "wb") as file:
        file.write(data)
