"""Declaration-only plug-ins of the actions in ``lib_osc``: the arguments of ``execute`` are those
the ``.osc`` declarations name (scenario_execution checks them against each invocation when it
builds the tree), and an action that is ticked fails: running needs ROS's real plug-ins."""

from typing import Any

import py_trees
from scenario_execution.actions.base_action import BaseAction


class _Declared(BaseAction):  # type: ignore[misc]
    """An action that only declares its arguments."""

    def update(self) -> py_trees.common.Status:
        self.feedback_message = f"{self.name}: only declared here; run it with scenario_execution_ros"
        return py_trees.common.Status.FAILURE


class BagRecord(_Declared):
    def execute(
        self, topics: list[str], timestamp_suffix: bool, hidden_topics: bool, storage: str, use_sim_time: bool
    ) -> None:
        pass


class _ActorAction(_Declared):
    """An action of an actor (``robot.init_nav2(...)``): scenario_execution passes the actor's
    resolved fields to ``__init__`` and ``execute`` alike, as to the real plug-ins."""

    def __init__(self, associated_actor: Any) -> None:
        super().__init__()
        self.namespace = associated_actor["namespace"] or associated_actor["name"]


class InitNav2(_ActorAction):
    def execute(
        self,
        associated_actor: Any,
        initial_pose: Any,
        base_frame_id: str,
        use_initial_pose: bool,
        namespace_override: str,
        wait_for_initial_pose: bool,
        wait_for_amcl: bool,
    ) -> None:
        pass


class NavToPose(_ActorAction):
    def execute(
        self,
        associated_actor: Any,
        goal_pose: Any,
        namespace_override: str,
        action_topic: str,
        success_on_acceptance: bool,
    ) -> None:
        pass


class NavThroughPoses(_ActorAction):
    def execute(
        self,
        associated_actor: Any,
        goal_poses: list[Any],
        namespace_override: str,
        action_topic: str,
        success_on_acceptance: bool,
    ) -> None:
        pass


class FollowWaypoints(_ActorAction):
    def execute(
        self,
        associated_actor: Any,
        goal_poses: list[Any],
        loop_count: int,
        namespace_override: str,
        action_topic: str,
        success_on_acceptance: bool,
    ) -> None:
        pass
