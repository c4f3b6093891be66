"""The vectorised message decoder (:mod:`exsce_dsl.runs.bags.decode`) against rosbags' own deserialiser.

Every reference value here is read from the message objects that rosbags gives
back for the bytes it serialised (``deserialize_ros1``, ``deserialize_cdr``),
by attribute, by this file's own :func:`expected`: no exsce code takes part in
the reference.  The property test makes up message definitions (every ROS
primitive, strings bounded or not, time and duration, headers, fixed arrays,
sequences and bounded sequences, a message nested in another, arrays of
messages with strings of any length inside), registers them in rosbags'
typestores, makes up messages of them, serialises them as ROS 1, little-endian
CDR and big-endian CDR, and decodes every leaf path: every number, every array,
its first and last element, its length, and selections on the elements of
arrays of messages (a value one element has, a value none has), alone and all
at once, with the messages joined, scattered in one buffer, or as equal rows.
The decoder reads the definition as a bag would give it (rosbags'
``generate_msgdef``).

What a path gives is read from the decoder's docstring: a number is one float64
a message; an array of numbers, or a field of every element of an array of
messages, one NaN-padded row a message as wide as the longest (float32 arrays
stay float32); a path that picks (``[0]``, ``[-1]``, a selection) the same with
NaN where there is nothing to pick, and a mask; ``len(...)`` a float64.  An array
inside a picked element is a row too (one a message), of any width where no
message has the element.  Below the property, one test per bug it found.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from exsce_dsl.errors import DecodeError, ExsceError
from exsce_dsl.messages.catalogue import (
    MessageCatalogue,
    Source,
    parse_definition,
    standard_catalogue,
    standard_ros1_catalogue,
)
from exsce_dsl.model.messages import FieldPath, Index, Select
from exsce_dsl.runs.bags.decode import PRESENT, decode
from exsce_dsl.runs.bags.raw_messages import RawMessages

from tests.support import bag_factory as factory

FORMATS = ("ros1", "cdr", "cdr_be")
"""ROS 1 serialization, CDR little-endian, CDR big-endian."""

INTEGERS = {
    "bool": (0, 1),
    "byte": (-(2**7), 2**7 - 1),  # rosbags reads and writes byte as a signed int8
    "char": (0, 2**8 - 1),
    "int8": (-(2**7), 2**7 - 1),
    "uint8": (0, 2**8 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}
PRIMITIVES = (*INTEGERS, "float32", "float64")
ARRAY_DTYPES = {
    "bool": np.bool_,
    "byte": np.int8,
    "char": np.uint8,
    **{n: np.dtype(n) for n in PRIMITIVES[3:]},
}
"""The numpy type rosbags wants for an array of each primitive."""

EXACT = tuple(p for p in PRIMITIVES if p not in ("int64", "uint64"))
"""Primitives whose every value is a float64: the ones a numeric selection is tried on."""

TEXT = "ab_/é"
"""Characters of generated strings (``é`` is two bytes in UTF-8)."""

NOWHERE = "\u2603"
"""A string no generated string holds: a selection on it matches nothing."""

STRUCTS = ("time", "duration", "header")

_names = itertools.count()
_typestores = {"ros1": get_typestore(Stores.ROS1_NOETIC), "ros2": get_typestore(Stores.ROS2_HUMBLE)}


def typestore_of(fmt: str) -> Any:
    return _typestores["ros1" if fmt == "ros1" else "ros2"]


def serialise(fmt: str, message: Any, msgtype: str) -> bytes:
    store = typestore_of(fmt)
    if fmt == "ros1":
        return bytes(store.serialize_ros1(message, msgtype))
    return bytes(store.serialize_cdr(message, msgtype, little_endian=fmt == "cdr"))


def deserialise(fmt: str, raw: bytes, msgtype: str) -> Any:
    store = typestore_of(fmt)
    return store.deserialize_ros1(raw, msgtype) if fmt == "ros1" else store.deserialize_cdr(raw, msgtype)


def catalogue_from_bag_text(fmt: str, msgtype: str) -> MessageCatalogue:
    """The exsce catalogue of ``msgtype`` made from its definition text, as a bag holds it."""
    text, _ = typestore_of(fmt).generate_msgdef(msgtype, ros_version=1 if fmt == "ros1" else 2)
    below = standard_ros1_catalogue() if fmt == "ros1" else standard_catalogue()
    return parse_definition(text, msgtype, "msg", Source("test")).layered(below)


# ------------------------------------------------------------------ definitions


@dataclass(frozen=True)
class Field:
    """One field of a generated definition.  ``kind`` is a primitive, ``string``, ``time``,
    ``duration``, ``header`` or the role of a generated type (``Inner``, ``Deep``)."""

    name: str
    kind: str
    bound: int | None = None  # of a string
    array: str | None = None  # None, "fixed", "seq" or "bounded"
    length: int = 0  # of a fixed array, or the bound of a bounded sequence


@dataclass(frozen=True)
class Definition:
    """Three generated types: ``Top`` holds an array of ``Inner`` (``subs``), ``Inner`` has a
    string ``label`` and may hold ``Deep``s."""

    types: dict[str, tuple[Field, ...]]
    package: str

    def name(self, role: str) -> str:
        return f"{self.package}/msg/{role}"

    def text(self, role: str, fmt: str) -> str:
        return "".join(f"{self._type_text(f, fmt)} {f.name}\n" for f in self.types[role])

    def _type_text(self, field: Field, fmt: str) -> str:
        ros1 = fmt == "ros1"
        base = {
            "time": "time" if ros1 else "builtin_interfaces/Time",
            "duration": "duration" if ros1 else "builtin_interfaces/Duration",
            "header": "std_msgs/Header",
            "string": "string" if field.bound is None else f"string<={field.bound}",
        }.get(field.kind, field.kind)
        if field.kind in self.types:
            base = f"{self.package}/{field.kind}"
        if field.array == "fixed":
            return f"{base}[{field.length}]"
        if field.array == "seq" or (field.array == "bounded" and ros1):  # ROS 1 has no bounded sequences
            return f"{base}[]"
        if field.array == "bounded":
            return f"{base}[<={field.length}]"
        return base

    def fields(self, kind: str, fmt: str) -> tuple[Field, ...]:
        """The fields of a message kind: a generated type, or a standard one."""
        if kind in ("time", "duration"):
            return (Field("sec", "int32"), Field("nanosec", "uint32"))
        if kind == "header":
            stamp = (Field("stamp", "time"), Field("frame_id", "string"))
            return ((Field("seq", "uint32"),) if fmt == "ros1" else ()) + stamp
        return self.types[kind]

    def is_message(self, kind: str) -> bool:
        return kind in STRUCTS or kind in self.types


@st.composite
def fields(draw: Any, role: str, least: int, most: int) -> list[Field]:
    nested = {"Top": ["Inner", "Deep", "header"], "Inner": ["Deep"], "Deep": []}[role]
    kinds = st.sampled_from([*PRIMITIVES, "string", "time", "duration", *nested])
    found = []
    for index in range(draw(st.integers(least, most))):
        kind = draw(kinds)
        bound = draw(st.sampled_from([None, None, 3])) if kind == "string" else None
        array = draw(st.sampled_from([None, None, "fixed", "seq", "bounded"]))
        length = draw(st.integers(1, 3)) if array in ("fixed", "bounded") else 0
        found.append(Field(f"{role[0].lower()}{index}", kind, bound, array, length))
    return found


@st.composite
def definitions(draw: Any) -> Definition:
    deep = draw(fields("Deep", 1, 3))
    inner = draw(fields("Inner", 0, 3))
    inner.insert(draw(st.integers(0, len(inner))), Field("label", "string"))
    top = draw(fields("Top", 0, 4))
    array = draw(st.sampled_from(["fixed", "seq", "bounded"]))
    subs = Field("subs", "Inner", None, array, draw(st.integers(1, 3)) if array != "seq" else 0)
    top.insert(draw(st.integers(0, len(top))), subs)
    return Definition(
        {"Deep": tuple(deep), "Inner": tuple(inner), "Top": tuple(top)}, f"exsce_prop{next(_names)}"
    )


def register(definition: Definition, fmt: str) -> str:
    """Register the generated types in the format's typestore; the top type's name."""
    found: dict[str, Any] = {}
    for role in ("Deep", "Inner", "Top"):
        found.update(get_types_from_msg(definition.text(role, fmt), definition.name(role)))
    typestore_of(fmt).register(found)
    return definition.name("Top")


# ------------------------------------------------------------------ messages


def scalars(kind: str) -> st.SearchStrategy[Any]:
    if kind == "bool":
        return st.booleans()
    if kind in INTEGERS:
        return st.integers(*INTEGERS[kind])
    if kind == "float32":
        return st.floats(width=32)
    return st.floats()


def draw_message(draw: Callable[[Any], Any], definition: Definition, kind: str, fmt: str) -> Any:
    """A rosbags message object of ``kind`` with made-up values."""
    store = typestore_of(fmt)
    if kind in ("time", "duration"):
        cls = store.types[f"builtin_interfaces/msg/{kind.capitalize()}"]
    elif kind == "header":
        cls = store.types["std_msgs/msg/Header"]
    else:
        cls = store.types[definition.name(kind)]
    values = {f.name: draw_field(draw, definition, f, fmt) for f in definition.fields(kind, fmt)}
    return cls(**values)


def draw_field(draw: Callable[[Any], Any], definition: Definition, field: Field, fmt: str) -> Any:
    def one() -> Any:
        if field.kind == "string":
            if field.bound is not None:
                return draw(st.text(alphabet="abc", max_size=field.bound))
            return draw(st.text(alphabet=TEXT, max_size=6))
        if definition.is_message(field.kind):
            return draw_message(draw, definition, field.kind, fmt)
        return draw(scalars(field.kind))

    if field.array is None:
        return one()
    count = field.length if field.array == "fixed" else draw(st.integers(0, field.length or 3))
    items = [one() for _ in range(count)]
    if field.kind in ARRAY_DTYPES:
        return np.array(items, dtype=ARRAY_DTYPES[field.kind])
    return items


# ------------------------------------------------------------------ paths and reference values


@dataclass(frozen=True)
class Want:
    """A path to decode, and the shape of its values: ``number`` (one float64 a message),
    ``row`` (a NaN-padded row a message) or ``count`` (a length, as float64)."""

    path: FieldPath
    shape: str
    float32: bool = False  # a row that stays float32


ABSENT = object()


def attribute(element: Any, names: Sequence[str]) -> Any:
    for name in names:
        element = getattr(element, name)
    return element


def walk(message: Any, steps: Sequence[Any]) -> tuple[Any, bool]:
    """The node at ``steps`` in a rosbags message object, or ABSENT (this file's own reading of
    a path: a name on a list of messages takes that field of every element), and whether it was
    spread so."""
    node = message
    spread = False
    for step in steps:
        if isinstance(step, str):
            if isinstance(node, list):
                node = [getattr(e, step) for e in node]
                spread = True
            else:
                node = getattr(node, step)
        elif isinstance(step, Index):
            if not -len(node) <= step.position < len(node):
                return ABSENT, spread
            node = node[step.position]
        else:
            node = next((e for e in node if attribute(e, step.field) == step.value), ABSENT)
            if node is ABSENT:
                return ABSENT, spread
    return node, spread


def resolve(message: Any, path: FieldPath) -> Any:
    """The value of ``path`` in a rosbags message object (a number, or a row), or ABSENT."""
    node, spread = walk(message, path.steps)
    if node is ABSENT:
        return ABSENT
    if path.length:
        return float(len(node))
    if spread:
        return np.array(node, dtype=np.float64)
    if isinstance(node, np.ndarray):
        return node
    return float(node)


def expected(messages: Sequence[Any], want: Want) -> tuple[np.ndarray, np.ndarray]:
    """The values of ``want`` in every message, from rosbags' objects, and which messages have one."""
    found = [resolve(m, want.path) for m in messages]
    present = np.array([v is not ABSENT for v in found], dtype=bool)
    if want.shape != "row":
        return np.array([math.nan if v is ABSENT else v for v in found], dtype=np.float64), present
    width = max((len(v) for v in found if v is not ABSENT), default=0)
    table = np.full((len(found), width), np.nan, dtype=np.float32 if want.float32 else np.float64)
    for i, v in enumerate(found):
        if v is not ABSENT:
            table[i, : len(v)] = v
    return table, present


