"""The demo: the whole method on the shipped example, from an empty folder to a report.

The demo runs exactly the ``exscec`` commands that ``docs/tutorial.md`` has a user type by
hand (:data:`STEPS`; a test checks that the two agree), so that what the demo shows is what
the tutorial teaches.  Some steps are meant to fail (the run with a fault): each step says
what it should end with, and the demo went well when every step ended as it should.

Running one command line is the caller's: :func:`run_steps` is given the function that
does it (``exscec demo`` gives its own, in-process), so this layer needs nothing above it.
"""

from __future__ import annotations

import glob
import os
import re
import shlex
import shutil
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path

from exsce_dsl.errors import ExsceError
from exsce_dsl.runs import ROS1_BAG

EXAMPLE = "brsu_building_c"
SCENARIOS = "scenarios"
CONVENTIONS = ("method", "nav2", "move_base")


@dataclass(frozen=True)
class DemoStep:
    title: str
    command: str
    """As typed in a shell, from the project folder (globs allowed)."""
    expected_exit: int = 0
    verdict: str | None = None
    """For a verify step: what the runs it judges are (shown in the summary)."""


STEPS: tuple[DemoStep, ...] = (
    DemoStep(
        "Check the scenario (syntax, references, free space on the map, SHACL)",
        "exscec check scenarios/scenario_c.exsce",
    ),
    DemoStep(
        "Compile it to PROV and add it to the store",
        "exscec compile scenarios/scenario_c.exsce -f provn -o scenario_c.provn --store",
    ),
    DemoStep(
        "Simulate three baseline runs (bags and their run-time PROV)",
        "exscec simulate scenarios/scenario_c.exsce --runs 3 --seed 1 -o runs/baseline",
    ),
    DemoStep(
        "Ingest them: metrics per run and per path segment, one transaction per bag",
        "exscec ingest runs/baseline/*.bag --scenario scenarios/scenario_c.exsce --jobs 2",
    ),
    DemoStep(
        "Build the baseline oracles from the acceptance criteria and the stored runs",
        "exscec baseline scenarios/scenario_c.exsce",
    ),
    DemoStep(
        "Simulate a new run, and one where tiago1 drives too fast",
        "exscec simulate scenarios/scenario_c.exsce --runs 1 --seed 7 -o runs/new",
    ),
    DemoStep(
        "(the faulty run)",
        "exscec simulate scenarios/scenario_c.exsce --runs 1 --seed 8 --fault overspeed:tiago1 "
        "-o runs/faulty",
    ),
    DemoStep(
        "Verify the new run against every oracle (it passes)",
        "exscec verify runs/new/*.bag --scenario scenarios/scenario_c.exsce --junit verdicts-new.xml",
        verdict="new run of scenario_c",
    ),
    DemoStep(
        "Verify the faulty run (it fails its safety limits and the baseline: exit 1)",
        "exscec verify runs/faulty/*.bag --scenario scenarios/scenario_c.exsce",
        expected_exit=1,
        verdict="run of scenario_c with the over-speed fault",
    ),
    DemoStep(
        "Derive a scenario: remove tiago2 and give its tasks to tiago1, with the oracles it must meet",
        "exscec derive scenarios/scenario_c.exsce -t remove_robot --robot tiago2 --reassign tiago1 "
        "--id c_one -o scenarios/c_one.exsce --expect --tolerance 15 --add-to-store",
    ),
    DemoStep(
        "What its runs should show, and where each number comes from", "exscec expect scenarios/c_one.exsce"
    ),
    DemoStep(
        "Simulate the derived scenario",
        "exscec simulate scenarios/c_one.exsce --runs 1 --seed 3 -o runs/c_one",
    ),
    DemoStep(
        "Verify it against its metamorphic oracles (it passes)",
        "exscec verify runs/c_one/*.bag --scenario scenarios/c_one.exsce",
        verdict="run of derived c_one",
    ),
    DemoStep("Where c_one comes from", "exscec lineage c_one"),
    DemoStep(
        "Explore derivations with a planted deadlock: found, and shrunk to the one step it needs (exit 1)",
        "exscec explore scenarios/scenario_c.exsce -n 1 -k 1 -t swap_start_poses -t reverse_task_order "
        "--fault deadlock-start:tiago1:classroom_c025-w002 -o explore/deadlock --junit campaign.xml",
        expected_exit=1,
    ),
    DemoStep(
        "Cluster the stored scenarios, with a dendrogram", "exscec cluster --k 2 --dendrogram clusters.svg"
    ),
    DemoStep("Write the HTML report", "exscec report -o report --spec scenarios/scenario_c.exsce"),
)

