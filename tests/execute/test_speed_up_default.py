"""One default speed-up for the stand-in, wherever it is started from."""

from __future__ import annotations

import inspect

import click

from exsce_dsl.cli.main import main
from exsce_dsl.execute.stand_in.session import DEFAULT_SPEED_UP
from exsce_dsl.explore.ros1_executor import ros1_executor


def _option(command: str, name: str) -> click.Parameter:
    found = main.get_command(click.Context(main), command)
    assert found is not None
    return next(p for p in found.params if p.name == name)


def test_execute_and_stand_in_default_to_the_stand_ins_speed_up() -> None:
    assert DEFAULT_SPEED_UP == 5.0  # a recorder stall of 50 ms is a 0.25 s gap at 5x (session.py)
    assert _option("execute", "speed_up").default == DEFAULT_SPEED_UP
    assert _option("stand-in", "speed_up").default == DEFAULT_SPEED_UP


def test_explore_says_the_same_default() -> None:
    # no click default: the value is chosen with the executor (explore.executors)
    assert f"[default: {DEFAULT_SPEED_UP:g}]" in (_option("explore", "speed_up").help or "")
    assert inspect.signature(ros1_executor).parameters["speed_up"].default == DEFAULT_SPEED_UP
