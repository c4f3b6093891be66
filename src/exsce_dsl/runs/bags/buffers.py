"""A bag file's bytes, shared by the index readers and the file checks: the file mapped into
memory and unmapped however reading ends, pages already read given back to the kernel, and
little-endian numbers read at an offset."""

from __future__ import annotations

import gc
import mmap
import struct
import traceback
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from exsce_dsl.errors import UnsupportedBag

Buffer = bytes | memoryview | mmap.mmap


@contextmanager
def mapped(path: Path) -> Iterator[mmap.mmap]:
    """The file mapped read-only (an empty file is :class:`UnsupportedBag`), closed however the
    reading ends."""
    with path.open("rb") as f:
        try:
            data = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
        except ValueError as exc:  # an empty file
            raise UnsupportedBag(str(exc)) from None
        try:
            yield data
        except BaseException as exc:
            # the frames the error went through still hold numpy views of the map (the whole file,
            # a chunk, an index): drop them, or close() fails with BufferError and hides the error
            traceback.clear_frames(exc.__traceback__)
            raise
        finally:
            _close(data)


def _close(data: mmap.mmap) -> None:
    """Unmap, once no numpy view of the map is left.  A view caught in a reference cycle lives
    until the collector runs, which a Dask worker runs rarely (it throttles collections): collect
    and try again; a view still alive then unmaps the file when it goes (the map is read-only, the
    file closed), rather than failing a bag whose reading succeeded."""
    try:
        data.close()
    except BufferError:
        gc.collect()
        try:
            data.close()
        except BufferError:
            pass


def release(data: mmap.mmap, start: int, end: int) -> None:
    """Let the kernel drop the pages of chunks already read (keeps resident memory low)."""
    page = mmap.PAGESIZE
    first = start // page * page
    try:
        data.madvise(mmap.MADV_DONTNEED, first, max(0, end - first) // page * page)
    except (AttributeError, OSError, ValueError):  # not on this platform: only memory is lost
        pass


def u32(data: Buffer, at: int) -> int:
    """The little-endian unsigned 32-bit number at byte ``at``."""
    value: int = struct.unpack_from("<I", data, at)[0]
    return value


def u64(data: Buffer, at: int) -> int:
    """The little-endian unsigned 64-bit number at byte ``at``."""
    value: int = struct.unpack_from("<Q", data, at)[0]
    return value
