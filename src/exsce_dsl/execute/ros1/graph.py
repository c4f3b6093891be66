"""A live ROS 1 graph as exsce meets it: rospy's Python, the master, a master of our own.

rospy is not in this project's venv: Debian (``python3-rospy``) and ROS Noetic install it for the
system Python.  exsce's ROS-side nodes (:mod:`.channel`) run with that Python, found as
``$EXSCE_ROS_PYTHON`` or ``/usr/bin/python3``; everything else (the mission core, planning,
ingesting) stays in this process.  The master is asked over XML-RPC, as every ROS node asks it,
so setting and dumping parameters needs no rospy.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import time
import xmlrpc.client
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any
from urllib.parse import urlparse

from exsce_dsl.errors import RosGraphError
from exsce_dsl.remedies import START_A_MASTER

ROS_PYTHON_VARIABLE = "EXSCE_ROS_PYTHON"
DEFAULT_ROS_PYTHON = Path("/usr/bin/python3")
CALLER = "/exsce"
"""The caller id exsce gives the master."""
INSTALL_HINT = "install ROS 1 (on Debian: sh scripts/install-ros1; on Ubuntu: ROS Noetic)"
NODE_IMPORTS = "import rospy, actionlib, move_base_msgs.msg, nav_msgs.msg, tf2_msgs.msg, rosgraph_msgs.msg"
"""What exsce's ROS 1 nodes import from rospy's Python."""


def ros_python() -> Path:
    """The Python that has rospy: ``$EXSCE_ROS_PYTHON``, else Debian's ``/usr/bin/python3``."""
    named = os.environ.get(ROS_PYTHON_VARIABLE)
    python = Path(named) if named else DEFAULT_ROS_PYTHON
    if not python.exists():
        raise RosGraphError(f"no Python for ROS 1 at {python} (set {ROS_PYTHON_VARIABLE}); {INSTALL_HINT}")
    return python


def check_ros_python(python: Path) -> None:
    """Raise :class:`RosGraphError` when ``python`` lacks what exsce's nodes import."""
    probe = subprocess.run(
        [str(python), "-c", NODE_IMPORTS], capture_output=True, text=True, env=node_environment(None)
    )
    if probe.returncode != 0:
        why = (probe.stderr.strip().splitlines() or ["no output"])[-1]
        raise RosGraphError(f"{python} cannot run exsce's ROS 1 nodes ({why}); {INSTALL_HINT}")


