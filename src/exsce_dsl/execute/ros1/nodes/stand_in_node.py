"""exsce's stand-in robot on a live ROS 1 graph: move_base action servers, odometry, TF, AMCL's
pose, scans and velocity commands, on simulated time that this node publishes on ``/clock``.

Runs in rospy's Python (standard library and ROS 1 packages only, Python 3.8 spellings).  It
plans nothing: when a goal arrives it says so (``goal`` event) and the venv side answers with the
whole leg (``leg`` command): per sample of a 50 Hz clock the odometry, the localiser's estimate,
the correction ``map -> odom``, the measured and commanded velocities, and a scan every fifth
sample, as base64 arrays.  The node plays the leg from the next sample on, then ends the goal
(succeeded or aborted).  A cancel, or a new goal while one is active, stops the robot where it is
(``stopped`` event with the leg's sample).  Between goals the robots stand still and every topic
keeps publishing.  While a goal awaits its leg, simulated time stands still (as a simulator's does
while its physics steps), so that how long the venv takes to plan does not show in the run.

Commands: ``setup`` (speed-up, robots, laser), ``leg``, ``stats``.  Events: ``ready``, ``goal``,
``stopped``, ``finished``, ``stats``.
"""

import array
import base64
import math
import queue
import threading
import time
from typing import Any, Dict, List, Optional

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TransformStamped, Twist
from move_base_msgs.msg import MoveBaseAction, MoveBaseFeedback, MoveBaseResult
from nav_msgs.msg import Odometry
from node_protocol import emit, fail, serve_commands
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

DT_NS = 20_000_000  # the 50 Hz sample clock
FIELDS = 13  # per sample: odom x y yaw, estimate x y yaw, correction x y yaw, v w, command v w
STATIC_EVERY = 50  # samples: 1 Hz
SCAN_EVERY, CORRECTION_EVERY, AMCL_EVERY, FEEDBACK_EVERY = 5, 5, 25, 10  # samples: 10, 10, 2, 5 Hz
CMD_VEL_PERIOD_NS = 50_000_000  # 20 Hz
TICK = 0.01  # wall seconds between publishing rounds
MAX_LAG_NS = 200_000_000  # simulated time runs no further ahead of what was published: a round after
# a stall of the node (whose recorder likely stalled with it) moves the clock 0.2 s at most, not
# speed_up times the stall (0.5 s let a 20 Hz topic stamped on receipt show a gap of 0.56 s)
QUEUE = 2000
LEG_WAIT = 10.0  # wall seconds simulated time waits for a leg at most
LOCALISATION_NOISE, LOCALISATION_YAW_NOISE = 0.02, 0.01
FOOTPRINT_HEIGHT, LASER_HEIGHT = 0.1, 0.2


def topic(ns: str, name: str) -> str:
    return "/" + "/".join(p for p in (ns.strip("/"), name) if p)


def stamp_of(ns: int) -> rospy.Time:
    return rospy.Time(ns // 1_000_000_000, ns % 1_000_000_000)


def set_yaw(q: Any, yaw: float) -> None:
    q.x, q.y, q.z, q.w = 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)


