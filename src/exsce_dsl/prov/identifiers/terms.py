"""Every namespace IRI, prefix name and vocabulary term of exsce, in one place: the method's
published namespaces (the base one, ``exsce:``, is configurable, and every namespace of the
method under it moves with it; the robot-schema and ROS namespaces are fixed), the W3C ones
(RDF, RDFS, XSD, PROV, SHACL, SPARQL results, LDP) and exsce's own fixed IRIs.

No other module spells an IRI: they import it from here (a local alias is fine).
"""

from __future__ import annotations

from typing import NamedTuple

DEFAULT_NAMESPACE = "https://www.sesame-project.org/scenarios/"
"""The method's base namespace, ``exsce:``."""

ROBOT_SCHEMA = "https://robot-schema.org/"
ROS_WIKI = "http://wiki.ros.org/"
PROV_NAMESPACE = "http://www.w3.org/ns/prov#"
XSD_NAMESPACE = "http://www.w3.org/2001/XMLSchema#"
RDF_NAMESPACE = "http://www.w3.org/1999/02/22-rdf-syntax-ns#"
RDF_TYPE = RDF_NAMESPACE + "type"
"""``rdf:type``: the one spelling of the IRI every layer writes and reads."""
XSD_STRING = XSD_NAMESPACE + "string"
RDF_LANG_STRING = RDF_NAMESPACE + "langString"
RDFS_NAMESPACE = "http://www.w3.org/2000/01/rdf-schema#"
SHACL_NAMESPACE = "http://www.w3.org/ns/shacl#"
"""``sh:``, the W3C Shapes Constraint Language."""
SPARQL_RESULTS_NAMESPACE = "http://www.w3.org/2005/sparql-results#"
"""The W3C SPARQL Query Results vocabulary (``res:``), of results written as RDF."""
LDP_NAMESPACE = "http://www.w3.org/ns/ldp#"
"""The W3C Linked Data Platform vocabulary (a graph Virtuoso keeps for itself)."""
SHAPES_NAMESPACE = DEFAULT_NAMESPACE + "shapes/"
"""Where exsce's SHACL shapes live (prefix ``exsce-sh:``), under the default base namespace."""
SKOLEM_BASE = "https://www.sesame-project.org/.well-known/genid/exsce/"
"""Where exsce's Skolem IRIs live: the blank nodes written to a store that cannot take them
(Virtuoso), read back as blank nodes."""

# The fixed prefix names, as published.
EXSCE = "exsce"
MISSION = "mission"
ENV = "env"
ROBOT = "robot"
TASK = "task"
POSE = "pose"
POINT = "point"
ORIENTATION = "orientation"
ORACLE = "oracle"
GEOM = "geom"
COORD = "coord"
ANGLE = "angle"
ROS = "ros"
RUN = "run"
TOPIC = "topic"
HOTSPOT = "hotspot"
SEGMENT = "segment"
METRIC = "metric"

STANDARD_PREFIXES = frozenset({"prov", "xsd", "xsi", "rdf", "rdfs", "owl", "xml"})
"""Prefix names that PROV and RDF tools bind themselves."""

RESERVED_PREFIXES = frozenset(
    {EXSCE, MISSION, ENV, ROBOT, TASK, POSE, POINT, ORIENTATION, ORACLE}
    | {GEOM, COORD, ANGLE, ROS}
    | {RUN, TOPIC, HOTSPOT, SEGMENT, METRIC}
    | STANDARD_PREFIXES
)
"""Prefix names no per-element namespace may take."""


class Term(NamedTuple):
    """A name in one of the fixed namespaces: ``Term("geom", "Pose")`` is ``geom:Pose``."""

    prefix: str
    local: str

    def __str__(self) -> str:
        return f"{self.prefix}:{self.local}"


