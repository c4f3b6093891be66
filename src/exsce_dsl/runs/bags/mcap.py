"""MCAP bags (ROS 2): read straight from the file's own index, with numpy.

:data:`MCAP` reads an ``.mcap`` file, or a ROS 2 bag folder whose ``metadata.yaml`` says
``storage_identifier: mcap``, over :mod:`exsce_dsl.runs.bags.mcap_index` (the file's
summary, chunks and message indexes), and passes it to the next reader (rosbags') when that
raises :class:`~exsce_dsl.errors.UnsupportedBag`.  A type's definition comes from
the channel's schema (``ros2msg`` or ``ros2idl``), else from the user's files, else from
rosbags' standard typestores.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from exsce_dsl.errors import ExsceError, UnsupportedBag
from exsce_dsl.messages.catalogue import MessageCatalogue, Source, parse_definition, standard_catalogue
from exsce_dsl.runs.bags.chunk_batches import Messages
from exsce_dsl.runs.bags.data import BagData, Check, Reduce, Wanted
from exsce_dsl.runs.bags.formats import MCAP_FILE, ROS2_METADATA
from exsce_dsl.runs.bags.mcap_index import IDL_SEPARATOR, Schema, definitions, read_channels, recorded_span
from exsce_dsl.runs.bags.objects import deserialized, deserializer_for
from exsce_dsl.runs.bags.reader import BagReader
from exsce_dsl.runs.bags.reading_base import IndexReading
from exsce_dsl.textfiles import read_text


def mcap_files(path: Path) -> list[Path] | None:
    """The MCAP files of the bag at ``path``, in order: the file itself, or those a ROS 2 bag
    folder lists; None if it is not an MCAP bag the index reader can read (another storage, or
    files or messages compressed whole, which only rosbags reads)."""
    if path.is_file():
        return [path] if path.suffix == MCAP_FILE.suffix else None
    import yaml  # here: only a ROS 2 bag folder needs it

    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml's: ten times faster
    try:
        text = read_text(path / ROS2_METADATA, ROS2_METADATA)  # bounded: never a FIFO's wait
        info = yaml.load(text, Loader=loader)["rosbag2_bagfile_information"]
        storage, mode = info.get("storage_identifier"), info.get("compression_mode") or ""
        files = [path / str(name) for name in info.get("relative_file_paths") or ()]
    except (ExsceError, yaml.YAMLError, KeyError, TypeError, AttributeError):
        return None
    if storage != "mcap" or str(mode).lower() not in ("", "none") or not files:
        return None
    if any(f.suffix != MCAP_FILE.suffix or not f.is_file() for f in files):
        return None
    return files


def schema_catalogue(schema: Schema, source: Source) -> MessageCatalogue:
    """The definitions a schema holds: ``ros2msg`` (a ``.msg`` text followed by those of the
    types it uses) or ``ros2idl`` (``.idl`` texts, each headed ``IDL: name``)."""
    if not schema.text.strip():
        return MessageCatalogue()
    if schema.encoding == "ros2msg":
        return parse_definition(schema.text, schema.name, "msg", source)
    if not schema.text.startswith(IDL_SEPARATOR + "IDL: "):
        return parse_definition(schema.text, schema.name, "idl", source)
    catalogue = MessageCatalogue()
    for part in schema.text.split(IDL_SEPARATOR)[1:]:
        header, _, text = part.partition("\n")
        name = header.removeprefix("IDL: ").strip()
        catalogue.add(parse_definition(text, name, "idl", source).definitions, source)
    return catalogue


class _Mcap(IndexReading):
    """The fast path for MCAP bags: the file's own index, numpy gathers, no per-message Python."""

    cdr = True

    def read(self, files: list[Path]) -> BagData:
        found: list[tuple[str, Messages]] = []
        spans = []  # the recording's: its topics not read too
        for file in files:
            self.schemas = definitions(file)
            spans.append(recorded_span(file))
            found.extend(read_channels(file, self.match, self.decoder).by_key())
        if not found:
            raise UnsupportedBag("none of the topics")  # rosbags then says whether the bag is empty
        start = min(int(m.times.min()) for _, m in found)
        end = max(int(m.times.max()) for _, m in found)
        start, end = min(start, *(s for s, _ in spans)), max(end, *(e for _, e in spans))
        for topic, messages in found:  # each channel's by its own schema
            if not messages.raws:
                continue
            msgtype = messages.msgtype
            catalogue = self.catalogues[self.catalogue_key(msgtype, messages.definition)]
            store = deserializer_for(catalogue, msgtype)
            order = np.argsort(messages.times, kind="stable")
            read = functools.partial(store.deserialize_cdr, typename=msgtype)
            objects = deserialized(read, [messages.raws[i] for i in order.tolist()], topic)
            self.add_whole(topic, messages.times[order] / 1e9, objects)
        return self.data(start / 1e9, end / 1e9, tuple(sorted({topic for topic, _ in found})))

    def own_types(self, topic: str, msgtype: str, definition: str) -> MessageCatalogue:
        schema = self.schemas[(msgtype, definition)]  # the schema of the file being read
        return schema_catalogue(schema, Source(f"the bag {self.path.name}"))

    def standard_types(self) -> MessageCatalogue:
        return standard_catalogue()

    def keep_whole(self, topic: str, msgtype: str, definition: str) -> None:
        self.catalogue(topic, msgtype, definition)  # from the schemas of the file being read


def _read(
    path: Path, wanted: Mapping[str, Wanted], reduce: Mapping[str, Reduce] | None, check: Check | None
) -> BagData:
    files = mcap_files(path)
    if files is None:
        raise UnsupportedBag("not MCAP files the index reader reads")
    return _Mcap(path, wanted, reduce, check).read(files)


MCAP = BagReader(
    "MCAP",
    claims=lambda path: path.suffix == MCAP_FILE.suffix if path.is_file() else path.is_dir(),
    read=_read,
    formats=(MCAP_FILE,),
)
"""MCAP bags (an ``.mcap`` file, or a ROS 2 bag folder of them), from the files' own index; their
topics are listed by rosbags."""
