"""Say what is wrong with a bag before reading it: its format, emptiness, truncation, compression.

The readers (ours for ROS 1 bags, rosbags' for the rest) are fast on
well-formed bags and trust their structure: given a damaged or foreign file
they fail deep inside, in terms of offsets and records, or not at all (under
``python -O`` rosbags' asserts are gone, and a broken index can be read as
garbage).  :func:`check_bag_file` looks first, at what can be told cheaply
(magic bytes, headers, indexes, summaries and message definitions, never the
messages), and says in a user's terms what the file is, what is wrong with it
and what to do about it.  A bag that passes may still hold damaged chunks; its
reader reports those.
"""

from __future__ import annotations

import mmap
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path, PurePath
from typing import Any

from exsce_dsl.errors import BagError, ExsceError, FileProblem
from exsce_dsl.runs.bags.formats import BUILT_IN_FORMATS, MCAP_FILE, ROS1_BAG, ROS2_METADATA, BagFormat
from exsce_dsl.textfiles import read_text


@dataclass(frozen=True)
class Compression:
    """A format that compresses a file as a whole: how to recognise it and how to undo it."""

    name: str
    magic: bytes
    suffixes: tuple[str, ...]
    command: str  # {file}: the compressed file, {out}: the bag it holds


WHOLE_FILE = (
    Compression("zstd", b"\x28\xb5\x2f\xfd", (".zst", ".zstd"), "zstd -d {file} -o {out}"),
    Compression("bzip2", b"BZh", (".bz2",), "bzip2 -dc {file} > {out}"),
    Compression("gzip", b"\x1f\x8b", (".gz",), "gzip -dc {file} > {out}"),
    Compression("lz4", b"\x04\x22\x4d\x18", (".lz4",), "lz4 -d {file} {out}"),
    Compression("xz", b"\xfd7zXZ\x00", (".xz",), "xz -dc {file} > {out}"),
)
"""Whole-file compressions a bag may come in (a bag's own chunks are compressed inside it)."""


def check_bag_file(path: Path, formats: Sequence[BagFormat] = BUILT_IN_FORMATS) -> None:
    """Raise :class:`BagError` if ``path`` is not a bag exsce can read, saying why and what to do.

    ``path`` is a file of one of ``formats`` (a ROS 1 bag, an MCAP file, a ROS 2 sqlite3 file)
    or a ROS 2 bag folder.  Only headers, indexes and message definitions are read, so the
    check costs little even for large bags.
    """
    if not path.exists():
        raise BagError(f"{path}: no such bag")
    if not path.is_file() and not path.is_dir():
        raise BagError(f"{path}: not a bag: neither a file nor a folder")
    if path.name == ROS2_METADATA:
        raise BagError(f"{path}: the metadata of a ROS 2 bag, not the bag: give its folder, {path.parent}")
    try:
        if path.is_dir():
            _check_ros2_folder(path, formats)
        else:
            _check_file(path, formats)
    except FileProblem as problem:
        raise BagError(f"{path}: {problem}") from None
    except OSError as exc:  # unreadable: permissions, a disk error
        raise BagError(f"{path}: cannot read the bag: {exc.strerror or exc}") from None


def _check_file(path: Path, formats: Sequence[BagFormat]) -> None:
    size = path.stat().st_size
    if size == 0:
        raise FileProblem("the file is empty (0 bytes): nothing was recorded into it")
    with path.open("rb") as stream:
        head = stream.read(64)
    for compression in WHOLE_FILE:
        if head.startswith(compression.magic):
            raise FileProblem(_compressed(path, compression))
    for format_ in formats:
        if head.startswith(format_.magic):
            _named(path, format_.suffix, format_.what)
            if format_.check is not None:
                _check_mapped(path, format_.check)
            return
    if head.startswith((b"#ROSRECORD V", b"#ROSBAG V")):
        raise FileProblem(_old_format(path, head))
    raise FileProblem(
        "not a bag: a ROS 1 bag starts with '#ROSBAG V2.0', an MCAP file with MCAP's magic bytes, "
        "and a ROS 2 bag is a folder holding metadata.yaml"
    )


def _named(path: Path, suffix: str, what: str) -> None:
    if path.suffix != suffix:
        raise FileProblem(
            f"{what}, but named '{path.name}': exsce tells a bag's format by its name; "
            f"rename it to end in {suffix}"
        )


def _compressed(path: Path, compression: Compression) -> str:
    if path.suffix in compression.suffixes:
        out = path.with_suffix("")
    else:
        out = path.with_name(f"{path.stem}.decompressed{path.suffix}")
    command = compression.command.format(file=path, out=out)
    return (
        f"the file is compressed as a whole ({compression.name}), so it is no bag exsce can read; "
        f"decompress it first (`{command}`) and ingest {out.name}"
    )