# Types (values of prov:type).
PROV_PLAN = Term("prov", "Plan")
PROV_PRIMARY_SOURCE = Term("prov", "PrimarySource")
PROV_SOFTWARE_AGENT = Term("prov", "SoftwareAgent")
CONCRETE_SCENARIO = Term(EXSCE, "ConcreteScenario")
MISSION_TYPE_VALUE = Term(EXSCE, "mission")
ENVIRONMENT_TYPE = Term(EXSCE, "environment")
MAP_TYPE = Term(EXSCE, "map")
ROBOT_TYPE_VALUE = Term(EXSCE, "robot")
OBSTACLE_TYPE = Term(EXSCE, "obstacle")
GEOM_POSE = Term(GEOM, "Pose")
GEOM_POINT = Term(GEOM, "Point")
GEOM_EULER_ANGLES = Term(GEOM, "EulerAngles")
ROS_OCCUPANCY_GRID = Term(ROS, "OccupancyGrid")
ROS_PARAMETER_SERVER = Term(ROS, "Parameter_Server")
ROS_GAZEBO_MODEL = Term(ROS, "GazeboModel")

# Attributes.
MISSION_TYPE = Term(EXSCE, "missionType")
SCENARIO_ATTR = Term(EXSCE, "scenario")
ROBOT_TYPE = Term(EXSCE, "robotType")
BASE_TYPE = Term(EXSCE, "baseType")
TORSO = Term(EXSCE, "torso")
OBSTACLE_MODEL = Term(EXSCE, "model")
OBSTACLE_SIZE = Term(EXSCE, "size")
GEOM_AXES = Term(GEOM, "axes")
COORD_X = Term(COORD, "x")
COORD_Y = Term(COORD, "y")
COORD_Z = Term(COORD, "z")
ANGLE_ROLL = Term(ANGLE, "roll")
ANGLE_PITCH = Term(ANGLE, "pitch")
ANGLE_YAW = Term(ANGLE, "yaw")
ROS_PKG = Term(ROS, "pkg")
ROS_RELATIVE_PATH = Term(ROS, "relative_path")
ROS_NAMESPACE = Term(ROS, "namespace")


# Local names of an element's parts, in the element's own namespace.
GAZEBO_MODEL = "gazebo_model"
"""``<robot>:gazebo_model``, the robot's simulation model."""
ROBOT_AGENT = "agent"
"""``<robot>:agent``, the software agent that is the robot."""
SOFTWARE_CONFIG = "software-config"
HARDWARE_CONFIG = "hardware-config"
"""``<robot>:software-config`` and ``<robot>:hardware-config``; also their ``prov:type`` strings."""
OCCUPANCY_GRID = "occupancy_grid"
MAP_METADATA = "metadata"
"""``<environment>:occupancy_grid`` and ``<environment>:metadata``, the map's members."""
GAZEBO_WORLD = "gazebo_world"
"""``<environment>:gazebo_world``, the simulator's world model."""


# Runs, metrics, oracles and derivations (the run-time PROV of the method).
RUN_TYPE = Term(EXSCE, "run")
"""The run activity's type; the same name is the ``exsce:run`` attribute (the run's uuid)."""
RUN_ATTR = Term(EXSCE, "run")
TASK_EXECUTION_TYPE = Term(EXSCE, "task_execution")
ACTION_TYPE = Term(EXSCE, "action")
OUTPUT_METRIC_TYPE = Term(EXSCE, "output_metric")
TOPIC_COLLECTION_TYPE = Term(EXSCE, "topic")
HOTSPOT_TYPE_VALUE = Term(EXSCE, "hotspot")
ORACLE_TYPE_VALUE = Term(EXSCE, "oracle")
TRANSFORM_TYPE = Term(EXSCE, "transform")
GENERATION_TYPE = Term(EXSCE, "generation")
ROS_BAGS = Term(ROS, "Bags")
ROS_TOPICS = Term(ROS, "Topics")

