"""The dispatcher on a live ROS 2 graph: one rclpy node per run, its Nav2 clients and its PROV.

The node (``exsce_dispatcher``) holds the scenario as its parameters (``scenario``: the method's
scenario file as YAML text, ``scenario_id``, ``run_id``; ``use_sim_time``), a
``NavigateToPose`` action client per robot (:class:`~.live.Ros2Navigator`) and a publisher of the
run-time PROV on :data:`~exsce_dsl.runs.PROV_TOPIC` (``std_msgs/msg/String``, reliable and
transient local: ROS 2's latching, so that a recorder that joins later still gets it).  It lives
in a context of its own, shut down when the run ends; rclpy's signal handlers are not installed
(exscec's own :class:`~exsce_dsl.execute.ros1.session.Interruption` handles Ctrl-C and SIGTERM).
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import TracebackType
from typing import Any

import yaml

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.ros2.live import WAIT_SLICE, Ros2Clock, Ros2Modules, Ros2Navigator, require_rclpy
from exsce_dsl.lang import scenario_to_yaml
from exsce_dsl.model import Scenario
from exsce_dsl.runs import PROV_TOPIC

NODE_NAME = "exsce_dispatcher"
CLOCK_TOPIC = "/clock"
DISCOVERY = 2.0
"""Wall seconds the node looks for a ``/clock`` publisher before deciding on wall time."""


class Ros2DispatcherNode:
    """The run's dispatcher node, its action clients (``actions``: robot → action name) up."""

    def __init__(
        self, scenario: Scenario, run_id: str, actions: Mapping[str, str], use_sim_time: bool | None = None
    ) -> None:
        self.modules: Ros2Modules = require_rclpy()
        self.scenario, self.run_id, self.actions = scenario, run_id, dict(actions)
        self._wanted_sim_time = use_sim_time
        self.context: Any = None

    def __enter__(self) -> Ros2DispatcherNode:
        modules = self.modules
        rclpy = modules.rclpy
        self.context = modules.context.Context()
        signals = importlib.import_module("rclpy.signals")
        rclpy.init(context=self.context, signal_handler_options=signals.SignalHandlerOptions.NO)
        try:
            self._start()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()

    def _start(self) -> None:
        modules, Parameter = self.modules, self.modules.parameter.Parameter
        self.parameters = {
            "scenario": yaml.safe_dump(scenario_to_yaml(self.scenario), sort_keys=False, allow_unicode=True),
            "scenario_id": self.scenario.id,
            "run_id": self.run_id,
        }
        self.node = modules.rclpy.create_node(NODE_NAME, context=self.context)
        for name, value in self.parameters.items():
            self.node.declare_parameter(name, value)
        self.executor = modules.executors.SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.use_sim_time = self._decide_sim_time()
        self.node.set_parameters([Parameter("use_sim_time", value=self.use_sim_time)])
        qos = importlib.import_module("rclpy.qos")
        latched = qos.QoSProfile(
            depth=1,
            reliability=qos.ReliabilityPolicy.RELIABLE,
            durability=qos.DurabilityPolicy.TRANSIENT_LOCAL,
        )
        string = importlib.import_module("std_msgs.msg").String
        self.prov_publisher = self.node.create_publisher(string, PROV_TOPIC, latched)
        self.clients = {
            robot: modules.action.ActionClient(self.node, modules.nav2.NavigateToPose, name)
            for robot, name in sorted(self.actions.items())
        }
        self.clock = Ros2Clock(self.node)

    def _decide_sim_time(self) -> bool:
        """As asked, else simulated time when something publishes ``/clock`` (a simulator)."""
        if self._wanted_sim_time is not None:
            return self._wanted_sim_time
        deadline = time.monotonic() + DISCOVERY
        while time.monotonic() < deadline:
            if self.node.count_publishers(CLOCK_TOPIC) > 0:
                return True
            self.executor.spin_once(timeout_sec=WAIT_SLICE)
        return False

    def wait_for_servers(self, timeout: float) -> None:
        """Until every robot's action server answers; else :class:`RosGraphError` naming the first
        that did not within ``timeout`` wall seconds."""
        deadline = time.monotonic() + timeout
        for robot, client in self.clients.items():
            if not client.wait_for_server(timeout_sec=max(deadline - time.monotonic(), 0.0)):
                raise RosGraphError(
                    f"no NavigateToPose action server at {self.actions[robot]} (robot '{robot}') "
                    f"after {timeout:g} s: is Nav2 running in that namespace?"
                )

    def wait_for_clock(self, timeout: float) -> None:
        """Spin until the node's clock has a time (under ``use_sim_time``: the first ``/clock``)."""
        deadline = time.monotonic() + timeout
        while self.clock.now() <= 0:
            if time.monotonic() > deadline:
                raise RosGraphError(f"no time on /clock after {timeout:g} s: is the simulator running?")
            self.executor.spin_once(timeout_sec=WAIT_SLICE)

    def published(self, topics: Sequence[str]) -> list[str]:
        """Those of ``topics`` that the node sees a publisher of."""
        return [t for t in topics if self.node.count_publishers(t) > 0]

    def navigator(self) -> Ros2Navigator:
        return Ros2Navigator(self.modules, self.executor, self.clients, self.clock)

    def publish(self, text: str) -> int:
        """Publish ``text`` on the PROV topic (latched); how many subscribers it has."""
        self.prov_publisher.publish(importlib.import_module("std_msgs.msg").String(data=text))
        return int(self.prov_publisher.get_subscription_count())

    def spin_for(self, seconds: float) -> None:
        """Serve the node for ``seconds`` wall seconds (a message on its way, goals' answers)."""
        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0:
            self.executor.spin_once(timeout_sec=min(left, WAIT_SLICE))

    def dump_parameters(self, path: Path) -> None:
        """The node's parameters as ``ros2 param dump`` writes them (``/node: ros__parameters:``);
        the file appears whole or not at all."""
        names = sorted([*self.parameters, "use_sim_time"])
        values = {name: self.node.get_parameter(name).value for name in names}
        text = yaml.safe_dump(
            {f"/{NODE_NAME}": {"ros__parameters": values}}, sort_keys=True, allow_unicode=True
        )
        partial = path.with_name(f".{path.name}.partial")
        partial.write_text(text, encoding="utf-8")
        partial.replace(path)

    def close(self) -> None:
        if self.context is None:
            return
        if hasattr(self, "executor"):
            self.executor.shutdown()
        if hasattr(self, "node"):
            self.node.destroy_node()
        self.context.try_shutdown()
        self.context = None
