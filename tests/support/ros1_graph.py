"""A real ROS 1 graph for the tests: roscore, rosbag record and play, nodes run by Debian's Python.

Debian bookworm's ROS 1 (``sh scripts/install-ros1``) installs rospy and rosbag for the
system Python, ``/usr/bin/python3``, not for this project's venv: nothing here imports
rospy.  Every part of the graph is a subprocess in its own process group, its output in a
log file below the graph's ``ROS_HOME``; stopping one stops what it started too (its group,
and what roscore starts in groups of their own: rosmaster, rosout), and every one still
running is stopped when the :func:`ros1_graph` block ends, also when a test fails.  The master
is asked over XML-RPC, as any ROS node asks it.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import time
import xmlrpc.client
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import pytest

from exsce_dsl.execute.ros1.graph import descendants, process_stat

ROS_PYTHON = Path("/usr/bin/python3")
"""Debian's Python, the one rospy, rosbag and the message packages are installed for."""
ROSBAG_FOLDERS = (Path("/usr/lib/rosbag"), Path("/opt/ros/noetic/lib/rosbag"))
"""Where the record and play programs are (Debian's, ROS Noetic's).  They are run directly,
not through the ``rosbag`` script: on SIGINT that script forwards the signal, then calls the
handler it replaced, which raises (or fails: SIG_IGN is no function) at once, while ``record``
is still closing the bag."""
INSTALL = "sh scripts/install-ros1"
IMPORTS = "import rospy, rosbag, genpy, numpy, std_msgs.msg, geometry_msgs.msg, sensor_msgs.msg"
"""What the monitor node and the graph's programs import from Debian's Python."""
CALLER = "/exsce_tests"
"""The caller id the tests give the master."""


def require_ros1() -> None:
    """Fail (not skip: CI installs ROS 1) when the graph's programs or rospy are missing."""
    missing = _missing()
    if missing:
        pytest.fail(f"ROS 1 is not installed ({', '.join(missing)} missing): run {INSTALL}", pytrace=False)


@cache
def _missing() -> tuple[str, ...]:
    """What of ROS 1 is not installed, found once per process (the rospy probe takes a second)."""
    missing = [name for name in ("roscore", "rosbag") if shutil.which(name) is None]
    if not ROS_PYTHON.exists():
        missing.append(str(ROS_PYTHON))
    elif not missing:
        probe = subprocess.run(
            [str(ROS_PYTHON), "-c", IMPORTS],
            capture_output=True,
            text=True,
            env=_clean_environment(),
        )
        if probe.returncode != 0:
            why = (probe.stderr.strip().splitlines() or ["no output"])[-1]
            missing.append(f"rospy or its messages for {ROS_PYTHON} ({why})")
    if _rosbag_program("record") is None:
        missing.append("rosbag's record program")
    return tuple(missing)


def _rosbag_program(name: str) -> Path | None:
    return next((folder / name for folder in ROSBAG_FOLDERS if (folder / name).exists()), None)