FILE_PATH = Term(EXSCE, "file_path")
ROBOT_ATTR = Term(EXSCE, "robot")
STATUS = Term(EXSCE, "status")
GOAL_OUTCOME = Term(EXSCE, "goal_outcome")
"""On an ABORTED action that its stack did not abort: ``rejected``, ``timed out`` or ``cancelled``."""
ATTEMPTS = Term(EXSCE, "attempts")
"""On an action whose goal was sent more than once: how many times."""
MISSION_STATUS = Term(EXSCE, "mission_status")
"""On a run whose mission did not complete: ``cancelled`` or ``stopped`` (incomplete)."""
SEGMENTED_BY = Term(EXSCE, "segmented_by")
"""On a task execution: what its actions (path segments) were found from, when not the method's
dispatcher (a navigation stack's goals, arrival at the planned waypoints)."""
TIMELINE = Term(EXSCE, "timeline")
"""On a bag: the clock of the run's timeline, ``simulated time`` or ``wall clock``."""
SOURCE_CLOCK_TYPE = Term(EXSCE, "source_clock")
"""The clock one topic of a bag was timed by in a run (derived from the topic)."""
CLOCK = Term(EXSCE, "clock")
SIMULATED_TIME = Term(EXSCE, "simulated_time")
CLOCK_OFFSET = Term(EXSCE, "clock_offset")
DETECTED_CONVENTION_TYPE = Term(EXSCE, "detected_convention")
"""Where a robot's signals were found in a run's bag, when its type named no convention
(derived from the topics that showed it)."""
CONVENTION = Term(EXSCE, "convention")
ESTIMATED_FROM = Term(EXSCE, "estimated_from")
"""On a metric value: the signal it was estimated from where the bag lacked its own (``pose``)."""
UNIT = Term(EXSCE, "unit")
METRIC_ATTR = Term(EXSCE, "metric")
"""On a ``violation_duration`` value: the safety metric whose limit was violated."""
VIOLATIONS = Term(EXSCE, "violations")
DURATION = Term(EXSCE, "duration")
COVERAGE_GAP_TYPE = Term(EXSCE, "coverage_gap")
"""Something a run's recording does not cover (cut short, no data, a gap, a low rate, a clock jump)."""
TOPIC_RATE_TYPE = Term(EXSCE, "topic_rate")
"""How densely a topic a metric reads was recorded in a run."""
SHORTFALL = Term(EXSCE, "shortfall")
"""On a coverage gap: ``cut_short``, ``no_data``, ``gap``, ``low_rate`` or ``clock_jump``."""
REASON = Term(EXSCE, "reason")
TOPIC_NAME = Term(EXSCE, "topic_name")
"""On a coverage gap or a topic rate: the topic, as the bag spells it."""
READ_BY = Term(EXSCE, "read_by")
"""On a coverage gap or a topic rate: the metrics whose values read the data, space-separated
(absent on a gap: every metric of the run)."""
GAP_START = Term(EXSCE, "gap_start")
GAP_END = Term(EXSCE, "gap_end")
MESSAGES = Term(EXSCE, "messages")
RATE = Term(EXSCE, "rate")
WINDOW_START = Term(EXSCE, "window_start")
"""On a metric value: where its window begins (``xsd:dateTime``, the recorder's wall clock; only
on a run with dates)."""
WINDOW_END = Term(EXSCE, "window_end")
WINDOW_FROM = Term(EXSCE, "window_from")
"""On a metric value: where its window begins, in seconds after the run's start."""
WINDOW_TO = Term(EXSCE, "window_to")
WINDOW_REASON = Term(EXSCE, "window_reason")
"""On a metric value: why its window is what it is (the recording, the goals' span, a segment)."""
ANNOTATIONS = Term(EXSCE, "annotations")
"""On a metric value: the coverage findings that touch it, one per line."""
SAMPLE_COUNT_TYPE = Term(EXSCE, "sample_count")
"""How many samples of one source a metric value used, of those its window holds."""
COUNTED_FOR = Term(EXSCE, "counted_for")
SAMPLES_USED = Term(EXSCE, "samples_used")
SAMPLES_IN_WINDOW = Term(EXSCE, "samples_in_window")
FEWER_BECAUSE = Term(EXSCE, "fewer_because")
TF_CHAIN = Term(EXSCE, "tf_chain")
"""On a sample count whose source is composed from TF: the transforms composed (``map → odom →
base_link``)."""
RUN_PROBLEM_TYPE = Term(EXSCE, "run_problem")
"""Something ingestion said of a run (a value it could not compute, and why)."""
PROBLEM = Term(EXSCE, "problem")
METRIC_TYPE = Term(RUN, "metricType")
HOTSPOT_TYPE = Term(HOTSPOT, "type")
ORACLE_METRIC = Term(ORACLE, "metric")
ORACLE_ROBOT = Term(ORACLE, "robot")
ORACLE_RELATIONSHIP = Term(ORACLE, "relationship")
ORACLE_PACKAGE = Term(ORACLE, "package")
ORACLE_KIND = Term(ORACLE, "type")
ORACLE_VALUE = Term(ORACLE, "value")
ORACLE_LIMIT = Term(ORACLE, "limit")
ORACLE_DELTA = Term(ORACLE, "delta")
ORACLE_TOLERANCE = Term(ORACLE, "tolerance")
ORACLE_WINDOW = Term(ORACLE, "window")
ORACLE_CRITERION = Term(ORACLE, "criterion")
ORACLE_RUNS = Term(ORACLE, "runs")
ORACLE_CONFIDENCE = Term(ORACLE, "confidence")
"""On an output relation built ``at 99 %``: the confidence (0.99); its tolerance is the half-width
of the prediction interval for one new run from oracle:sampleSize runs."""
ORACLE_SAMPLE_SIZE = Term(ORACLE, "sampleSize")
ORACLE_OUTCOME = Term(ORACLE, "outcome")
ORACLE_MARGIN = Term(ORACLE, "margin")
ORACLE_REASON = Term(ORACLE, "reason")
ORACLE_SHORTFALL = Term(ORACLE, "shortfall")
"""On a verdict: the kinds of what the recording did not cover (``cut_short gap``), space-separated."""
ORACLE_AGAINST = Term(ORACLE, "against")
BASELINE_RUNS_TYPE = Term(EXSCE, "baseline_runs")
"""In an oracles bundle: the runs of one scenario its oracles learnt from (``oracle:runs``)."""
LEFT_OUT_RUN_TYPE = Term(EXSCE, "left_out_run")
"""In an oracles bundle: a stored run its oracles did not learn from, with ``oracle:reason``."""
"""On a verdict of a metamorphic oracle: the base scenario it compared with."""

