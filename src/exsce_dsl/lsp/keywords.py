"""What each word of the language means, as hover shows it."""

from __future__ import annotations

from exsce_dsl.lsp.derive_steps import step_meanings

_WRITTEN: dict[str, str] = {
    "import": '`import "path.exsce"`: use the declarations of another file (a path relative to this one).',
    "robot": "`robot type NAME { ... }` declares the hardware of a kind of robot; "
    "`each robot` says a clause of every robot of the fleet.",
    "type": "`robot type NAME { base B  torso yes|no }`: hardware facts that similarity compares.",
    "base": "`base NAME`: the robot type's mobile base (e.g. pmb2, omni_base).",
    "torso": "`torso yes|no`: whether the robot type has a torso.",
    "convention": "`convention method|nav2|move_base`: where the robot type's signals are in its bags: "
    "the method's topics, Nav2's (pose from TF map -> base_link, else amcl_pose, else "
    "odom; velocity on cmd_vel) or move_base's; named by none, it is detected from each bag. Each "
    "`pose`, `velocity`, `scan`, `navigation` or `arrival` line overrides one.",
    "motion": "`motion planar|3d`: a robot type's motion; `3d` (a drone's) measures its path lengths in "
    "x-y-z and makes arrival compare heights (planar, the default: x-y).",
    "window": "`window goals|whole recording`: what the robot's whole-run metrics cover: its first "
    "goal's start to its last goal's end (the default), or the whole recording of its signals.",
    "recording": "`window whole recording`: whole-run metrics over the whole recording of the robot's "
    "signals.",
    "velocity": '`velocity on "/{ns}/cmd_vel" [TYPE]`: where the robot\'s velocity is (Twist, TwistStamped '
    "or an Odometry's twist); several lines are tried in order. In a metric, `reads vel: robot "
    "velocity` reads it (`vel.linear.x` ... `vel.angular.z`).",
    "scan": '`scan on "/{ns}/base_scan" [at 10 Hz]`: the robot\'s laser scan (sensor_msgs/msg/LaserScan); '
    "`scan at 10 Hz`: the rate it is published at, wherever it is read from (a run that recorded it "
    "at less than half of it is told at ingest). In a metric, `reads laser: robot scan` reads it "
    "(`laser.ranges`, `laser.range_min` ...).",
    "Hz": "`at 10 Hz`: the rate a robot's signal is published at (pose, velocity, scan or distance); a "
    "run recorded at less than half of it is reported at ingest, and its clauses are inconclusive.",
    "distance": "`reads odometer: robot distance`: in a metric, the distance the robot has travelled "
    "so far (`odometer.data`, m), wherever its type says it is.",
    "goals": "`reads goals: robot goals`: in a metric, the robot's navigation goals, read as windows "
    "(`elapsed`, `succeeded`) from whatever recorded them (the dispatcher, Nav2, move_base, else arrival "
    "at its planned waypoints). `window goals`: whole-run metrics from its first goal's start to its "
    "last goal's end.",
    "navigation": '`navigation dispatcher|nav2|move_base|none [on "/{ns}/ACTION", ...]`: the '
    "navigation interface whose goals make the path segments; `none`: segments by arrival at the "
    "planned waypoints.",
    "arrival": "`arrival within 0.25 m [and 0.3 rad]`: how close the robot must come to a planned "
    "waypoint (and its heading) to have reached it, or to be a goal's target.",
    "tf": "`pose from tf FIXED -> BODY`: the pose of frame BODY in frame FIXED, composed from /tf and "
    "/tf_static.",
    "yes": "A hardware fact holds.",
    "no": "A hardware fact does not hold.",
    "environment": "`environment NAME { map ...  world ...  area ... }`: where scenarios happen: its models, "
    "areas of named poses, and obstacles.",
    "map": '`map NAME [from package P path D] [file "map.yaml"]`: the occupancy grid; with `file`, '
    "every pose and obstacle is checked to lie in its free space.",
    "world": "`world NAME [from package P path D]`: the simulator's world model.",
    "from": '`from package "P" path "D"`: where ROS finds a model; `derive NEW from BASE`: the base '
    "scenario; `is increasing from VALUE`: the expected value.",
    "package": '`package "P"`: a ROS package.',
    "path": '`path "D"`: a path inside the ROS package.',
    "file": '`file "map.yaml"`: the map_server YAML on this machine, relative to this file.',
    "area": "`area NAME { pose ... }`: a region (a room) holding named poses.",
    "pose": "`pose NAME at (x, y[, z]) [facing YAW | rpy(R, P, Y)]`: a named pose of an area "
    "(lengths in m unless cm or mm follow; angles in rad unless deg follows); in a robot type, "
    '`pose from tf map -> base_link` or `pose on "/{ns}/odom" [TYPE]`: where the robot\'s pose is.',
    "at": "`at (x, y[, z])`: a position; `starts at POSE`: a robot's start pose; in a robot type, "
    "`scan at 10 Hz`: the rate a signal is published at; `is invariant at 99 %`: a confidence instead "
    "of a tolerance (the band one new healthy run falls in 99 times in 100).",
    "facing": "`facing YAW`: the heading (rad, or deg).",
    "rpy": "`rpy(roll, pitch, yaw)`: a full orientation (rad, or deg).",
    "obstacle": '`obstacle NAME [model "M"] at (x, y) [facing YAW] [size (sx, sy[, sz])]`: an obstacle '
    "of the environment.",
    "size": "`size (sx, sy[, sz])`: an obstacle's extent.",
    "model": '`model "M"`: the obstacle\'s model in the simulator.',
    "task": "`task NAME { visit a, b }`: a reusable plan: subtasks, each an ordered list of waypoints.",
    "subtask": "`subtask { visit ... }`: one part of a task, its waypoints in order.",
    "visit": "`visit POSE, POSE, (x, y)`: waypoints, in order: poses of an environment or coordinates.",
    "source": '`source package "P" path "F"`: the method\'s task file this task came from.',
    "timeout": "`timeout 120 s` (or `2 min`): how long each navigation goal may take before the "
    "dispatcher cancels it as timed out; in a task, for its goals; in a mission, for every goal whose "
    "task gives none. Without either, max(60 s, 3 x the straight leg / the robot's speed limit).",
    "scenario": "`scenario NAME in ENVIRONMENT { robots { ... } mission ... }`: robots with start poses, an "
    'environment and a mission; in acceptance criteria, `scenario "title" { given when then }`.',
    "in": "`scenario NAME in ENVIRONMENT`: the environment the scenario happens in.",
    "robots": '`robots { NAME: TYPE [namespace "ns"] [starts at POSE] }`: the scenario\'s fleet.',
    "namespace": '`namespace "ns"`: the robot\'s ROS namespace (its id by default); its topics live there.',
    "starts": "`starts at POSE`: where the robot is when the mission starts.",
    "mission": "`mission NAME parallel|sequential { ROBOT does TASK then TASK }`: the ordered allocation of "
    "tasks to robots; in a metric, `for mission` says the metric is of the whole mission.",
    "parallel": "Each robot runs its own tasks one at a time, robots side by side.",
    "sequential": "One robot executes a task at any time.",
    "does": "`ROBOT does TASK then TASK`: allocates tasks to a robot, in order.",
    "then": "`does A then B`: the next task of the robot; in criteria, `then CLAUSE`: what runs must show.",
    "acceptance": '`acceptance for SCENARIO { scenario "title" { given ... when ... then ... } }`: what runs '
    "of a scenario must show; each clause becomes an oracle.",
    "for": "`acceptance for SCENARIO`; `metric NAME for each robot | each pair of robots (a, b) | mission`.",
    "given": "`given each robot at its start pose` or `given at least N baseline runs`: a precondition.",
    "when": "`when MISSION runs` or `when ROBOT does TASK`: what the runs do.",
    "and": "Joins the clauses of `then`; in metric expressions, logical and.",
    "each": "`each robot`: the clause holds of every robot of the fleet (one oracle per robot).",
    "stays": "`stays below LIMIT` (relation below_max) or `stays above LIMIT` (above_min): a safety limit.",
    "below": "`stays below LIMIT`: the relation below_max(result, limit).",
    "above": "`stays above LIMIT`: the relation above_min(result, limit).",
    "is": "`is invariant ...` or `is increasing|decreasing ...`: compares runs with a baseline or a base "
    "scenario.",
    "invariant": "`is invariant [around V] [within T | at C %] [of baseline|SCENARIO]`: the relation "
    "invariant(result, value, tolerance); tolerance one standard deviation unless told; `at 99 %`: "
    "mean ± t((1+c)/2, n−1)·s·√(1+1/n), Student's prediction interval for one new run from n runs.",
    "increasing": "`is increasing [from V] [by D] [within T]`: the relation increasing(result, value, delta, "
    "tolerance).",
    "decreasing": "`is decreasing [from V] [by D] [within T]`: the relation decreasing(result, value, delta, "
    "tolerance).",
    "within": "`within T`: the tolerance (a quantity, `N std` or `N %`).",
    "around": "`around V`: the expected value (else the mean of the baseline's or base's runs).",
    "std": "`N std`: N standard deviations of the baseline's runs.",
    "of": "`of baseline` or `of SCENARIO`: what a relation compares against; `reverse waypoints of TASK`.",
    "baseline": "The scenario's own stored runs (`given at least N baseline runs`, `of baseline`).",
    "by": "`by D`: the change expected; `replace robot R by NEW`, `substitute task T by U`.",
    "before": "`before TASK` or `before ROBOT reaches POSE`: a window of the run before it.",
    "after": "`after TASK` or `after ROBOT reaches POSE`: a window of the run after it.",
    "during": "`during TASK`: the window of the run while the task is done.",
    "reaches": "`ROBOT reaches POSE`: the moment a robot reaches a pose.",
    "least": "`at least N baseline runs`.",
    "its": "`each robot at its start pose`.",
    "derive": "`derive NEW from BASE { steps }`: a scenario made from another by input transformations, "
    "applied in order (each a step of the generation provenance).",
    "reassign": "`reassign to R`: the removed robot's tasks go to R.",
    "like": "`like R`: the new robot has R's type.",
    "metric": '`metric NAME for each robot [per segment] { "meaning" unit U reads ... value EXPR }`: '
    "what a monitor computes from a run's topics.",
    "per": "`per segment`: the metric also has a value for each path segment.",
    "segment": "A path segment: the action between two consecutive poses.",
    "unit": "`unit U`: the metric's SI unit (s, m, m/s, rad, rad/s).",
    "safe": "`safe below|above LIMIT`: a safety metric (its violation durations and hotspots are computed).",
    "reads": '`reads NAME: pkg/msg/Type on "/{ns}/topic"`: a topic the metric reads ({ns} is the '
    "robot's namespace), of any standard ROS type or one of yours (`exscec --msg-path`); its fields: "
    '`NAME.pose.pose.position.x`, `NAME.ranges[-1]`, `NAME.transforms[child_frame_id == "base_link"]`, '
    "`len(NAME.status_list)`.",
    "value": "`value EXPR`: how the metric's value is computed from what it reads.",
    "otherwise": "`otherwise EXPR`: computed instead when a topic of the value is not in the bag.",
    "runs": "`when MISSION runs`.",
}

MEANINGS: dict[str, str] = _WRITTEN | step_meanings()
"""Every keyword's meaning; the words that start a derive step say their transformations'."""
