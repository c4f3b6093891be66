"""Issue 46, item 1: a ``.exsce`` file never runs code.  A quoted selection string holding a
newline and a Python statement was copied raw into a comment of the generated monitors, so its
second line became code that ``exscec ingest`` ran and that ``generate`` wrote into packages.

Also: ``generate`` refuses to write a file that does not read back in its language, and never
writes through a symbolic link planted in its output folder."""

from __future__ import annotations

import dataclasses
import functools
import os
from pathlib import Path

import pytest

from exsce_dsl.codegen.output import write_files
from exsce_dsl.codegen.readback import check_generated, check_written
from exsce_dsl.errors import ExsceError, GenerationError
from exsce_dsl.lang import load_spec, standard_metrics
from exsce_dsl.model.expressions import Number, Unary
from exsce_dsl.model.metrics import MetricDefinition
from exsce_dsl.monitor_code import load_monitors, monitor_source

from tests.support.cli import exscec_here
from tests.support.hostile_specs import (
    called_names,
    check_files_read_back,
    names_outside_literals,
    python_files,
    write_spec,
)

TARGETS = ("monitors", "ros1-monitor", "ros2-monitor")


def _payload(marker: Path) -> str:
    return f"base_link\n        __import__('os').system('touch {marker}') # "


def _generated(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): p.read_text() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_hostile_selection_string_is_inert(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    spec = write_spec(tmp_path / "hostile", "SELECTION", _payload(marker))
    plain = write_spec(tmp_path / "plain", "SELECTION", "base_link")
    checked = exscec_here("check", str(spec))
    assert checked.returncode in (0, 2) and "Traceback" not in checked.stderr, checked.stderr
    if checked.returncode == 2:  # refused, with where: what still loads must be inert
        assert f"{spec}:" in checked.stderr, checked.stderr
        try:
            load_spec(spec)
        except ExsceError:
            return

    # what ingest renders and runs: the metric's method runs the comment's line, if it is code
    (metric,) = load_spec(spec).metrics
    source = monitor_source([*standard_metrics(), metric], "hostile.exsce")
    (plain_metric,) = load_spec(plain).metrics
    assert called_names(source) <= called_names(monitor_source([*standard_metrics(), plain_metric], "p"))
    assert "__import__" not in names_outside_literals(source)
    module = load_monitors([metric], "hostile.exsce")
    assert module.RobotMetrics("r1", "r1", {}).get_frame_height(0.0, 1.0) is None
    assert not marker.exists()

    for target in TARGETS:
        out, baseline = tmp_path / target, tmp_path / f"{target}-plain"
        done = exscec_here("generate", target, str(spec), "-o", str(out))
        assert done.returncode == 0, done.stderr
        assert exscec_here("generate", target, str(plain), "-o", str(baseline)).returncode == 0
        files, expected = _generated(out), python_files(_generated(baseline))
        check_files_read_back(files)
        for name, text in python_files(files).items():
            assert called_names(text) <= called_names(expected[name]), name
            assert "__import__" not in names_outside_literals(text), name
    assert not marker.exists()


def test_a_generated_file_that_does_not_read_back_is_refused_and_nothing_is_written(tmp_path: Path) -> None:
    files = {"pkg/good.py": "x = 1\n", "pkg/bad.py": "def f(:\n    pass\n"}
    with pytest.raises(GenerationError) as raised:
        write_files(tmp_path / "out", files)
    assert raised.value.location is not None
    assert raised.value.location.file == str(tmp_path / "out" / "pkg" / "bad.py")
    assert raised.value.location.line == 1
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("a.py", "x = 1\n\0\n"),
        ("scripts/node", "#!/usr/bin/env python3\nif x\n"),
        ("config.yaml", "a: [1\n"),
        ("package.xml", "<package><name>x</package>"),
        ("launch/x.launch", "<launch>"),
        ("setup.cfg", "[develop\n"),
        ("CMakeLists.txt", "project(x\n"),
        ("CMakeLists.txt", 'project("x)\n'),
    ],
)
def test_each_language_is_read_back(name: str, text: str) -> None:
    with pytest.raises(GenerationError, match=f"the generated .* file {name} does not read back"):
        check_generated(name, text)