LIVE_SCENARIO = "scenarios/scenario_c.exsce"
LIVE_STEPS: tuple[DemoStep, ...] = (
    DemoStep("Check the scenario", f"exscec check {LIVE_SCENARIO}"),
    DemoStep(
        "Compile it to PROV and add it to the store",
        f"exscec compile {LIVE_SCENARIO} -f provn -o scenario_c.provn --store",
    ),
    DemoStep(
        "Execute three baseline runs on the live ROS 1 graph: exsce's stand-in robots serve the move_base "
        "goals, rosbag record records each run",
        f"exscec execute {LIVE_SCENARIO} --ros1 --stand-in --seed 1 --runs 3 -o runs/baseline",
    ),
    DemoStep("Ingest them", f"exscec ingest runs/baseline/*.bag --scenario {LIVE_SCENARIO} --jobs 2"),
    DemoStep("Build the baseline oracles", f"exscec baseline {LIVE_SCENARIO}"),
    DemoStep(
        "Execute a new run and judge it (it passes)",
        f"exscec execute {LIVE_SCENARIO} --ros1 --stand-in --seed 7 -o runs/new --verify "
        "--junit verdicts-new.xml",
        verdict="new run of scenario_c on the live graph",
    ),
    DemoStep(
        "Execute a run where tiago1's stand-in drives too fast, and judge it (it fails: exit 1)",
        f"exscec execute {LIVE_SCENARIO} --ros1 --stand-in --seed 8 --fault overspeed:tiago1 "
        "-o runs/faulty --verify",
        expected_exit=1,
        verdict="live run with the over-speed fault",
    ),
    DemoStep("Write the HTML report", f"exscec report -o report --spec {LIVE_SCENARIO}"),
)
"""``exscec demo --ros1``: the method's loop on a live ROS 1 graph (a roscore of the demo's own),
the robots played by the stand-in in move_base's convention; ``docs/live.md`` has the same steps."""


def _on_ros2(step: DemoStep) -> DemoStep:
    """A live step on ROS 2: Nav2's goals and exsce's recorder, each run's bag a folder."""
    title = step.title.replace("live ROS 1 graph", "live ROS 2 graph").replace("move_base", "Nav2")
    title = title.replace("rosbag record records", "exsce's recorder records")
    command = step.command.replace("--ros1", "--ros2").replace(f"/*{ROS1_BAG.suffix} ", "/*/ ")
    return replace(step, title=title, command=command)


LIVE_ROS2_STEPS: tuple[DemoStep, ...] = tuple(_on_ros2(step) for step in LIVE_STEPS)
"""``exscec demo --ros2``: the same loop on the live ROS 2 graph of ``$ROS_DOMAIN_ID``, the robots
played by the Nav2 stand-in (the example's robot types on Nav2's convention), each run recorded by
exsce's recorder into a rosbag2 MCAP folder."""

_ENDINGS = {0: "passed", 1: "failed", 2: "refused (bad input)", 3: "inconclusive"}
"""What a verify step's exit status says of the runs it judged (the codes of ``exscec --help``)."""


@dataclass(frozen=True)
class StepOutcome:
    """How one step ended."""

    step: DemoStep
    exit_code: int

    @property
    def as_expected(self) -> bool:
        return self.exit_code == self.step.expected_exit

    @property
    def text(self) -> str:
        """``failed, as expected``; ``passed, NOT as expected (expected: failed)``."""
        if self.as_expected:
            return f"{self._shown(self.exit_code)}, as expected"
        expected = self._shown(self.step.expected_exit)
        return f"{self._shown(self.exit_code)}, NOT as expected (expected: {expected})"

    def _shown(self, code: int) -> str:
        if self.step.verdict is not None and code in _ENDINGS:
            return _ENDINGS[code]
        return f"exited {code}"