def select_fields(definition: Definition, kind: str, fmt: str) -> list[tuple[tuple[str, ...], str]]:
    """Fields of a message kind reachable by names only (no arrays): (names, primitive kind)."""
    found: list[tuple[tuple[str, ...], str]] = []
    for f in definition.fields(kind, fmt):
        if f.array is not None:
            continue
        if definition.is_message(f.kind):
            found += [((f.name, *names), k) for names, k in select_fields(definition, f.kind, fmt)]
        else:
            found.append(((f.name,), f.kind))
    return found


def picks_of(
    draw: Callable[[Any], Any], definition: Definition, field: Field, fmt: str, elements: list[Any]
) -> list[Index | Select]:
    """How to pick one element of an array of messages: first, last, and selections on a string
    field and a number field, each with a value an element has and with one no element has."""
    picks: list[Index | Select] = [Index(0), Index(-1), Index(draw(st.integers(-3, 3)))]
    if field.array == "fixed":  # the language refuses a position a fixed array does not have
        picks = [p for p in picks if -field.length <= p.position < field.length]
    candidates = select_fields(definition, field.kind, fmt)
    texts = [names for names, kind in candidates if kind == "string"]
    numbers = [names for names, kind in candidates if kind in EXACT]
    if texts:
        names = draw(st.sampled_from(texts))
        values = sorted({attribute(e, names) for e in elements})
        if values:
            picks.append(Select(names, draw(st.sampled_from(values))))
        picks.append(Select(names, NOWHERE))
    if numbers:
        names = draw(st.sampled_from(numbers))
        values = sorted({float(attribute(e, names)) for e in elements if not math.isnan(attribute(e, names))})
        if values:
            picks.append(Select(names, draw(st.sampled_from(values))))
        picks.append(Select(names, 0.5 if all(v != 0.5 for v in values) else 0.25))
    return picks