def test_a_written_folder_with_a_broken_file_is_found(tmp_path: Path) -> None:
    done = exscec_here(
        "generate", "ros2-monitor", str(write_spec(tmp_path, "TITLE", "t")), "-o", str(tmp_path / "out")
    )
    assert done.returncode == 0, done.stderr
    written = sorted(p for p in (tmp_path / "out").rglob("*") if p.is_file())
    check_written(written)
    config = next(p for p in written if p.name == "config.py")
    config.write_text(config.read_text() + "ORACLES = [\n")
    with pytest.raises(GenerationError) as raised:
        check_written(written)
    assert raised.value.location is not None and raised.value.location.file == str(config)


def test_generate_output_refuses_planted_symlink(tmp_path: Path) -> None:
    spec = write_spec(tmp_path, "TITLE", "t")
    outside = tmp_path / "outside.txt"
    outside.write_text("mine\n")
    out = tmp_path / "out"
    (out / "exsce_monitors").mkdir(parents=True)
    (out / "exsce_monitors" / "monitors.py").symlink_to(outside)
    done = exscec_here("generate", "monitors", str(spec), "-o", str(out), "--force")
    assert done.returncode == 2 and "is a symbolic link" in done.stderr, done.stderr
    assert str(out / "exsce_monitors" / "monitors.py") in done.stderr
    assert outside.read_text() == "mine\n"
    assert not (out / "exsce_monitors" / "__init__.py").exists()  # nothing written


def test_generate_output_refuses_a_planted_folder_link(tmp_path: Path) -> None:
    spec = write_spec(tmp_path, "TITLE", "t")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / "exsce_monitors").symlink_to(elsewhere, target_is_directory=True)
    done = exscec_here("generate", "monitors", str(spec), "-o", str(out), "--force")
    assert done.returncode == 2 and "is a symbolic link" in done.stderr, done.stderr
    assert list(elsewhere.iterdir()) == []


def test_a_link_swapped_in_after_the_check_is_replaced_not_followed(tmp_path: Path) -> None:
    """The file is written under a fresh name and renamed over its target: even a link that
    appears between the check and the write is replaced, never written through."""
    from exsce_dsl.output_folder import write_below

    outside = tmp_path / "outside.txt"
    outside.write_text("mine\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "x.py").symlink_to(outside)
    with pytest.raises(ExsceError, match="is a symbolic link"):
        write_below(out, "x.py", b"y = 2\n")
    os.unlink(out / "x.py")
    written = write_below(out, "x.py", b"y = 2\n", 0o777)
    assert written.read_text() == "y = 2\n" and outside.read_text() == "mine\n"
    assert os.access(written, os.X_OK) and not written.is_symlink()
    assert sorted(p.name for p in out.iterdir()) == ["x.py"]  # no temporary file left


def test_ingest_of_the_hostile_spec_runs_nothing(tmp_path: Path) -> None:
    """The finding as it was met: ``exscec ingest`` of a run with the hostile spec."""
    from exsce_dsl.sim.run import simulate

    marker = tmp_path / "ran"
    spec = write_spec(tmp_path, "SELECTION", _payload(marker))
    try:
        scenario = load_spec(spec).scenario()
    except ExsceError:
        return  # refused: nothing to ingest
    (run,) = simulate(scenario, tmp_path / "runs", 1, seed=3)
    done = exscec_here("ingest", str(run.bag), "--scenario", str(spec), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert not marker.exists()


def test_generate_of_a_500_term_sum_is_an_error_at_the_metric(tmp_path: Path) -> None:
    """Issue 46, item 9: it passed check, and generate exited 70 (a RecursionError)."""
    spec = tmp_path / "sum.exsce"
    terms = " + ".join(["max(v.data)"] * 500)
    spec.write_text(f'metric m for each robot {{\n  reads v: std_msgs/msg/Float64 on "/{{ns}}/v"\n  value {terms}\n}}\n')
    done = exscec_here("generate", "monitors", str(spec), "-o", str(tmp_path / "out"))
    assert done.returncode == 2 and done.stderr.startswith(f"{spec}:"), done.stderr  # refused where it is
    assert not (tmp_path / "out").exists()
    # a model made in Python is not built by the checks: the generator keeps the same limit
    spec.write_text(spec.read_text().replace(terms, "max(v.data)"))
    (metric,) = load_spec(spec).metrics

    def negated(times: int) -> MetricDefinition:
        value = functools.reduce(lambda e, _: Unary("-", e), range(times), Number(1.0))
        return dataclasses.replace(metric, value=value)

    with pytest.raises(GenerationError, match="nests 101 operations deep, more than the 100"):
        monitor_source([negated(101)], "sum.exsce")
    deep = negated(100)
    assert "core.finite" in monitor_source([deep], "deep.exsce")  # 100 deep: code is written for it