def _old_format(path: Path, head: bytes) -> str:
    version = head.split(b"\n", 1)[0].rsplit(b"V", 1)[-1].decode("ascii", "replace")
    if head.startswith(b"#ROSRECORD V"):
        fixed = path.with_suffix(".v2" + ROS1_BAG.suffix)
        return (
            f"a ROS bag of the old format {version} (ROS before 2010), which exsce does not read (only "
            f"format 2.0); migrate it with ROS 1's `rosbag fix {path} {fixed}`, "
            "which writes format 2.0, and ingest the result"
        )
    return f"a ROS bag of format {version}; exsce reads ROS 1 bags of format 2.0 only"


def _check_mapped(path: Path, check: Callable[[mmap.mmap, Path], None]) -> None:
    """``check`` the file mapped into memory (only the pages it reads are read)."""
    try:
        with path.open("rb") as stream, mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ) as data:
            check(data, path)
    except (struct.error, IndexError):  # a number or a record cut off by the end of the file
        raise FileProblem("the file is damaged: a record runs past its end (truncated?)") from None


def _check_ros2_folder(folder: Path, formats: Sequence[BagFormat]) -> None:
    meta = folder / ROS2_METADATA
    if not meta.is_file() and not meta.exists():
        inside = sorted(p.name for p in folder.iterdir())
        if not inside:
            raise BagError(
                f"{folder}: an empty folder, not a ROS 2 bag "
                "(which holds metadata.yaml and its .db3 or .mcap files)"
            )
        suffixes = tuple(f.suffix for f in formats if f.in_folder)
        storage = [name for name in inside if name.endswith(suffixes)]
        if not storage:
            raise BagError(f"{folder}: not a bag: a folder without metadata.yaml, .db3 or .mcap files")
        raise BagError(
            f"{folder}: a ROS 2 bag folder without its metadata.yaml (was the recording killed?); rebuild "
            f"it with `ros2 bag reindex {folder}`"
            + (f", or ingest {folder / storage[0]} itself" if storage[0].endswith(MCAP_FILE.suffix) else "")
        )
    import yaml  # here: only a ROS 2 bag folder needs it

    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml's bounds its nesting (issue 46)
    try:
        info = _bag_information(yaml.load(read_text(meta, ROS2_METADATA), Loader=loader))
    except ExsceError as exc:
        raise BagError(f"{folder}: {exc.message}") from None
    except (yaml.YAMLError, RecursionError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else "nested too deeply"
        raise BagError(f"{folder}: its metadata.yaml does not parse: {reason}") from None
    except FileProblem as problem:
        raise BagError(f"{folder}: its metadata.yaml {problem}") from None
    storage_id = str(info.get("storage_identifier", ""))
    if storage_id not in ("sqlite3", "mcap"):
        raise BagError(f"{folder}: a ROS 2 bag stored with {storage_id!r}; exsce reads sqlite3 and mcap bags")
    foreign = sorted(
        (str(t["topic_metadata"].get("name")), str(t["topic_metadata"].get("serialization_format")))
        for t in info["topics_with_message_count"]
        if t["topic_metadata"].get("serialization_format") != "cdr"
    )
    if foreign:
        listed = ", ".join(f"{topic} ({fmt})" for topic, fmt in foreign)
        raise BagError(
            f"{folder}: its metadata.yaml names topics not serialized as CDR: {listed}; "
            "exsce reads ROS 2's CDR messages only"
        )
    mode = str(info.get("compression_mode") or "").lower()
    compression = str(info.get("compression_format") or "")
    if mode not in ("", "none") and compression != "zstd":
        raise BagError(f"{folder}: a ROS 2 bag compressed with {compression!r}; exsce reads zstd only")
    for name in info["relative_file_paths"]:
        file = folder / PurePath(str(name)).name
        if not file.is_file():
            raise BagError(f"{folder}: its file {file.name}, named in metadata.yaml, is missing")
        if mode == "file":  # each file compressed whole, on purpose: the reader decompresses it
            if file.stat().st_size == 0:
                raise BagError(f"{folder}: {file.name}: the file is empty (0 bytes)")
            continue
        try:
            _check_file(file, formats)
        except FileProblem as problem:
            raise BagError(f"{folder}: {file.name}: {problem}") from None
    if info.get("message_count") == 0:
        raise BagError(f"{folder}: the bag holds no messages (its recording stopped before any arrived?)")


def _bag_information(meta: Any) -> dict[str, Any]:
    """The ``rosbag2_bagfile_information`` of a metadata.yaml, with the parts read here checked."""
    info = meta.get("rosbag2_bagfile_information") if isinstance(meta, dict) else None
    if not isinstance(info, dict):
        raise FileProblem("is not a ROS 2 bag's: it has no rosbag2_bagfile_information")
    topics = info.get("topics_with_message_count") or []
    if not isinstance(topics, list) or not all(
        isinstance(t, dict) and isinstance(t.get("topic_metadata"), dict) for t in topics
    ):
        raise FileProblem("is damaged: its topics_with_message_count is not a list of topics")
    files = info.get("relative_file_paths")
    if not isinstance(files, list) or not files:
        raise FileProblem("names no storage file (relative_file_paths)")
    return {**info, "topics_with_message_count": topics}