def wants_of(
    draw: Callable[[Any], Any],
    definition: Definition,
    kind: str,
    fmt: str,
    messages: Sequence[Any],
    prefix: tuple[Any, ...] = (),
    spread: bool = False,
) -> list[Want]:
    """Every leaf path below ``prefix`` (a message of ``kind``).  After a spread (a field of every
    element of an array of messages) only names of numbers follow: a row a message is as deep as
    the decoder's output goes."""
    found: list[Want] = []
    for field in definition.fields(kind, fmt):
        steps = (*prefix, field.name)
        message = definition.is_message(field.kind)
        if field.array is None:
            if message:
                found += wants_of(draw, definition, field.kind, fmt, messages, steps, spread)
            elif field.kind != "string":
                found.append(Want(FieldPath(steps), "row" if spread else "number"))
            continue
        if spread:  # an array in every element of an array: not a row a message
            continue
        found.append(Want(FieldPath(steps, length=True), "count"))
        if field.kind == "string":
            continue
        if not message:
            found.append(Want(FieldPath(steps), "row", float32=field.kind == "float32"))
            found += [
                Want(FieldPath((*steps, Index(i))), "number") for i in (0, -1, draw(st.integers(-4, 4)))
            ]
            continue
        elements = [e for m in messages for e in as_list(walk(m, steps)[0])]
        for pick in picks_of(draw, definition, field, fmt, elements):
            found += wants_of(draw, definition, field.kind, fmt, messages, (*steps, pick))
        found += wants_of(draw, definition, field.kind, fmt, messages, steps, spread=True)
    return found


