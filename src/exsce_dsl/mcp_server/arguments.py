"""Tool arguments: the JSON schemas the tools declare, and the check of what a client sends.

A tool's input schema is the one source of truth: clients read it from
``tools/list`` and :func:`checked_arguments` holds every call to it (the SDK's
low-level server does not), so a value that reaches the store has the type and
the form its schema promises.  The schemas use a small part of JSON Schema
(``type`` string, number, boolean or array of strings; ``pattern``,
``maxLength``, ``minItems``, ``maxItems``, ``required``, no other properties),
and the check knows exactly that part.

Identifiers have the forms the rest of exsce gives them: the DSL's names
(scenario, robot, metric and pose ids), pose names with their heading
(``classroom_c025-w001-R0.00_P0.00_Y0.00``) and run uuids.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from typing import Any

from exsce_dsl.errors import ArgumentError
from exsce_dsl.model.names import NAME_PATTERN

__all__ = [
    "NAME",
    "POSE_NAME",
    "RUN_ID",
    "checked_arguments",
    "identifier",
    "object_schema",
]

_ANGLE = r"[-+0-9.eE]+"
NAME = f"^{NAME_PATTERN}$"
"""A DSL id: scenario, robot, metric, task or pose id."""
POSE_NAME = f"^{NAME_PATTERN}-R{_ANGLE}_P{_ANGLE}_Y{_ANGLE}$"
"""A pose's name with its heading, as the store names pose entities."""
RUN_ID = "^[0-9a-fA-F][0-9a-fA-F-]{3,35}$"
"""A run's uuid, or a unique prefix of it of 4 characters or more (tables print 8), as ``exscec
verify`` takes them (:func:`~exsce_dsl.store.queries.resolve_run` says which run it is)."""
MAX_TEXT = 10_000
"""The longest free text a query parameter may hold."""
MAX_VALUES = 1_000
"""The most values a list parameter may hold."""

_FORMS = {
    NAME: "an id (letters, digits, _ and inner -)",
    POSE_NAME: "a pose name with its heading (e.g. classroom_c025-w001-R0.00_P0.00_Y0.00)",
    RUN_ID: "a run uuid or a prefix of one (4 characters or more)",
}


def identifier(pattern: str, description: str) -> dict[str, Any]:
    """The schema of a string of the form ``pattern`` (one of :data:`NAME`, :data:`POSE_NAME`,
    :data:`RUN_ID`)."""
    return {"type": "string", "pattern": pattern, "maxLength": 200, "description": description}


def object_schema(properties: Mapping[str, dict[str, Any]], required: tuple[str, ...] = ()) -> dict[str, Any]:
    """A tool's input schema: these properties, those ``required``, no others."""
    schema: dict[str, Any] = {"type": "object", "properties": dict(properties), "additionalProperties": False}
    if required:
        schema["required"] = list(required)
    return schema


def checked_arguments(schema: Mapping[str, Any], arguments: Mapping[str, Any] | None) -> dict[str, Any]:
    """``arguments`` if they follow ``schema`` (an :func:`object_schema`); an ArgumentError
    naming every problem otherwise."""
    given = dict(arguments or {})
    properties: Mapping[str, Mapping[str, Any]] = schema.get("properties", {})
    problems = [
        f"unknown argument '{name}' (known: {', '.join(properties) or 'none'})"
        for name in given
        if name not in properties
    ]
    problems += [f"missing argument '{name}'" for name in schema.get("required", ()) if name not in given]
    for name, value in given.items():
        if name in properties:
            problems += [f"argument '{name}': {p}" for p in _problems(properties[name], value)]
    if problems:
        raise ArgumentError("; ".join(problems))
    return given


def _problems(schema: Mapping[str, Any], value: Any) -> list[str]:
    kind = schema.get("type")
    if kind == "string":
        if not isinstance(value, str):
            return [f"expected a string, got {_json_type(value)}"]
        if len(value) > schema.get("maxLength", math.inf):
            return [f"longer than {schema['maxLength']} characters"]
        pattern = schema.get("pattern")
        if pattern is not None and not re.fullmatch(pattern, value):
            return [f"{_shown(value)} is not {_FORMS.get(pattern, f'of the form {pattern}')}"]
        return []
    if kind == "number":
        ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
        return [] if ok else [f"expected a finite number, got {_json_type(value)}"]
    if kind == "boolean":
        return [] if isinstance(value, bool) else [f"expected true or false, got {_json_type(value)}"]
    if kind == "array":
        if not isinstance(value, list):
            return [f"expected a list, got {_json_type(value)}"]
        if len(value) < schema.get("minItems", 0):
            return [f"needs at least {schema['minItems']} value(s)"]
        if len(value) > schema.get("maxItems", math.inf):
            return [f"takes at most {schema['maxItems']} values"]
        items = schema.get("items", {})
        return [f"value {i + 1}: {p}" for i, item in enumerate(value) for p in _problems(items, item)]
    return []


def _json_type(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "a list"
    return "an object"


def _shown(value: str) -> str:
    return repr(value if len(value) <= 60 else value[:57] + "...")