@dataclass(frozen=True)
class DemoRun:
    """What :func:`run_steps` did: each step's outcome, in order, up to the last one run."""

    folder: Path
    store: str
    steps: tuple[DemoStep, ...]
    outcomes: tuple[StepOutcome, ...]
    seconds: float

    @property
    def unexpected(self) -> tuple[StepOutcome, ...]:
        return tuple(o for o in self.outcomes if not o.as_expected)

    @property
    def stopped(self) -> StepOutcome | None:
        """The step the demo stopped at (the steps after it need what it failed to make), if any."""
        if len(self.outcomes) < len(self.steps) and self.outcomes:
            return self.outcomes[-1]
        return None

    @property
    def as_expected(self) -> bool:
        """Every step ran and ended as it should (the faulty run failing, the others passing)."""
        return len(self.outcomes) == len(self.steps) and not self.unexpected


_ROBOT_TYPE = re.compile(r"^(robot type \S+ \{\n(?:(?!\}).*\n)*?)\}", re.MULTILINE)


def with_convention(text: str, convention: str) -> str:
    """``text`` with every robot type naming ``convention`` (as its last line, where the
    formatter puts it)."""
    return _ROBOT_TYPE.sub(lambda m: f"{m.group(1)}  convention {convention}\n}}", text)


def example_folder() -> Path:
    from exsce_dsl.resources import resource_dir

    return resource_dir("examples") / EXAMPLE


def set_up(folder: Path, convention: str = "method") -> Path:
    """Copy the example into ``folder/scenarios`` (``folder`` must be empty or new), its robot
    types on ``convention``'s topics; return the scenarios' folder."""
    if convention not in CONVENTIONS:
        raise ExsceError(f"unknown convention '{convention}'; the conventions are {', '.join(CONVENTIONS)}")
    if folder.exists() and any(folder.iterdir()):
        raise ExsceError(f"{folder} is not empty: the demo starts from an empty folder (give another one)")
    folder.mkdir(parents=True, exist_ok=True)
    scenarios = folder / SCENARIOS
    shutil.copytree(example_folder(), scenarios)
    if convention != "method":
        for spec in sorted(scenarios.rglob("*.exsce")):
            spec.write_text(with_convention(spec.read_text(encoding="utf-8"), convention), encoding="utf-8")
    return scenarios


def command_argv(command: str) -> list[str]:
    """The arguments of an ``exscec ...`` command line, its globs expanded in the current folder
    (as a shell would)."""
    words = shlex.split(command)
    if not words or words[0] != "exscec":
        raise ValueError(f"not an exscec command: {command!r}")
    expanded: list[str] = []
    for word in words[1:]:
        matches = sorted(glob.glob(word)) if any(c in word for c in "*?[") else []
        expanded += matches or [word]
    return expanded


def store_of(folder: Path, store_url: str | None) -> str:
    """The store the demo in ``folder`` uses."""
    return store_url or os.environ.get("EXSCE_STORE") or str(folder / ".exsce" / "store")


@contextmanager
def _inside(folder: Path, store_url: str | None) -> Iterator[None]:
    before, store_before = Path.cwd(), os.environ.get("EXSCE_STORE")
    os.chdir(folder)
    if store_url is not None:
        os.environ["EXSCE_STORE"] = store_url
    try:
        yield
    finally:
        os.chdir(before)
        if store_url is not None:
            if store_before is None:
                os.environ.pop("EXSCE_STORE", None)
            else:
                os.environ["EXSCE_STORE"] = store_before


@contextmanager
def live_graph(folder: Path) -> Iterator[str]:
    """A roscore of the demo's own (its logs in ``folder/.exsce-ros``), exported as
    ``$ROS_MASTER_URI`` while the block runs; the master's URI."""
    from exsce_dsl.execute import start_master

    before = os.environ.get("ROS_MASTER_URI")
    with start_master(folder.absolute() / ".exsce-ros") as master:
        os.environ["ROS_MASTER_URI"] = master.uri
        try:
            yield master.uri
        finally:
            if before is None:
                os.environ.pop("ROS_MASTER_URI", None)
            else:
                os.environ["ROS_MASTER_URI"] = before