def prefix_picks(prefix: tuple[Any, ...]) -> bool:
    return any(not isinstance(s, str) for s in prefix)


def as_list(value: Any) -> list[Any]:
    return value if isinstance(value, list) else []


# ------------------------------------------------------------------ checking


def check(out: dict[str, np.ndarray], wants: Sequence[Want], messages: Sequence[Any], label: str) -> None:
    """``out`` holds exactly the keys of ``wants`` (and masks of the paths that pick), with the
    values and shapes rosbags' objects give."""
    keys = {w.path.key for w in wants} | {w.path.key + PRESENT for w in wants if w.path.picks}
    assert set(out) == keys, f"{label}: keys {sorted(set(out) ^ keys)} differ"
    n = len(messages)
    for want in wants:
        key = want.path.key
        values, present = expected(messages, want)
        actual = out[key]
        if want.shape == "row" and not present.any():  # no message has it: how wide is not said
            assert actual.ndim == 2 and len(actual) == n and np.isnan(actual).all(), (
                f"{label}: {key}: {actual}"
            )
            values = np.full(actual.shape, np.nan)
        assert actual.shape == values.shape, f"{label}: {key}: shape {actual.shape}, rosbags {values.shape}"
        if want.shape == "row":
            # an array of float32 stays float32; in a picked element it may also come as float64
            wanted = [np.float32] if want.float32 else [np.float64]
            wanted += [np.float64] if want.float32 and want.path.picks else []
            assert actual.dtype in wanted, f"{label}: {key}: dtype {actual.dtype}, wanted {wanted}"
        else:
            assert actual.dtype == np.float64, f"{label}: {key}: dtype {actual.dtype}"
        np.testing.assert_array_equal(actual, values, err_msg=f"{label}: {key}")
        if want.path.picks:
            mask = out[key + PRESENT]
            assert mask.dtype == bool and mask.shape == (n,), (
                f"{label}: {key}{PRESENT}: {mask.dtype} {mask.shape}"
            )
            np.testing.assert_array_equal(mask, present, err_msg=f"{label}: {key}{PRESENT}")


def layouts(raws: Sequence[bytes]) -> dict[str, RawMessages]:
    """The same messages laid out as a reader may hand them over: joined; scattered in one buffer
    (last first, with junk between); equal sizes as rows, and after a junk prefix."""
    found = {"joined": RawMessages.join(raws)}
    buffer = bytearray(b"\xee\xee\xee")
    starts = [0] * len(raws)
    for i in reversed(range(len(raws))):
        buffer += b"\xee" * (i % 3)
        starts[i] = len(buffer)
        buffer += raws[i]
    begin = np.array(starts, dtype=np.int64)
    size = np.array([len(r) for r in raws], dtype=np.int64)
    found["scattered"] = RawMessages(np.frombuffer(bytes(buffer), dtype=np.uint8), begin, begin + size)
    if len(set(size.tolist())) == 1:
        width = int(size[0])
        found["rows"] = RawMessages.rows(
            np.frombuffer(b"".join(raws), dtype=np.uint8).reshape(len(raws), width)
        )
        offset = 5 + np.arange(len(raws), dtype=np.int64) * width
        junk = np.frombuffer(b"\xee" * 5 + b"".join(raws), dtype=np.uint8)
        found["after a prefix"] = RawMessages(junk, offset, offset + width, width)
    return found


# ------------------------------------------------------------------ the property


