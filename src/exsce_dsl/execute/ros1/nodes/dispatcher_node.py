"""exsce's mission dispatcher on a live ROS 1 graph: one actionlib client per robot.

Run by rospy's Python (see ``exsce_dsl.execute.ros1.channel``), never by exsce's: the standard
library, rospy, actionlib, the message packages and ``node_protocol`` only, in Python 3.8.

Arguments: ``--actions JSON`` (robot → its move_base action, ``{"tiago1": "/tiago1/move_base"}``),
``--server-timeout S`` (wall seconds to wait for every action server), ``--prov-topic NAME``.
Once every server answers it says ``ready``; else it fails naming each action that did not.

Commands (one JSON object a line):
- ``{"command": "send", "goal": N, "robot": R, "pose": [x, y, z, qx, qy, qz, qw]}``: a
  ``MoveBaseGoal`` in the ``map`` frame to R's server;
- ``{"command": "cancel", "goal": N}``: cancel it (its end is not reported);
- ``{"command": "time", "id": K}``: answered by ``{"event": "time", "id": K, "time": T}``;
- ``{"command": "wait", "id": K, "until": T}``: ``{"event": "deadline", "id": K, "time": T'}``
  once the ROS time reaches T (simulated time under ``/use_sim_time`` too);
- ``{"command": "publish", "id": K, "text": S}``: S on the PROV topic (latched), then
  ``{"event": "published", "id": K, "subscribers": N}``.
Events of their own: ``{"event": "finished", "goal": N, "outcome": O, "time": T}`` with O one of
``succeeded``, ``aborted``, ``rejected``, ``cancelled`` (preempted by another client).
The end of input cancels the goals still active, then ends the node.
"""

import argparse
import json
import threading
import time

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
from node_protocol import emit, fail, serve_commands
from std_msgs.msg import String

OUTCOMES = {
    GoalStatus.SUCCEEDED: "succeeded",
    GoalStatus.ABORTED: "aborted",
    GoalStatus.REJECTED: "rejected",
    GoalStatus.PREEMPTED: "cancelled",
    GoalStatus.RECALLED: "cancelled",
    GoalStatus.LOST: "aborted",
}
FRAME = "map"
TICK = 0.005
"""Wall seconds between two looks at the ROS time for the deadlines asked for."""


def ros_now():
    return rospy.get_rostime().to_sec()


def move_base_goal(pose):
    x, y, z, qx, qy, qz, qw = (float(v) for v in pose)
    goal = MoveBaseGoal()
    goal.target_pose.header.frame_id = FRAME
    goal.target_pose.header.stamp = rospy.Time.now()
    goal.target_pose.pose.position.x = x
    goal.target_pose.pose.position.y = y
    goal.target_pose.pose.position.z = z
    q = goal.target_pose.pose.orientation
    q.x, q.y, q.z, q.w = qx, qy, qz, qw
    return goal


class Dispatcher:
    def __init__(self, actions, prov_topic):
        self.clients = {r: actionlib.ActionClient(name, MoveBaseAction) for r, name in actions.items()}
        self.actions = actions
        self.prov = rospy.Publisher(prov_topic, String, queue_size=1, latch=True)
        self.lock = threading.RLock()  # held while sending: a fast end waits for the handle
        self.goals = {}  # number → goal handle, while active
        self.cancelled = set()
        self.waits = {}  # id → ROS time

    def wait_for_servers(self, timeout):
        up = {}

        def wait(robot):
            up[robot] = self.clients[robot].wait_for_server()

        threads = [threading.Thread(target=wait, args=(r,), daemon=True) for r in self.clients]
        for thread in threads:
            thread.start()
        deadline = time.monotonic() + timeout
        for thread in threads:
            thread.join(max(0.0, deadline - time.monotonic()))
        missing = sorted(self.actions[r] + " (robot " + r + ")" for r in self.clients if not up.get(r))
        if missing:
            fail(
                "no move_base action server answered within %g s at %s" % (timeout, ", ".join(missing))
                + ": start the robots' navigation stacks (or exsce's stand-in) first"
            )

    def handle(self, command):
        kind = command.get("command")
        if kind == "send":
            self.send(int(command["goal"]), command["robot"], command["pose"])
        elif kind == "cancel":
            self.cancel(int(command["goal"]))
        elif kind == "time":
            emit("time", id=command.get("id"), time=ros_now())
        elif kind == "wait":
            with self.lock:
                self.waits[command.get("id")] = float(command["until"])
        elif kind == "publish":
            self.prov.publish(String(data=command["text"]))
            emit("published", id=command.get("id"), subscribers=self.prov.get_num_connections())
        else:
            emit("warning", message="unknown command %r" % kind)

    def send(self, number, robot, pose):
        if robot not in self.clients:
            emit("warning", message="no action client for robot %r" % robot)
            return

        def transition(handle):
            self.transition(number, handle)

        with self.lock:
            self.goals[number] = self.clients[robot].send_goal(move_base_goal(pose), transition_cb=transition)

    def transition(self, number, handle):
        if handle.get_comm_state() != actionlib.CommState.DONE:
            return
        with self.lock:
            if self.goals.pop(number, None) is None or number in self.cancelled:
                return
        outcome = OUTCOMES.get(handle.get_goal_status(), "aborted")
        emit("finished", goal=number, outcome=outcome, time=ros_now())

    def cancel(self, number):
        with self.lock:
            self.cancelled.add(number)
            handle = self.goals.pop(number, None)
        if handle is not None:
            handle.cancel()

    def cancel_all(self):
        with self.lock:
            numbers = list(self.goals)
        for number in numbers:
            self.cancel(number)

    def watch_deadlines(self, stop):
        while not stop.is_set() and not rospy.is_shutdown():
            now = ros_now()
            with self.lock:
                reached = [k for k, until in self.waits.items() if now >= until]
                for k in reached:
                    del self.waits[k]
            for k in reached:
                emit("deadline", id=k, time=now)
            time.sleep(TICK)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--actions", required=True, help="JSON: robot → action name")
    parser.add_argument("--server-timeout", type=float, default=10.0)
    parser.add_argument("--prov-topic", default="/exsce/prov")
    args = parser.parse_args(rospy.myargv()[1:])
    try:
        actions = json.loads(args.actions)
    except ValueError as e:
        fail("--actions is not JSON: %s" % e)
    rospy.init_node("exsce_dispatcher", anonymous=True, disable_signals=True)
    dispatcher = Dispatcher(actions, args.prov_topic)
    dispatcher.wait_for_servers(args.server_timeout)
    stop = threading.Event()
    serve_commands(dispatcher.handle, stop.set)
    watcher = threading.Thread(target=dispatcher.watch_deadlines, args=(stop,), daemon=True)
    watcher.start()
    emit("ready", time=ros_now())
    stop.wait()
    dispatcher.cancel_all()
    time.sleep(0.2)  # the cancels on their way out
    rospy.signal_shutdown("input closed")


if __name__ == "__main__":
    main()