def simulated_by(
    steps: Sequence[DemoStep], simulator: str, behaviour: str | None = None
) -> tuple[DemoStep, ...]:
    """``steps`` with every ``exscec simulate`` played by ``simulator`` (with IR-SIM's ``behaviour``
    when given): the same method on runs another simulator played."""
    added = f" --simulator {simulator}" + (f" --behaviour {behaviour}" if behaviour else "")
    return tuple(
        replace(step, command=step.command + added) if step.command.startswith("exscec simulate ") else step
        for step in steps
    )


def run_steps(
    folder: Path,
    run_command: Callable[[list[str]], int],
    store_url: str | None = None,
    steps: Sequence[DemoStep] | None = None,
    on_step: Callable[[int, DemoStep], None] | None = None,
) -> DemoRun:
    """Run ``steps`` (default: :data:`STEPS`) in ``folder``, each through ``run_command`` (the
    arguments after ``exscec``; returns the exit status), on ``store_url`` if given.

    ``on_step(number, step)`` is called before each step.  A verify step that ends otherwise
    than expected is recorded and the demo goes on (the next steps do not need its verdict);
    any other step that does stops it, since the steps after it need what it makes.
    """
    chosen = tuple(STEPS if steps is None else steps)
    outcomes: list[StepOutcome] = []
    started = time.monotonic()
    with _inside(folder, store_url):
        for number, step in enumerate(chosen, start=1):
            if on_step is not None:
                on_step(number, step)
            outcome = StepOutcome(step, run_command(command_argv(step.command)))
            outcomes.append(outcome)
            if not outcome.as_expected and step.verdict is None:
                break
    return DemoRun(folder, store_of(folder, store_url), chosen, tuple(outcomes), time.monotonic() - started)


def summary_lines(run: DemoRun, walkthrough: str = "docs/tutorial.md") -> list[str]:
    """The summary: how each verify step ended against what it should, where the results are,
    and, when something went otherwise, what."""
    verdict = "every step ended as expected" if run.as_expected else "NOT every step ended as expected"
    lines = [f"Summary ({run.seconds:.0f} s): {verdict}"]
    width = max((len(o.text) for o in run.outcomes if o.step.verdict is not None), default=0)
    for outcome in run.outcomes:
        if outcome.step.verdict is not None:
            lines.append(f"  {outcome.text:{width}}  {outcome.step.verdict}")
    lines.append(f"  store: {run.store}")
    lines.append(f"  report: {run.folder / 'report' / 'index.html'}")
    lines.append(f"  tutorial: {walkthrough} runs the same commands by hand")
    stopped = run.stopped
    if stopped is not None:
        number = len(run.outcomes)
        lines.append(
            f"error: step {number} ({stopped.step.command}): {stopped.text}; "
            "the steps after it need it, so the demo stopped"
        )
    for outcome in run.unexpected:
        if outcome is not stopped:
            lines.append(f"error: {outcome.step.command}: {outcome.text}")
    return lines


def command_hint(cwd: Path, search_path: str | None = None, bin_dir: Path | None = None) -> str | None:
    """One line on how to type the ``exscec ...`` commands the demo prints, when typing ``exscec``
    would not run this exscec (not on PATH, as after the README's first command); else None.

    ``bin_dir`` is the folder of this exscec's script (default: beside this Python's executable,
    as in a virtual environment); ``search_path`` the PATH to look on (default: $PATH).
    """
    scripts = Path(sys.executable).parent if bin_dir is None else bin_dir
    script = scripts / ("exscec.exe" if os.name == "nt" else "exscec")
    if not script.exists():
        return None  # installed some other way: we cannot tell which exscec the user types
    found = shutil.which("exscec", path=os.environ.get("PATH", "") if search_path is None else search_path)
    if found is not None and Path(found).resolve() == script.resolve():
        return None
    shown = _shown_path(scripts, cwd)
    if (scripts / "activate").exists():
        return (
            f"exscec is not on your PATH: to type the demo's commands yourself, first run "
            f"'. {shown}/activate' (or type {scripts.absolute() / script.name} instead of exscec)"
        )
    return f"exscec is not on your PATH: type {scripts.absolute() / script.name} instead of exscec"


def _shown_path(path: Path, cwd: Path) -> str:
    """``path`` relative to ``cwd`` when it is inside it, else absolute."""
    absolute, base = path.absolute(), cwd.absolute()
    try:
        return str(absolute.relative_to(base))
    except ValueError:
        return str(absolute)
