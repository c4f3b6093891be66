"""The canonical text of ``derive`` blocks (the formatter's part for them)."""

from __future__ import annotations

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.lexical import as_written, read_length
from exsce_dsl.model.derived import DerivedScenario, Step

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
    """A step as written (a ``reallocate`` block takes several lines)."""
    a = step.argument
    name = step.transformation
    if name == "remove_robot":
        return [f"remove robot {a('robot')}" + (f" reassign to {a('reassign')}" if a("reassign") else "")]
    if name == "add_robot":
        text = f"add robot {a('robot')} like {a('like')} at {a('start')}"
        return [text + (f" taking over {a('take_over')}" if a("take_over") else "")]
    if name == "replace_robot":
        text = f"replace robot {a('robot')} by {a('by')}" + (f" like {a('like')}" if a("like") else "")
        return [text + (f" at {a('start')}" if a("start") else "")]
    if name in ("swap_assignment", "swap_start_poses"):
        what = "tasks" if name == "swap_assignment" else "start poses"
        return [f"swap {what} of {a('robot')} and {a('with')}"]
    if name == "reverse_waypoint_order":
        return [f"reverse waypoints of {a('task')}" + (f" as {a('as')}" if a("as") else "")]
    if name == "reverse_task_order":
        return ["reverse task order" + (f" of {a('robot')}" if a("robot") else "")]
    if name == "add_task":
        return [f"add task {a('task')} to {a('robot')}" + (f" at {a('position')}" if a("position") else "")]
    if name == "remove_task":
        if a("task") is None:
            return [f"remove tasks of {a('robot')}"]
        return [f"remove task {a('task')}" + (f" from {a('robot')}" if a("robot") else "")]
    if name == "substitute_task":
        return [f"substitute task {a('task')} by {a('with')}"]
    if name == "add_start_pose":
        return [f"start {a('robot')} at {a('pose')}"]
    if name == "remove_start_pose":
        return [f"remove start pose of {a('robot')}"]
    if name == "move_obstacle":  # metres, as x,y[,z]
        metres = [float(v) for v in (a("to") or "").split(",")]
        texts = [t for t in dict(step.written).get("to", "").split(",") if t.strip()]
        if len(texts) == 3 and len(metres) == 2:  # a z of 0 written out
            metres.append(0.0)
        shown = as_written(metres, texts, read_length) or [repr(v) for v in metres]
        return [f"move obstacle {a('obstacle')} to ({', '.join(shown)})"]
    assert name == "substitute_allocation", name
    runs: list[tuple[str, list[str]]] = []
    for entry in (a("allocation") or "").split(","):
        robot, _, task = (part.strip() for part in entry.partition(":"))
        if runs and runs[-1][0] == robot:
            runs[-1][1].append(task)
        else:
            runs.append((robot, [task]))
    return ["reallocate {", *(f"{INDENT}{robot} does {' then '.join(tasks)}" for robot, tasks in runs), "}"]