class StandInLeg:
    """A leg the venv computed: FIELDS values per sample, a scan every SCAN_EVERY samples."""

    def __init__(self, command: Dict[str, Any]) -> None:
        self.goal: Optional[str] = command.get("goal")
        self.outcome: Optional[str] = command.get("outcome")
        self.samples = int(command["samples"])
        self.values = array.array("d", base64.b64decode(command["poses"]))
        self.beams = int(command["beams"])
        self.scans = array.array("f", base64.b64decode(command["scans"]))
        self.start = 0  # the global sample of its first one
        if len(self.values) != self.samples * FIELDS or self.samples < 1:
            raise ValueError("a leg of %d samples with %d values" % (self.samples, len(self.values)))

    def sample(self, k: int) -> List[float]:
        return list(self.values[k * FIELDS : (k + 1) * FIELDS])

    def scan(self, k: int) -> Any:
        count = len(self.scans) // self.beams
        j = min(k // SCAN_EVERY, count - 1)
        return self.scans[j * self.beams : (j + 1) * self.beams]


class StandInRobot:
    def __init__(self, name: str, ns: str) -> None:
        self.name, self.ns = name, ns
        self.held = [0.0] * FIELDS  # where it stands between goals
        self.held_scan: Any = None
        self.leg: Optional[StandInLeg] = None
        self.active: Any = None  # the goal handle being driven (or awaiting its leg)
        self.active_id: Optional[str] = None
        self.awaiting: Optional[float] = None  # wall time since when its goal awaits its leg
        self.server: Any = None
        self.pubs: Dict[str, Any] = {}


class StandInNode:
    def __init__(self) -> None:
        self.lock = threading.RLock()
        self.robots: Dict[str, StandInRobot] = {}
        self.setup_done = threading.Event()
        self.running = True
        self.speed_up = 5.0  # until the setup command says (DEFAULT_SPEED_UP)
        self.laser: Dict[str, float] = {}
        self.start_ns = 0
        self.published = 0  # the last global sample published
        self.counts: Dict[str, int] = {}
        self.wall_start = 0.0
        self.requests = queue.Queue()  # (kind, robot, goal handle) from actionlib

    # -- commands (from the venv) ------------------------------------------------------------

    def handle(self, command: Dict[str, Any]) -> None:
        kind = command.get("command")
        if kind == "setup":
            self.speed_up = float(command["speed_up"])
            self.laser = command["laser"]
            for r in command["robots"]:
                self.robots[r["name"]] = StandInRobot(r["name"], r["ns"])
        elif kind == "leg":
            self.take_leg(StandInLeg(command), command["robot"])
        elif kind == "stats":
            with self.lock:
                now_ns = self.time_of(self.published)
                wall = time.monotonic() - self.wall_start
                emit(
                    "stats",
                    sim_time=(now_ns - self.start_ns) / 1e9,
                    wall_time=wall,
                    published=dict(self.counts),
                )
        else:
            emit("warning", message="unknown command %r" % kind)

    def take_leg(self, leg: StandInLeg, name: str) -> None:
        with self.lock:
            robot = self.robots[name]
            if leg.goal is None:  # where the robot stands at the start
                robot.held = leg.sample(leg.samples - 1)
                robot.held_scan = leg.scan(leg.samples - 1)
                if all(r.held_scan is not None for r in self.robots.values()):
                    self.setup_done.set()
                return
            if robot.active_id != leg.goal or robot.leg is not None:
                return  # cancelled meanwhile
            leg.start = self.published + 1
            robot.leg, robot.awaiting = leg, None

    # -- actionlib ------------------------------------------------------------------------------
    # actionlib calls back holding its server's lock, which its goal handles take too: the callbacks
    # only queue what came, and the clock thread handles it (holding our lock, then actionlib's)

    def handle_requests(self) -> None:
        while True:
            try:
                kind, robot, handle = self.requests.get_nowait()
            except queue.Empty:
                return
            if kind == "goal":
                self.on_goal(robot, handle)
            else:
                self.on_cancel(robot, handle)

    def on_goal(self, robot: StandInRobot, handle: Any) -> None:
        with self.lock:
            if robot.active is not None:  # move_base: a new goal preempts the active one
                self.stop(robot, "preempted by a new goal")
            handle.set_accepted()
            target = handle.get_goal().target_pose.pose
            q = target.orientation
            yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
            goal_id = handle.get_goal_id().id
            robot.active, robot.active_id, robot.awaiting = handle, goal_id, time.monotonic()
            emit(
                "goal",
                robot=robot.name,
                goal=goal_id,
                x=target.position.x,
                y=target.position.y,
                yaw=yaw,
                time=self.time_of(self.published) / 1e9,
            )

    def on_cancel(self, robot: StandInRobot, handle: Any) -> None:
        with self.lock:
            if robot.active is not None and robot.active_id == handle.get_goal_id().id:
                self.stop(robot, "cancelled")

    def stop(self, robot: StandInRobot, why: str) -> None:
        """Stop ``robot`` where it is now, its goal canceled (preempted)."""
        leg, k = robot.leg, -1
        if leg is not None:
            k = min(max(self.published - leg.start, -1), leg.samples - 1)
            if k >= 0:
                robot.held = leg.sample(k)
                robot.held[9:] = [0.0, 0.0, 0.0, 0.0]
                robot.held_scan = leg.scan(k)
        robot.active.set_canceled(MoveBaseResult(), why)
        emit(
            "stopped",
            robot=robot.name,
            goal=robot.active_id,
            sample=k,
            time=self.time_of(self.published) / 1e9,
        )
        robot.leg, robot.active, robot.active_id, robot.awaiting = None, None, None, None

    # -- the graph -----------------------------------------------------------------------------

    def time_of(self, sample: int) -> int:
        return self.start_ns + sample * DT_NS

    def start(self) -> None:
        rospy.init_node("exsce_stand_in", disable_signals=True)
        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=QUEUE)
        for robot in self.robots.values():
            ns = robot.ns
            robot.pubs = {
                "odom": rospy.Publisher(topic(ns, "odom"), Odometry, queue_size=QUEUE),
                "tf": rospy.Publisher(topic(ns, "tf"), TFMessage, queue_size=QUEUE),
                "tf_static": rospy.Publisher(topic(ns, "tf_static"), TFMessage, queue_size=10, latch=True),
                "amcl_pose": rospy.Publisher(
                    topic(ns, "amcl_pose"), PoseWithCovarianceStamped, queue_size=QUEUE
                ),
                "cmd_vel": rospy.Publisher(topic(ns, "cmd_vel"), Twist, queue_size=QUEUE),
                "scan": rospy.Publisher(topic(ns, "scan"), LaserScan, queue_size=QUEUE),
            }
            robot.server = actionlib.ActionServer(
                topic(ns, "move_base"),
                MoveBaseAction,
                lambda h, r=robot: self.requests.put(("goal", r, h)),
                lambda h, r=robot: self.requests.put(("cancel", r, h)),
                auto_start=False,
            )
        self.start_ns = int(time.time()) * 1_000_000_000
        self.wall_start = time.monotonic()
        self.publish_clock(self.start_ns)
        threading.Thread(target=self.run, name="clock", daemon=True).start()
        for robot in self.robots.values():
            self.publish_static(robot, self.start_ns)
            robot.server.start()

    def publish_clock(self, ns: int) -> None:
        self.clock_pub.publish(Clock(clock=stamp_of(ns)))
        self.counts["/clock"] = self.counts.get("/clock", 0) + 1

    def publish(self, robot: StandInRobot, name: str, message: Any) -> None:
        robot.pubs[name].publish(message)
        key = topic(robot.ns, name)
        self.counts[key] = self.counts.get(key, 0) + 1

    def run(self) -> None:
        """Publish every sample up to simulated now, each after its ``/clock``; TICK wall seconds a round."""
        base_wall, base_sim = time.monotonic(), self.start_ns
        try:
            while self.running and not rospy.is_shutdown():
                self.handle_requests()
                now = time.monotonic()
                published_ns = self.time_of(self.published)
                if self.planning(now):  # simulated time stands still while a leg is planned
                    base_wall, base_sim = now, published_ns
                    time.sleep(TICK)
                    continue
                target = base_sim + int(self.speed_up * (now - base_wall) * 1e9)
                if target - published_ns > MAX_LAG_NS:  # behind: simulated time waits for us
                    target = published_ns + MAX_LAG_NS
                    base_wall, base_sim = now, target
                last = (target - self.start_ns) // DT_NS
                with self.lock:
                    # /clock steps with each sample, so a round that catches up after a stall does
                    # not reach a recorder as one burst stamped at one time (a gap before it)
                    while self.published < last:
                        self.publish_clock(self.time_of(self.published + 1))
                        self.publish_sample(self.published + 1)
                        self.published += 1
                if target > self.time_of(self.published):
                    self.publish_clock(target)
                time.sleep(TICK)
        except Exception as e:  # the node is useless without its clock: say why and end
            self.running = False
            emit("error", message="the stand-in's clock stopped: %s: %s" % (type(e).__name__, e))

    def planning(self, now: float) -> bool:
        """Whether a robot's goal awaits its leg; one that waited LEG_WAIT wall seconds is aborted."""
        with self.lock:
            for robot in self.robots.values():
                if robot.awaiting is not None and now - robot.awaiting >= LEG_WAIT:
                    handle, goal_id = robot.active, robot.active_id
                    robot.active, robot.active_id, robot.awaiting = None, None, None
                    handle.set_aborted(MoveBaseResult(), "No plan came for the goal.")
                    when = self.published_time()
                    emit("finished", robot=robot.name, goal=goal_id, outcome="aborted", time=when)
            return any(r.awaiting is not None for r in self.robots.values())

    def published_time(self) -> float:
        return self.time_of(self.published) / 1e9

    def publish_sample(self, n: int) -> None:
        t = self.time_of(n)
        for robot in self.robots.values():
            values, scan, leg = robot.held, robot.held_scan, robot.leg
            k = -1
            if leg is not None and n >= leg.start:
                k = n - leg.start
                values, scan = leg.sample(k), leg.scan(k)
            self.publish_state(robot, n, t, values, scan, k)
            if leg is not None and k == leg.samples - 1:
                self.finish(robot, leg, values, scan, t)

    def finish(self, robot: StandInRobot, leg: StandInLeg, values: List[float], scan: Any, t: int) -> None:
        robot.held = values[:9] + [0.0, 0.0, 0.0, 0.0]
        robot.held_scan = scan
        handle, goal_id = robot.active, robot.active_id
        robot.leg, robot.active, robot.active_id = None, None, None
        if leg.outcome == "succeeded":
            handle.set_succeeded(MoveBaseResult(), "Goal reached.")
        else:
            handle.set_aborted(
                MoveBaseResult(), "Failed to find a valid control. Even after executing recovery behaviors."
            )
        emit("finished", robot=robot.name, goal=goal_id, outcome=leg.outcome, time=t / 1e9)

    def publish_state(self, robot: StandInRobot, n: int, t: int, v: List[float], scan: Any, k: int) -> None:
        stamp = stamp_of(t)
        if n % STATIC_EVERY == 0:  # latched, and again: a recorder started later gets it on its clock
            self.publish_static(robot, t)
        odom = Odometry()
        odom.header.stamp, odom.header.frame_id, odom.child_frame_id = stamp, "odom", "base_link"
        odom.pose.pose.position.x, odom.pose.pose.position.y = v[0], v[1]
        set_yaw(odom.pose.pose.orientation, v[2])
        odom.pose.covariance = ODOM_COVARIANCE
        odom.twist.twist.linear.x, odom.twist.twist.angular.z = v[9], v[10]
        odom.twist.covariance = ODOM_COVARIANCE
        self.publish(robot, "odom", odom)
        transforms = [transform(stamp, "odom", "base_link", v[0], v[1], v[2])]
        if n % CORRECTION_EVERY == 0:
            transforms.append(transform(stamp, "map", "odom", v[6], v[7], v[8]))
        self.publish(robot, "tf", TFMessage(transforms=transforms))
        if n % AMCL_EVERY == 0:
            amcl = PoseWithCovarianceStamped()
            amcl.header.stamp, amcl.header.frame_id = stamp, "map"
            amcl.pose.pose.position.x, amcl.pose.pose.position.y = v[3], v[4]
            set_yaw(amcl.pose.pose.orientation, v[5])
            amcl.pose.covariance = AMCL_COVARIANCE
            self.publish(robot, "amcl_pose", amcl)
        # 20 Hz: one per multiple of the period in [t, t + DT_NS), ceilings both (floors lost half)
        for _ in range(-(-t // CMD_VEL_PERIOD_NS), -(-(t + DT_NS) // CMD_VEL_PERIOD_NS)):
            command = Twist()
            command.linear.x, command.angular.z = v[11], v[12]
            self.publish(robot, "cmd_vel", command)
        if n % SCAN_EVERY == 0:  # a leg's latest scan (computed every SCAN_EVERY of its samples)
            laser = self.laser
            message = LaserScan(
                angle_min=laser["angle_min"],
                angle_max=laser["angle_max"],
                angle_increment=laser["angle_increment"],
                time_increment=0.0,
                scan_time=SCAN_EVERY * DT_NS / 1e9,
                range_min=laser["range_min"],
                range_max=laser["range_max"],
                ranges=scan,
            )
            message.header.stamp, message.header.frame_id = stamp, "base_laser_link"
            self.publish(robot, "scan", message)
        if robot.active is not None and k >= 0 and k % FEEDBACK_EVERY == 0:
            position = PoseStamped()
            position.header.stamp, position.header.frame_id = stamp, "map"
            position.pose.position.x, position.pose.position.y = v[3], v[4]
            set_yaw(position.pose.orientation, v[5])
            if robot.active.get_goal_status().status == GoalStatus.ACTIVE:
                robot.active.publish_feedback(MoveBaseFeedback(base_position=position))

    def publish_static(self, robot: StandInRobot, t: int) -> None:
        stamp = stamp_of(t)
        transforms = [
            transform(stamp, "base_link", "base_footprint", 0.0, 0.0, 0.0, -FOOTPRINT_HEIGHT),
            transform(stamp, "base_link", "base_laser_link", 0.0, 0.0, 0.0, LASER_HEIGHT),
        ]
        self.publish(robot, "tf_static", TFMessage(transforms=transforms))


def transform(stamp: Any, parent: str, child: str, x: float, y: float, yaw: float, z: float = 0.0) -> Any:
    moved = TransformStamped()
    moved.header.stamp, moved.header.frame_id, moved.child_frame_id = stamp, parent, child
    moved.transform.translation.x, moved.transform.translation.y = x, y
    moved.transform.translation.z = z
    set_yaw(moved.transform.rotation, yaw)
    return moved


def diagonal(values: List[float]) -> List[float]:
    matrix = [0.0] * 36
    for i, value in enumerate(values):
        matrix[i * 7] = value
    return matrix


ODOM_COVARIANCE = diagonal([1e-3, 1e-3, 1e6, 1e6, 1e6, 1e-3])
AMCL_COVARIANCE = diagonal(
    [LOCALISATION_NOISE**2, LOCALISATION_NOISE**2, 0.0, 0.0, 0.0, LOCALISATION_YAW_NOISE**2]
)


def main() -> None:
    node = StandInNode()

    def closed() -> None:
        node.running = False

    serve_commands(node.handle, closed)
    if not node.setup_done.wait(60.0):
        fail("no setup and start poses came within 60 s")
    try:
        node.start()
    except Exception as e:  # noqa: BLE001  # a graph that refuses us: say why
        fail("could not start: %s: %s" % (type(e).__name__, e))
    deadline = time.monotonic() + 30.0
    while rospy.Time.now().is_zero():  # our own /clock has come back to us
        if time.monotonic() > deadline:
            fail("rospy never received the /clock this node publishes")
        time.sleep(0.01)
    emit("ready", start=node.start_ns / 1e9, robots=sorted(node.robots))
    while node.running:
        time.sleep(0.1)
    rospy.signal_shutdown("the stand-in's input closed")


if __name__ == "__main__":
    main()
