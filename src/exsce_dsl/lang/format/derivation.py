"""The canonical text of ``derive`` blocks (the formatter's part for them): each step in its
transformation's phrase, each argument as its type is written."""

from __future__ import annotations

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.lexical import as_written, read_length
from exsce_dsl.model.derived import DerivedScenario, Step
from exsce_dsl.transform import TRANSFORMATIONS, Slot, Transformation, Word, phrase_parts, variants

INDENT = "  "
Line = tuple[str, SourceLocation | None]


def derivation_lines(derived: DerivedScenario) -> list[Line]:
    lines: list[Line] = [(f"derive {derived.id} from {derived.base} {{", derived.location)]
    for step in derived.steps:
        lines.extend(
            (f"{INDENT}{text}", step.location if n == 0 else None) for n, text in enumerate(step_text(step))
        )
    lines.append(("}", None))
    return lines


def step_text(step: Step) -> list[str]:
    """A step as written, in the first phrase of its transformation that holds its arguments
    (a ``reallocate`` block takes several lines)."""
    record = TRANSFORMATIONS[step.transformation]
    given = {k for k, v in step.arguments if v is not None}
    for phrase in record.phrases:
        for variant in variants(phrase_parts(phrase)):
            if {p.parameter for p in variant if isinstance(p, Slot)} == given:
                return _written(record, variant, step)
    raise ValueError(f"no phrase of {step.transformation} takes {sorted(given)}")


def _written(record: Transformation, variant: tuple[Word | Slot, ...], step: Step) -> list[str]:
    lines = [""]
    for part in variant:
        if isinstance(part, Word):
            texts = [part.text]
        else:
            texts = _argument_text(record.type_of(part.parameter), part.parameter, step)
        lines[-1] = f"{lines[-1]} {texts[0]}".strip()
        lines.extend(texts[1:])
    return lines


def _argument_text(kind: str, parameter: str, step: Step) -> list[str]:
    """An argument as a step writes it: its text, or the lines of a block."""
    value = step.argument(parameter) or ""
    if kind == "position":  # metres, as x,y[,z]
        metres = [float(v) for v in value.split(",")]
        texts = [t for t in dict(step.written).get(parameter, "").split(",") if t.strip()]
        if len(texts) == 3 and len(metres) == 2:  # a z of 0 written out
            metres.append(0.0)
        shown = as_written(metres, texts, read_length) or [repr(v) for v in metres]
        return [f"({', '.join(shown)})"]
    if kind == "allocation":
        runs: list[tuple[str, list[str]]] = []
        for entry in value.split(","):
            robot, _, task = (part.strip() for part in entry.partition(":"))
            if runs and runs[-1][0] == robot:
                runs[-1][1].append(task)
            else:
                runs.append((robot, [task]))
        return ["{", *(f"{INDENT}{robot} does {' then '.join(tasks)}" for robot, tasks in runs), "}"]
    return [value]
