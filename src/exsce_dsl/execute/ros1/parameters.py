"""The scenario on the ROS parameter server, and the server's parameters saved with a run.

The method loads its scenario file on the parameter server before a run (its report, §3.2 and
Figure 7) and its recorder saves the whole server with the run, as ``rosparam dump`` does
(``<run>.rosparams``, which holds the ``scenario:`` tree: the published run
``2023-06-26T21-47-04_scenario_c_run-30af607a``'s).  :func:`load_scenario` puts there the same
structure ``exscec export --to yaml`` writes to the scenario file (:func:`scenario_to_yaml`),
under :data:`SCENARIO_NAMESPACE`; :func:`dump_parameters` writes the server's tree as
``rosparam dump`` writes it (YAML, keys sorted, block style), with a safe dumper.  Both speak to
the master over XML-RPC: no rospy here.
"""

from __future__ import annotations

import datetime
import os
import xmlrpc.client
from pathlib import Path
from typing import Any

import yaml

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.ros1.graph import Master
from exsce_dsl.lang import scenario_to_yaml
from exsce_dsl.model import Scenario

SCENARIO_NAMESPACE = "/scenario"
"""Where the method's runs keep the scenario on the parameter server."""
XMLRPC_INT = (-(2**31), 2**31 - 1)
"""The integers XML-RPC carries (``<i4>``); the master refuses others."""


def load_scenario(master: Master, scenario: Scenario) -> dict[str, Any]:
    """Put ``scenario`` on the parameter server under :data:`SCENARIO_NAMESPACE`, as the method's
    scenario file (replacing what was there); returns what was put."""
    tree = scenario_to_yaml(scenario)
    _check_carriable(tree, SCENARIO_NAMESPACE)
    master.delete_param(SCENARIO_NAMESPACE)
    master.set_param(SCENARIO_NAMESPACE, tree)
    return tree


def dump_parameters(master: Master, path: Path) -> dict[str, Any]:
    """Write the parameter server's whole tree to ``path`` as ``rosparam dump`` does; returns the
    tree.  The file appears whole or not at all (written beside it, then renamed)."""
    tree = _plain(master.get_param("/"))
    if not isinstance(tree, dict):
        raise RosGraphError(f"the parameter server's root is not a namespace ({type(tree).__name__})")
    text = yaml.safe_dump(tree, default_flow_style=False, sort_keys=True, allow_unicode=True)
    partial = path.with_name(f".{path.name}.partial")
    partial.write_text(text, encoding="utf-8")
    os.replace(partial, path)
    return tree


def _plain(value: Any) -> Any:
    """A value read over XML-RPC with its wrappers unwrapped (``Binary`` → bytes, ``DateTime``
    → datetime), which a safe dumper writes as ``!!binary`` and timestamps."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, xmlrpc.client.Binary):
        return bytes(value.data)
    if isinstance(value, xmlrpc.client.DateTime):
        return datetime.datetime.strptime(value.value, "%Y%m%dT%H:%M:%S")
    return value


def _check_carriable(value: Any, where: str) -> None:
    """Raise :class:`RosGraphError` for a value the parameter server cannot hold (XML-RPC has no
    null, and 32-bit integers only)."""
    if isinstance(value, dict):
        for key, item in value.items():
            _check_carriable(item, f"{where}/{key}")
    elif isinstance(value, list):
        for index, item in enumerate(value):
            _check_carriable(item, f"{where}[{index}]")
    elif value is None:
        raise RosGraphError(f"{where} has no value, which the ROS parameter server cannot hold")
    elif isinstance(value, int) and not XMLRPC_INT[0] <= value <= XMLRPC_INT[1]:
        raise RosGraphError(f"{where} = {value} is beyond the 32-bit integers the ROS parameter server holds")