def node_environment(master_uri: str | None, ros_home: Path | None = None) -> dict[str, str]:
    """This process's environment for a ROS-side program: without what points Python at the venv,
    with the master's URI (and a ROS home) when given."""
    drop = {"PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "PYTHONSTARTUP"}
    env = {k: v for k, v in os.environ.items() if k not in drop}
    env["PYTHONUNBUFFERED"] = "1"
    if master_uri is not None:
        env["ROS_MASTER_URI"] = master_uri
        host = urlparse(master_uri).hostname or ""
        if host in {"127.0.0.1", "localhost"} and "ROS_IP" not in env and "ROS_HOSTNAME" not in env:
            env["ROS_IP"] = "127.0.0.1"
    if ros_home is not None:
        env["ROS_HOME"] = str(ros_home)
        env["ROS_LOG_DIR"] = str(ros_home / "log")
    return env


def master_uri() -> str:
    """``$ROS_MASTER_URI``, as every ROS tool reads it (an error if it is not set)."""
    uri = os.environ.get("ROS_MASTER_URI")
    if not uri:
        raise RosGraphError("ROS_MASTER_URI is not set", remedy=START_A_MASTER)
    return uri


class Master:
    """The ROS master at ``uri``, asked over XML-RPC."""

    def __init__(self, uri: str) -> None:
        self.uri = uri
        self._proxy = xmlrpc.client.ServerProxy(uri, allow_none=True)

    def _call(self, method: str, *args: Any) -> Any:
        try:
            code, message, value = getattr(self._proxy, method)(CALLER, *args)
        except (OSError, xmlrpc.client.Error) as e:
            raise RosGraphError(f"no ROS master answers at {self.uri} ({e})") from e
        if code != 1:
            raise RosGraphError(f"the ROS master at {self.uri} refused {method}: {message}")
        return value

    def reachable(self) -> bool:
        try:
            self._call("getPid")
        except RosGraphError:
            return False
        return True

    def wait(self, timeout: float) -> None:
        """Wait until the master answers; :class:`RosGraphError` after ``timeout`` seconds."""
        deadline = time.monotonic() + timeout
        while not self.reachable():
            if time.monotonic() > deadline:
                raise RosGraphError(f"no ROS master answers at {self.uri} after {timeout:g} s")
            time.sleep(0.1)

    def set_param(self, name: str, value: Any) -> None:
        self._call("setParam", name, value)

    def get_param(self, name: str) -> Any:
        return self._call("getParam", name)

    def has_param(self, name: str) -> bool:
        return bool(self._call("hasParam", name))

    def delete_param(self, name: str) -> None:
        if self.has_param(name):
            self._call("deleteParam", name)

    def publishers(self) -> dict[str, set[str]]:
        """Topic → the nodes that publish it."""
        publishers, _, _ = self._call("getSystemState")
        return {topic: set(nodes) for topic, nodes in publishers}

    def subscribers(self) -> dict[str, set[str]]:
        """Topic → the nodes that subscribe to it."""
        _, subscribers, _ = self._call("getSystemState")
        return {topic: set(nodes) for topic, nodes in subscribers}

    def lookup_node(self, name: str) -> str | None:
        """The XML-RPC URI of node ``name``; None if the master does not know it."""
        try:
            answer: Any = self._proxy.lookupNode(CALLER, name)
        except (OSError, xmlrpc.client.Error) as e:
            raise RosGraphError(f"no ROS master answers at {self.uri} ({e})") from e
        code, _, uri = answer
        return str(uri) if code == 1 else None


@dataclass
class StartedMaster:
    """A roscore exsce started (``--start-master``) and stops, with what it started."""

    uri: str
    process: subprocess.Popen[bytes]
    log: Path
    below: dict[int, str] = field(default_factory=dict)
    """What roscore started (rosmaster, rosout: roslaunch gives each a session of its own, out of
    reach of a signal to roscore's group), by pid, with their start times."""

    def __enter__(self) -> StartedMaster:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.stop()

    def stop(self) -> None:
        """Ctrl-C to roscore, as in a terminal; then SIGKILL what is left: its group, and rosmaster
        and rosout (roscore killed after 15 s of shutting down, on a loaded machine, left them running)."""
        if self.process.poll() is None:
            self.below.update(descendants(self.process.pid))
            _signal_group(self.process, signal.SIGINT)
            try:
                self.process.wait(15.0)
            except subprocess.TimeoutExpired:
                pass
        _signal_group(self.process, signal.SIGKILL)
        for pid, started in self.below.items():
            if process_stat(pid)[1] == started:  # the same process, not a later one given its pid
                try:
                    os.kill(pid, signal.SIGKILL)
                except (ProcessLookupError, PermissionError):
                    pass
        if self.process.poll() is None:
            self.process.wait(5.0)


def start_master(ros_home: Path, port: int | None = None, timeout: float = 30.0) -> StartedMaster:
    """Start ``roscore`` on 127.0.0.1 at ``port`` (a free one if None), its log in ``ros_home``."""
    roscore = shutil.which("roscore")
    if roscore is None:
        raise RosGraphError(f"roscore is not on PATH; {INSTALL_HINT}")
    port = free_port() if port is None else port
    uri = f"http://127.0.0.1:{port}"
    ros_home.mkdir(parents=True, exist_ok=True)
    log = ros_home / "roscore.log"
    with log.open("wb") as out:
        process = subprocess.Popen(
            [roscore, "-p", str(port)],
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            env=node_environment(uri, ros_home),
            start_new_session=True,
        )
    started = StartedMaster(uri, process, log)
    try:
        deadline = time.monotonic() + timeout
        master = Master(uri)
        # up: the master answers with its run id, and rosout, which roslaunch starts after it, is
        # registered (so both are among the processes noted below)
        while not (master.reachable() and master.has_param("/run_id") and master.lookup_node("/rosout")):
            if process.poll() is not None or time.monotonic() > deadline:
                tail = "\n".join(log.read_text(errors="replace").splitlines()[-10:])
                raise RosGraphError(f"roscore did not start on port {port}:\n{tail}")
            time.sleep(0.1)
        started.below.update(descendants(process.pid))
    except BaseException:
        started.stop()
        raise
    return started


def free_port() -> int:
    """A TCP port of 127.0.0.1 that nothing listens on now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def _signal_group(process: subprocess.Popen[bytes], sig: int) -> None:
    try:
        os.killpg(process.pid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def descendants(pid: int) -> dict[int, str]:
    """The processes below ``pid`` now, by pid, with their start times, as /proc shows them
    (nothing where there is no /proc)."""
    children: dict[int, list[int]] = {}
    started: dict[int, str] = {}
    try:
        entries = [int(e.name) for e in Path("/proc").iterdir() if e.name.isdigit()]
    except OSError:
        return {}
    for entry in entries:
        parent, started[entry] = process_stat(entry)
        children.setdefault(parent, []).append(entry)
    found: dict[int, str] = {}
    todo = [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found[child] = started[child]
            todo.append(child)
    return found


def process_stat(pid: int) -> tuple[int, str]:
    """(parent pid, start time) of process ``pid``; (-1, "") if there is none."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return -1, ""
    fields = stat[stat.rindex(")") + 2 :].split()  # after "pid (command) ": state, ppid, ...
    return int(fields[1]), fields[19]