# Exploration campaigns (exsce_dsl.prov.campaign).
CAMPAIGN_TYPE = Term(EXSCE, "campaign")
TRIAL_TYPE = Term(EXSCE, "trial")
SHRINK_TYPE = Term(EXSCE, "shrink")
SHRINK_TRY_TYPE = Term(EXSCE, "shrink_try")
CAMPAIGN_ID = Term(EXSCE, "campaign_id")
"""On a campaign, its trials, shrinkings and tries: the campaign's id, for queries."""
CAMPAIGN_BUDGET = Term(EXSCE, "budget")
CAMPAIGN_SEED = Term(EXSCE, "seed")
RUNS_PER_SCENARIO = Term(EXSCE, "runs_per_scenario")
MAX_STEPS = Term(EXSCE, "max_steps")
CAMPAIGN_TRANSFORMATIONS = Term(EXSCE, "transformations")
EXECUTOR = Term(EXSCE, "executor")
STRATEGY = Term(EXSCE, "strategy")
RELATIONS_CHECKED = Term(EXSCE, "relations")
TOLERANCE = Term(EXSCE, "tolerance")
ORDER = Term(EXSCE, "order")
STEPS = Term(EXSCE, "steps")
TRIAL_RUNS = Term(EXSCE, "trial_runs")
CHECKED = Term(EXSCE, "checked")
VIOLATED = Term(EXSCE, "violated")
INCONCLUSIVE = Term(EXSCE, "inconclusive")
"""On a trial: the relations it could not decide (runs not covered could have violated them)."""
OUTCOME = Term(EXSCE, "outcome")
RELATION = Term(EXSCE, "relation")
TRIAL = Term(EXSCE, "trial_number")
MINIMAL = Term(EXSCE, "minimal")
SHRINK_NUMBER = Term(EXSCE, "shrink_number")
CAMPAIGN_EXECUTIONS = Term(EXSCE, "executions")
COUNTEREXAMPLES = Term(EXSCE, "counterexamples")
COUNTEREXAMPLES_PER_100 = Term(EXSCE, "counterexamples_per_100_executions")
VIOLATED_RELATIONS = Term(EXSCE, "violated_relations")
INCONCLUSIVE_TRIALS = Term(EXSCE, "inconclusive_trials")
TO_FIRST_FAILURE = Term(EXSCE, "executions_to_first_failure")
VALIDATION_TYPE = Term(EXSCE, "validation")
VERDICT_TYPE = Term(EXSCE, "verdict")
VERDICTS_BUNDLE = "verdicts_bundle"
TRANSFORM_ATTR = Term(EXSCE, "transform")
STEP = Term(EXSCE, "step")