def _clean_environment() -> dict[str, str]:
    """This process's environment without what points Python at the venv."""
    drop = {"PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "PYTHONSTARTUP"}
    return {k: v for k, v in os.environ.items() if k not in drop and not k.startswith("ROS_")}


def free_port() -> int:
    """A TCP port of 127.0.0.1 that nothing listens on now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


@dataclass
class Process:
    """One program of the graph, started in its own process group."""

    name: str
    popen: subprocess.Popen[bytes]
    log: Path
    stopped: bool = False
    """Its group is signalled no more: its leader has exited and what it left was killed."""
    below: dict[int, str] = field(default_factory=dict)
    """Processes it started in groups of their own (roslaunch does: rosmaster, rosout), by pid,
    with their start times."""

    def running(self) -> bool:
        return self.popen.poll() is None

    def output(self, last: int = 40) -> str:
        """The last lines of its output, for failure messages."""
        lines = self.log.read_text(errors="replace").splitlines() if self.log.exists() else []
        return "\n".join(lines[-last:])


@dataclass(frozen=True)
class SystemState:
    """The master's view: topic → node names publishing it, and subscribing to it."""

    publishers: dict[str, set[str]]
    subscribers: dict[str, set[str]]


class Graph:
    """A running roscore on 127.0.0.1 and the programs started on it."""

    def __init__(self, home: Path, port: int) -> None:
        self.home = home
        self.port = port
        self.uri = f"http://127.0.0.1:{port}"
        self.env = {
            **_clean_environment(),
            "ROS_MASTER_URI": self.uri,
            "ROS_IP": "127.0.0.1",
            "ROS_HOSTNAME": "127.0.0.1",
            "ROS_HOME": str(home),
            "ROS_LOG_DIR": str(home / "log"),
            "PYTHONUNBUFFERED": "1",
        }
        self.processes: list[Process] = []

    # -- programs ----------------------------------------------------------------------------------

    def start(self, name: str, argv: Sequence[str], pythonpath: Sequence[Path] = ()) -> Process:
        """Start ``argv`` on the graph, its output to ``<ROS_HOME>/<name>.log``."""
        log = self.home / f"{name}.log"
        env = dict(self.env)
        if pythonpath:
            env["PYTHONPATH"] = os.pathsep.join(str(p) for p in pythonpath)
        with log.open("wb") as out:
            popen = subprocess.Popen(
                list(argv),
                stdin=subprocess.DEVNULL,
                stdout=out,
                stderr=subprocess.STDOUT,
                env=env,
                cwd=self.home,
                start_new_session=True,  # its own process group: stop() reaches its children
            )
        process = Process(name, popen, log)
        self.processes.append(process)
        return process

    def stop(self, process: Process, sig: int = signal.SIGINT, timeout: float = 15.0) -> int:
        """Send ``sig`` to the process group of ``process`` (SIGINT: ROS programs shut down cleanly
        on it, record closes its bag); SIGKILL what is left after ``timeout`` seconds."""
        if not process.stopped:
            if process.running():
                process.below.update(descendants(process.popen.pid))
                _signal_group(process, sig)
                try:
                    process.popen.wait(timeout)
                except subprocess.TimeoutExpired:
                    _signal_group(process, signal.SIGKILL)
                    process.popen.wait(5.0)
            self._ended(process)
        return process.popen.returncode

    @staticmethod
    def _ended(process: Process) -> None:
        """Kill what the process left, in its group or below it, as soon as it has exited, once."""
        _signal_group(process, signal.SIGKILL)
        for pid, started in process.below.items():
            if process_stat(pid)[1] == started:  # the same process, not a later one given its pid
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        process.stopped = True

    def run_python(self, name: str, script: Path, *args: str, pythonpath: Sequence[Path] = ()) -> Process:
        """Run ``script`` with Debian's Python (rospy's), ``pythonpath`` in front of its path."""
        return self.start(name, [str(ROS_PYTHON), str(script), *args], pythonpath)

    # -- the master --------------------------------------------------------------------------------

    def master(self) -> xmlrpc.client.ServerProxy:
        return xmlrpc.client.ServerProxy(self.uri)

    def set_param(self, name: str, value: object) -> None:
        code, message, _ = self.master().setParam(CALLER, name, value)
        assert code == 1, f"the master refused to set {name}: {message}"

    def system_state(self) -> SystemState:
        code, message, (publishers, subscribers, _) = self.master().getSystemState(CALLER)
        assert code == 1, f"the master did not tell its state: {message}"
        return SystemState(
            {topic: set(nodes) for topic, nodes in publishers},
            {topic: set(nodes) for topic, nodes in subscribers},
        )

    def wait_until(
        self, done: Callable[[], bool], what: str, timeout: float = 30.0, watch: Sequence[Process] = ()
    ) -> None:
        """Poll ``done`` until it holds; fail saying ``what`` was awaited, with the output of a
        watched process that ended meanwhile or of every watched one at the timeout."""
        deadline = time.monotonic() + timeout
        while not done():
            for process in watch:
                if not process.running():
                    pytest.fail(
                        f"{process.name} ended (exit {process.popen.returncode}) while waiting for {what}:\n"
                        f"{process.output()}",
                        pytrace=False,
                    )
            if time.monotonic() > deadline:
                logs = "\n".join(f"--- {p.name}:\n{p.output()}" for p in watch)
                pytest.fail(f"timed out after {timeout:.0f} s waiting for {what}\n{logs}", pytrace=False)
            time.sleep(0.05)

    def wait_for_subscriptions(
        self, node: str, topics: Sequence[str], process: Process, timeout: float = 30.0
    ) -> None:
        """Until the master lists ``node`` among the subscribers of every one of ``topics``."""

        def subscribed() -> bool:
            state = self.system_state().subscribers
            return all(node in state.get(topic, set()) for topic in topics)

        self.wait_until(subscribed, f"{node} to subscribe to {', '.join(topics)}", timeout, [process])

    # -- rosbag --------------------------------------------------------------------------------------

    def record(self, bag: Path, topics: Sequence[str], name: str = "exsce_record") -> Process:
        """``rosbag record -O bag topics``, as node ``/name``; returns once it has subscribed."""
        program = _rosbag_program("record")
        assert program is not None, f"rosbag's record program is missing: run {INSTALL}"
        process = self.start(name, [str(program), "-O", str(bag), *topics, f"__name:={name}"])
        self.wait_for_subscriptions(f"/{name}", topics, process)
        return process

    def stop_recording(self, process: Process, bag: Path, timeout: float = 30.0) -> Path:
        """Stop ``record`` with SIGINT, as Ctrl-C does, and wait until it has closed the bag:
        written its index and renamed ``bag.active`` to ``bag``."""
        code = self.stop(process, signal.SIGINT, timeout)
        active = bag.with_name(bag.name + ".active")
        self.wait_until(lambda: bag.exists() and not active.exists(), f"{bag.name} to be closed", 10.0)
        assert code == 0, f"rosbag record exited with {code}:\n{process.output()}"
        return bag

    def play(self, bag: Path, rate: float, clock_hz: float, timeout: float = 120.0) -> Process:
        """``rosbag play --clock --hz clock_hz -r rate --wait-for-subscribers bag``, to its end:
        the bag's messages at ``rate`` times their pace, with ``/clock`` in bag time, once each
        topic has a subscriber."""
        program = _rosbag_program("play")
        assert program is not None, f"rosbag's play program is missing: run {INSTALL}"
        argv = [str(program), "--clock", f"--hz={clock_hz}", f"--rate={rate}", "--wait-for-subscribers"]
        process = self.start("exsce_play", [*argv, "--quiet", str(bag), "__name:=exsce_play"])
        try:
            code = process.popen.wait(timeout)
        except subprocess.TimeoutExpired:
            self.stop(process)
            pytest.fail(f"rosbag play did not end within {timeout:.0f} s:\n{process.output()}", pytrace=False)
        self._ended(process)
        assert code == 0, f"rosbag play exited with {code}:\n{process.output()}"
        return process


def gone(pid: int) -> bool:
    """Whether process ``pid`` has ended (or is a zombie its parent has yet to reap)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return True
    return state in ("Z", "X")


def _signal_group(process: Process, sig: int) -> None:
    try:
        os.killpg(process.popen.pid, sig)
    except ProcessLookupError:
        pass


@contextmanager
def ros1_graph(home: Path, sim_time: bool = True) -> Iterator[Graph]:
    """A fresh roscore on a free port of 127.0.0.1 (``ROS_HOME``, logs included, in ``home``),
    up and answering when the block starts, and stopped with everything started on it when the
    block ends.  ``sim_time``: ``/use_sim_time`` is set, so nodes take the time from ``/clock``."""
    require_ros1()
    home.mkdir(parents=True, exist_ok=True)
    graph = Graph(home, free_port())
    try:
        core = graph.start("roscore", ["roscore", "-p", str(graph.port)])

        def answers() -> bool:
            try:
                graph.system_state()
            except OSError:
                return False
            return True

        graph.wait_until(answers, f"the master at {graph.uri} to answer", 30.0, [core])
        core.below.update(descendants(core.popen.pid))
        if sim_time:
            graph.set_param("/use_sim_time", True)
        yield graph
    finally:
        for process in reversed(graph.processes):
            graph.stop(process)


MOVE_BASE_SERVER = Path(__file__).resolve().parents[1] / "fixtures" / "ros1" / "move_base_server.py"
"""The tests' move_base action servers (rospy, actionlib), one per robot, logging the goals they get."""


def start_server(graph: Graph, log: Path, robots: str, *args: str) -> None:
    """The test server for ``robots`` (``tiago1,tiago2``), once its action topics are up."""
    server = graph.run_python(
        "move_base_server", MOVE_BASE_SERVER, "--log", str(log), "--robots", robots, *args
    )
    goals = {f"/{r}/move_base/goal" for r in robots.split(",")}
    graph.wait_until(lambda: goals <= graph.system_state().subscribers.keys(), "the servers", 30.0, [server])


def on_graph(graph: Graph, monkeypatch: pytest.MonkeyPatch) -> None:
    """Point this process's ROS clients (``exscec execute --ros1`` run from it) at ``graph``."""
    monkeypatch.setenv("ROS_MASTER_URI", graph.uri)
    monkeypatch.setenv("ROS_IP", "127.0.0.1")