@pytest.mark.parametrize("fmt", FORMATS)
@settings(
    max_examples=50,
    deadline=None,
    report_multiple_bugs=False,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(definition=definitions(), data=st.data())
def test_decode_agrees_with_rosbags(fmt: str, definition: Definition, data: st.DataObject) -> None:
    msgtype = register(definition, fmt)
    count = data.draw(st.integers(1, 4), label="messages")
    made = [draw_message(data.draw, definition, "Top", fmt) for _ in range(count)]
    raws = [serialise(fmt, m, msgtype) for m in made]
    messages = [deserialise(fmt, r, msgtype) for r in raws]
    catalogue = catalogue_from_bag_text(fmt, msgtype)
    wants = list({w.path: w for w in wants_of(data.draw, definition, "Top", fmt, messages)}.values())
    paths = [w.path for w in wants]
    for label, raw in layouts(raws).items():
        note(f"layout: {label}")
        check(decode(catalogue, msgtype, raw, paths, cdr=fmt != "ros1"), wants, messages, label)
    joined = RawMessages.join(raws)
    for want in wants:  # each path alone walks less of the message
        check(decode(catalogue, msgtype, joined, [want.path], cdr=fmt != "ros1"), [want], messages, "alone")


# ------------------------------------------------------------------ the standard types of the bag factory

BASE, NAME, ARRAY, SEQUENCE = 1, 2, 3, 4  # rosbags' node types


def definition_of(store: Any, msgtype: str) -> Definition:
    """The generated-definition form of a type the typestore knows, and of every type it needs."""
    types: dict[str, tuple[Field, ...]] = {}
    todo = [msgtype]
    while todo:
        name = todo.pop()
        if name in types:
            continue
        found = []
        for fname, desc in store.fielddefs[name][1]:
            array, length = None, 0
            if int(desc[0]) in (ARRAY, SEQUENCE):
                (desc, length), array = desc[1], "fixed" if int(desc[0]) == ARRAY else "seq"
                array = "bounded" if array == "seq" and length else array
            if int(desc[0]) == NAME:
                found.append(Field(fname, desc[1], None, array, length))
                todo.append(desc[1])
            else:
                base, bound = desc[1]
                found.append(Field(fname, base, bound or None, array, length))
        types[name] = tuple(found)
    return Definition(types, "")


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("msgtype", list(factory.BUILDERS))
@settings(
    max_examples=3, deadline=None, report_multiple_bugs=False, suppress_health_check=[HealthCheck.too_slow]
)
@given(data=st.data())
def test_standard_messages_agree_with_rosbags(msgtype: str, fmt: str, data: st.DataObject) -> None:
    """The bag factory's messages (Odometry, PoseStamped, TwistStamped, Imu, TFMessage, LaserScan,
    turtlesim's Pose), every leaf path, read with the standard catalogues (or the bag's text for
    the types only a bag defines)."""
    store = factory.typestore_for("ros1" if fmt == "ros1" else "sqlite3")
    seed = data.draw(st.integers(0, 2**16), label="seed")
    made = [
        m for _, m in factory.series(store, msgtype, data.draw(st.integers(1, 5), label="count"), seed=seed)
    ]
    if fmt == "ros1":
        raws = [bytes(store.serialize_ros1(m, msgtype)) for m in made]
        messages = [store.deserialize_ros1(r, msgtype) for r in raws]
    else:
        raws = [bytes(store.serialize_cdr(m, msgtype, little_endian=fmt == "cdr")) for m in made]
        messages = [store.deserialize_cdr(r, msgtype) for r in raws]
    standard = standard_ros1_catalogue() if fmt == "ros1" else standard_catalogue()
    if msgtype in standard:
        catalogue = standard
    else:
        text, _ = store.generate_msgdef(msgtype, ros_version=1 if fmt == "ros1" else 2)
        catalogue = parse_definition(text, msgtype, "msg", Source("the bag")).layered(standard)
    wants = list(
        {
            w.path: w for w in wants_of(data.draw, definition_of(store, msgtype), msgtype, fmt, messages)
        }.values()
    )
    out = decode(catalogue, msgtype, RawMessages.join(raws), [w.path for w in wants], cdr=fmt != "ros1")
    check(out, wants, messages, "standard")


# ------------------------------------------------------------------ messages of different sizes

SIZES = """\
std_msgs/Header header
string[] names
float64 x
float32[] values
uint8 flag
exsce_sizes/Item[] items
int64 big
"""
ITEM = """\
string child_frame_id
float64[] ranges
int16 code
"""


def sized_messages(fmt: str) -> tuple[str, list[Any]]:
    """Seven messages whose sizes all differ: a frame_id of 0..6 characters before the numbers,
    sequences of 0..6 numbers, strings and items."""
    store = typestore_of(fmt)
    if "exsce_sizes/msg/Sizes" not in store.fielddefs:
        found = get_types_from_msg(ITEM, "exsce_sizes/msg/Item")
        found.update(get_types_from_msg(SIZES, "exsce_sizes/msg/Sizes"))
        store.register(found)
    t = store.types
    messages = []
    for i in range(7):
        stamp = t["builtin_interfaces/msg/Time"](sec=100 + i, nanosec=i * 1000)
        extra = {"seq": i} if fmt == "ros1" else {}
        header = t["std_msgs/msg/Header"](stamp=stamp, frame_id="m" * i, **extra)
        items = [
            t["exsce_sizes/msg/Item"](
                child_frame_id=["base_link", "odom", "laser_frame_x"][k % 3][: 9 - i],
                ranges=np.arange(k, dtype=np.float64) / (i + 1),
                code=-k * i,
            )
            for k in range((i * 2) % 5)
        ]
        messages.append(
            t["exsce_sizes/msg/Sizes"](
                header=header,
                names=["n" * k for k in range(i % 4)],
                x=i * 1.5 - 3,
                values=np.arange(i, dtype=np.float32) * np.float32(0.1),
                flag=i * 37 % 256,
                items=items,
                big=-(2**62) + i,
            )
        )
    return "exsce_sizes/msg/Sizes", messages


SIZED_PATHS = [
    Want(FieldPath(("header", "stamp", "sec")), "number"),
    Want(FieldPath(("header", "stamp", "nanosec")), "number"),
    Want(FieldPath(("x",)), "number"),
    Want(FieldPath(("flag",)), "number"),
    Want(FieldPath(("big",)), "number"),
    Want(FieldPath(("names",), length=True), "count"),
    Want(FieldPath(("values",)), "row", float32=True),
    Want(FieldPath(("values", Index(-1))), "number"),
    Want(FieldPath(("values",), length=True), "count"),
    Want(FieldPath(("items",), length=True), "count"),
    Want(FieldPath(("items", "code")), "row"),
    Want(FieldPath(("items", Index(1), "code")), "number"),
    Want(FieldPath(("items", Select(("child_frame_id",), "odom"), "code")), "number"),
    Want(FieldPath(("items", Select(("child_frame_id",), "base_lin"), "code")), "number"),
    Want(FieldPath(("items", Select(("child_frame_id",), "odom"), "ranges"), length=True), "count"),
]


@pytest.mark.parametrize("fmt", FORMATS)
def test_messages_of_different_sizes_on_one_connection(fmt: str) -> None:
    msgtype, made = sized_messages(fmt)
    raws = [serialise(fmt, m, msgtype) for m in made]
    assert len({len(r) for r in raws}) == len(raws)
    messages = [deserialise(fmt, r, msgtype) for r in raws]
    catalogue = catalogue_from_bag_text(fmt, msgtype)
    out = decode(catalogue, msgtype, RawMessages.join(raws), [w.path for w in SIZED_PATHS], cdr=fmt != "ros1")
    check(out, SIZED_PATHS, messages, fmt)
    # written out by hand, so that the reference reading itself is checked too
    np.testing.assert_array_equal(out["header.stamp.sec"], [100, 101, 102, 103, 104, 105, 106])
    np.testing.assert_array_equal(out["len(items)"], [0, 2, 4, 1, 3, 0, 2])
    np.testing.assert_array_equal(out["flag"], [0, 37, 74, 111, 148, 185, 222])
    np.testing.assert_array_equal(
        out['items[child_frame_id == "odom"].code'], [np.nan, -1, -2, np.nan, -4, np.nan, np.nan]
    )


def test_standard_types_of_different_sizes() -> None:
    """TFMessage with transforms whose child_frame_id lengths differ, from the standard catalogues."""
    for fmt in FORMATS:
        store = typestore_of(fmt)
        if "tf2_msgs/msg/TFMessage" not in store.fielddefs:  # rosbags' noetic store lacks it
            store.register(
                get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage")
            )
        t = store.types
        made = []
        for i in range(6):
            extra = {"seq": i} if fmt == "ros1" else {}
            transforms = []
            for k in range(i % 4):
                header = t["std_msgs/msg/Header"](
                    stamp=t["builtin_interfaces/msg/Time"](sec=i, nanosec=k), frame_id="map"[: i % 4], **extra
                )
                transform = t["geometry_msgs/msg/Transform"](
                    translation=t["geometry_msgs/msg/Vector3"](x=i + k / 10, y=-k, z=0.5),
                    rotation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                )
                child = ["odom", "base_link", "laser"][k % 3] + "_" * i
                transforms.append(
                    t["geometry_msgs/msg/TransformStamped"](
                        header=header, child_frame_id=child, transform=transform
                    )
                )
            made.append(t["tf2_msgs/msg/TFMessage"](transforms=transforms))
        msgtype = "tf2_msgs/msg/TFMessage"
        raws = [serialise(fmt, m, msgtype) for m in made]
        messages = [deserialise(fmt, r, msgtype) for r in raws]
        catalogue = standard_ros1_catalogue() if fmt == "ros1" else standard_catalogue()
        wants = [
            Want(FieldPath(("transforms", "transform", "translation", "x")), "row"),
            Want(FieldPath(("transforms", Index(-1), "header", "stamp", "nanosec")), "number"),
            Want(FieldPath(("transforms",), length=True), "count"),
            Want(
                FieldPath(
                    ("transforms", Select(("child_frame_id",), "base_link_"), "transform", "translation", "y")
                ),
                "number",
            ),
            Want(
                FieldPath(
                    ("transforms", Select(("header", "frame_id"), "ma"), "transform", "translation", "x")
                ),
                "number",
            ),
        ]
        out = decode(catalogue, msgtype, RawMessages.join(raws), [w.path for w in wants], cdr=fmt != "ros1")
        check(out, wants, messages, fmt)
        np.testing.assert_array_equal(out["len(transforms)"], [0, 1, 2, 3, 0, 1])


# ------------------------------------------------------------------ broken bytes

TAIL = """\
string frame_id
float32[] values
exsce_tail/Part[] parts
float64 last
"""
PART = """\
string name
uint16 code
"""
TAIL_PATHS = [
    FieldPath(("last",)),
    FieldPath(("values",)),
    FieldPath(("parts", "code")),
    FieldPath(("parts", Select(("name",), "ab"), "code")),
    FieldPath(("parts",), length=True),
]


def tail_message(fmt: str) -> tuple[str, bytes]:
    """A message whose last field is a number that every path list here reads."""
    store = typestore_of(fmt)
    if "exsce_tail/msg/Tail" not in store.fielddefs:
        found = get_types_from_msg(PART, "exsce_tail/msg/Part")
        found.update(get_types_from_msg(TAIL, "exsce_tail/msg/Tail"))
        store.register(found)
    t = store.types
    parts = [t["exsce_tail/msg/Part"](name="ab"[:k], code=k) for k in range(3)]
    message = t["exsce_tail/msg/Tail"](
        frame_id="odom", values=np.array([1.5, 2.5], dtype=np.float32), parts=parts, last=7.25
    )
    return "exsce_tail/msg/Tail", serialise(fmt, message, "exsce_tail/msg/Tail")


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_truncated_message_is_a_decode_error(fmt: str) -> None:
    msgtype, raw = tail_message(fmt)
    catalogue = catalogue_from_bag_text(fmt, msgtype)
    whole = decode(catalogue, msgtype, RawMessages.join([raw]), TAIL_PATHS, cdr=fmt != "ros1")
    assert whole["last"].tolist() == [7.25]
    for size in range(len(raw)):
        for batch in ([raw[:size]], [raw, raw[:size]], [raw[:size], raw]):
            with pytest.raises(DecodeError):
                decode(catalogue, msgtype, RawMessages.join(batch), TAIL_PATHS, cdr=fmt != "ros1")


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_length_prefix_past_the_end_is_a_decode_error(fmt: str) -> None:
    """Each length prefix (of the string, the float32 sequence, the parts) set far too large."""
    msgtype, raw = tail_message(fmt)
    catalogue = catalogue_from_bag_text(fmt, msgtype)
    start = 0 if fmt == "ros1" else 4
    order = "big" if fmt == "cdr_be" else "little"
    string_at = start
    values_at = string_at + 4 + len("odom") + (0 if fmt == "ros1" else 1)
    values_at += -values_at % 4 if fmt != "ros1" else 0
    parts_at = values_at + 4 + 2 * 4
    for at in (string_at, values_at, parts_at):
        for huge in (2**31 - 1, 2**32 - 1, 1000):
            broken = raw[:at] + huge.to_bytes(4, order) + raw[at + 4 :]
            with pytest.raises(DecodeError):
                decode(catalogue, msgtype, RawMessages.join([broken]), TAIL_PATHS, cdr=fmt != "ros1")


def test_big_endian_cdr_float32_rows_are_native_float32() -> None:
    msgtype, raw = tail_message("cdr_be")
    assert raw[:2] == b"\x00\x00"  # rosbags wrote big-endian CDR
    out = decode(
        catalogue_from_bag_text("cdr_be", msgtype),
        msgtype,
        RawMessages.join([raw, raw]),
        TAIL_PATHS,
        cdr=True,
    )
    assert out["values"].dtype == np.dtype(np.float32)
    assert out["values"].tolist() == [[1.5, 2.5], [1.5, 2.5]]
    assert out["last"].tolist() == [7.25, 7.25]
    assert out["parts.code"].tolist() == [[0, 1, 2], [0, 1, 2]]
    assert out['parts[name == "ab"].code'].tolist() == [2, 2]


# ------------------------------------------------------------------ one test per bug found


def one_type(fmt: str, msgtype: str, types: dict[str, str]) -> MessageCatalogue:
    """Register ``types`` (name → .msg text) in the format's typestore, once; the exsce catalogue
    of ``msgtype`` from its bag text."""
    store = typestore_of(fmt)
    if msgtype not in store.fielddefs:
        found: dict[str, Any] = {}
        for name, text in types.items():
            found.update(get_types_from_msg(text, name))
        store.register(found)
    return catalogue_from_bag_text(fmt, msgtype)


def test_equal_size_messages_after_a_prefix_are_read_from_their_starts() -> None:
    """Messages of one size, one after the other, but not from the buffer's first byte (as in a
    bag's chunk): ``width`` is set, the first start is 3."""
    catalogue = one_type("ros1", "exsce_bug/msg/Single", {"exsce_bug/msg/Single": "float64 x"})
    raws = [
        serialise("ros1", typestore_of("ros1").types["exsce_bug/msg/Single"](x=x), "exsce_bug/msg/Single")
        for x in (1.5, 2.5)
    ]
    buffer = np.frombuffer(b"\x00\x00\x00" + b"".join(raws), dtype=np.uint8)
    starts = np.array([3, 11], dtype=np.int64)
    out = decode(
        catalogue,
        "exsce_bug/msg/Single",
        RawMessages(buffer, starts, starts + 8, 8),
        [FieldPath(("x",))],
        cdr=False,
    )
    assert out["x"].tolist() == [1.5, 2.5]


@pytest.mark.parametrize("fmt", FORMATS)
def test_byte_is_signed_as_rosbags_reads_it(fmt: str) -> None:
    """rosbags reads ``byte`` as int8 (ROS 1's definition of it), ``char`` as uint8."""
    msgtype = "exsce_bug/msg/Bytes"
    catalogue = one_type(fmt, msgtype, {msgtype: "byte b\nbyte[] bs\nchar c\nchar[] cs"})
    made = typestore_of(fmt).types[msgtype](
        b=-56, bs=np.array([-1, 5], dtype=np.int8), c=200, cs=np.array([255, 1], dtype=np.uint8)
    )
    raw = serialise(fmt, made, msgtype)
    message = deserialise(fmt, raw, msgtype)
    assert (message.b, message.bs.tolist(), message.c, message.cs.tolist()) == (-56, [-1, 5], 200, [255, 1])
    paths = [
        FieldPath(("b",)),
        FieldPath(("bs",)),
        FieldPath(("c",)),
        FieldPath(("cs",)),
        FieldPath(("bs", Index(0))),
    ]
    out = decode(catalogue, msgtype, RawMessages.join([raw]), paths, cdr=fmt != "ros1")
    assert {k: v.tolist() for k, v in out.items() if not k.endswith(PRESENT)} == {
        "b": [-56.0],
        "bs": [[-1.0, 5.0]],
        "c": [200.0],
        "cs": [[255.0, 1.0]],
        "bs[0]": [-1.0],
    }


PICKED = {
    "exsce_bug/msg/Point": "float64 x\nstring name",
    "exsce_bug/msg/Part": "string label\nfloat32[] values\nexsce_bug/Point[] points",
    "exsce_bug/msg/Whole": "exsce_bug/Part[] parts",
}


@pytest.mark.parametrize("fmt", FORMATS)
def test_an_array_in_a_picked_element_is_a_row_a_message(fmt: str) -> None:
    """``parts[-1].values`` and ``parts[-1].points.x``: one row a message (NaN-padded, NaN where
    there is no such part), and a mask."""
    msgtype = "exsce_bug/msg/Whole"
    catalogue = one_type(fmt, msgtype, PICKED)
    t = typestore_of(fmt).types

    def part(k: int) -> Any:
        points = [t["exsce_bug/msg/Point"](x=k + j / 4, name="p" * j) for j in range(k)]
        return t["exsce_bug/msg/Part"](
            label="l" * k, values=np.arange(k, dtype=np.float32) / 2, points=points
        )

    raws = [serialise(fmt, t[msgtype](parts=[part(k) for k in range(i)]), msgtype) for i in (0, 2, 3)]
    messages = [deserialise(fmt, r, msgtype) for r in raws]
    wants = [
        Want(FieldPath(("parts", Index(-1), "values")), "row", float32=True),
        Want(FieldPath(("parts", Index(-1), "points", "x")), "row"),
        Want(FieldPath(("parts", Select(("label",), "l"), "points", "x")), "row"),
    ]
    out = decode(catalogue, msgtype, RawMessages.join(raws), [w.path for w in wants], cdr=fmt != "ros1")
    check(out, wants, messages, fmt)
    nan = math.nan
    np.testing.assert_array_equal(out["parts[-1].values"], [[nan, nan], [0, nan], [0, 0.5]])
    np.testing.assert_array_equal(out["parts[-1].points.x"], [[nan, nan], [1, nan], [2, 2.25]])
    assert out["parts[-1].values#present"].tolist() == [False, True, True]


@pytest.mark.parametrize("size", range(4))
def test_a_message_shorter_than_the_cdr_header_is_a_decode_error(size: int) -> None:
    msgtype, raw = tail_message("cdr")
    catalogue = catalogue_from_bag_text("cdr", msgtype)
    for batch in ([raw[:size]], [raw, raw[:size]]):
        with pytest.raises(DecodeError):
            decode(catalogue, msgtype, RawMessages.join(batch), TAIL_PATHS, cdr=True)


NOT_ANSWERABLE = {
    "no such field": FieldPath(("nope",)),
    "steps past a number": FieldPath(("header", "stamp", "sec", "oops")),
    "text": FieldPath(("header", "frame_id")),
    "a sub-message": FieldPath(("header",)),
    "text of every element": FieldPath(("parts", "label")),
    "an element of an array of texts": FieldPath(("names", Index(0))),
    "an array in every element": FieldPath(("parts", "values")),
    "an array of messages in every element": FieldPath(("parts", "points", "x")),
    "a selection on an array": FieldPath(("parts", Select(("values",), 1.0), "label")),
}


@pytest.mark.parametrize("path", NOT_ANSWERABLE.values(), ids=NOT_ANSWERABLE.keys())
def test_a_path_without_numbers_to_decode_is_an_error(path: FieldPath) -> None:
    """A path that names no field of the definition, or no number a message has (nor a row of
    them a message), is an exsce error; not a crash of numpy, not NaNs, not a missing key."""
    fmt = "cdr"
    msgtype = "exsce_bug/msg/Named"
    catalogue = one_type(
        fmt, msgtype, {**PICKED, msgtype: "std_msgs/Header header\nstring[] names\nexsce_bug/Part[] parts"}
    )
    t = typestore_of(fmt).types
    header = t["std_msgs/msg/Header"](
        stamp=t["builtin_interfaces/msg/Time"](sec=1, nanosec=2), frame_id="map"
    )
    part = t["exsce_bug/msg/Part"](label="a", values=np.array([1.0], dtype=np.float32), points=[])
    raw = serialise(fmt, t[msgtype](header=header, names=["x"], parts=[part, part]), msgtype)
    with pytest.raises(ExsceError):
        decode(catalogue, msgtype, RawMessages.join([raw]), [path], cdr=True)