# The execution of a run as its dispatcher recorded it (see exsce_dsl.prov.run_execution).
EXECUTION_TYPE = Term(EXSCE, "execution")
"""The dispatcher's run activity, ``run:run_<dispatcher's uuid>``, stored with the ingested run."""
DISPATCHED_GOAL_TYPE = Term(EXSCE, "dispatched_goal")
"""One goal the dispatcher sent, as its run-time PROV names it."""
DISPATCHED_RUN = Term(EXSCE, "dispatched_run")
"""On an execution: the dispatcher's uuid of the run."""
RUN_TIME_PROV = Term(EXSCE, "run_time_prov")
"""On an execution: where its run-time PROV was read (``/exsce/prov`` or the ``.prov.json``)."""
SIMULATOR = Term(EXSCE, "simulator")
"""On the agent that played a simulated run (``<run>:simulator``): the simulator's name."""
SIMULATOR_VERSION = Term(EXSCE, "simulator_version")
SIMULATOR_SETTINGS = Term(EXSCE, "simulator_settings")
"""``name=value`` pairs joined by ``; ``, in the order the simulator gives them."""
SIMULATOR_AGENT = "simulator"
"""``<run>:simulator``, the software agent that played the run."""

# The segment index (written by the store beside a run's bundles, see exsce_dsl.store.segment_index).
PATH_SEGMENT = Term(EXSCE, "PathSegment")
START_POSE = Term(EXSCE, "startPose")
GOAL_POSE = Term(EXSCE, "goalPose")
SEGMENT_OF = Term(EXSCE, "segmentOf")

# The run summaries (written by the store beside a run's bundles and verdicts, see
# exsce_dsl.store.run_summary): what the scenario-wide questions read, one range of an index each.
SCENARIO_RUNS = Term(EXSCE, "ScenarioRuns")
VIOLATION_SERIES = Term(EXSCE, "ViolationSeries")
HOTSPOT_SERIES = Term(EXSCE, "HotspotSeries")
METRIC_VALUES = Term(EXSCE, "MetricValues")
RUN_DEFECT = Term(EXSCE, "RunDefect")
SUMMARY_OF = Term(EXSCE, "summaryOf")
SUMMARY_METRIC = Term(EXSCE, "summaryMetric")
SUMMARY_ROBOT = Term(EXSCE, "summaryRobot")
SUMMARY_RUN = Term(EXSCE, "summaryRun")
SUMMARY_START = Term(EXSCE, "summaryStart")
SUMMARY_END = Term(EXSCE, "summaryEnd")
SUMMARY_STATUS = Term(EXSCE, "summaryStatus")
SUMMARY_BAG = Term(EXSCE, "summaryBag")
SUMMARY_BAG_PATH = Term(EXSCE, "summaryBagPath")
VIOLATION_SECONDS = Term(EXSCE, "violationSeconds")
HOTSPOT_COUNT = Term(EXSCE, "hotspotCount")
DEFECT = Term(EXSCE, "defect")
DEFECT_KIND = Term(EXSCE, "defectKind")
DEFECT_SUBJECT = Term(EXSCE, "defectSubject")
DEFECT_RELATION = Term(EXSCE, "defectRelation")
DEFECT_ROBOT = Term(EXSCE, "defectRobot")
DEFECT_SECONDS = Term(EXSCE, "defectSeconds")
DEFECT_HOTSPOT = Term(EXSCE, "defectHotspot")
BASELINE_RUN = Term(EXSCE, "baselineRun")
RUN_SUMMARY = "summary"
"""``<run>:summary``: the run's summary graph (its ingest's facts)."""
VERDICTS_SUMMARY = "verdicts_summary"
"""``<run>:verdicts_summary``: the summary of the run's last verification (its defects)."""

PARAMETER_SERVER = "parameter-server"
"""``<run>:parameter-server``, the saved parameters the run used."""
GOAL_ROLE = "goal"
TOPIC_ROLE = "topic"
HOTSPOTS_BUNDLE = "hotspots_bundle"
BAG_BUNDLE = "bag_bundle"
"""``<run>:bag_bundle``: the bag a run generated and its topics, named by the run (never by the bag's
file, which two recordings may share)."""
COVERAGE_BUNDLE = "coverage_bundle"
PROBLEMS_BUNDLE = "problems_bundle"
EXECUTION_BUNDLE = "execution_bundle"
GENERATION = "generation"
GENERATION_BUNDLE = "scenario_generation"
