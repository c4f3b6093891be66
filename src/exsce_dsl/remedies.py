"""What the user can do about a problem, said in words: the ``remedy`` of an
:class:`~exsce_dsl.errors.ExsceError` or a :class:`~exsce_dsl.errors.Remedied` text.

The library names no option or command of the command line (issue 49): it says the remedy in
words, and ``cli.common.REMEDIES`` says each as the command line does, with the option or the
command that does it (``use --force to replace``).  A remedy may be about something, given as
``about`` (``{about}`` here and in the command line's wording).  Each remedy is its own key:
two problems with one remedy in words but another option on the command line need two keys."""

from __future__ import annotations

# files and specifications
REPLACE_FILES = "ask to replace the files that exist"
"""The remedy of an error that would overwrite files."""
SIMULATE_IT = "the simulator plays it"
"""A fault the stand-in does not play."""
INSTALL_IRSIM = "install exsce's irsim extra, which brings IR-SIM (ir-sim on PyPI)"
"""IR-SIM was asked for and is not installed."""
CHOOSE_A_CONVENTION = "the executor writes one for the whole run: choose it"
"""Robots of one run that follow different conventions."""
DEFINE_THE_TYPE = (
    "give exsce the type's .msg or .idl file, in a folder EXSCE_MSG_PATH names, to check them now"
)
"""A metric's read of a message type exsce does not know (a warning of ``check``)."""
DEFINE_THE_BAGS_TYPE = "give exsce the definition the bag uses, in a folder EXSCE_MSG_PATH names"
"""A field a metric was checked with that the bag's definition shapes otherwise."""
POINT_MSG_PATH = "point EXSCE_MSG_PATH at a folder of message packages"
"""A bag that carries no definition of a type it holds."""

# the store
REPLACE_THE_RUN = "ask to replace it to analyse it again under this spec"
"""A bag whose run the store holds already (ingest skips it)."""
REPLACE_A_STORED_RUN = "to analyse the run again and replace it, ingest its bag with replace"
"""A run the store holds with other content."""
REPLACE_A_STORED_SPEC = (
    "to replace it, add it again with replace: the old version is kept as a revision (prov:wasRevisionOf)"
)
"""A specification's graphs the store holds with other content."""
REPLACE_A_SHARED_ELEMENT = (
    f"{REPLACE_A_STORED_SPEC}; but {{about}} named by id alone, shared by every scenario of the "
    "store that names one so: if another scenario declares it otherwise, give this scenario's "
    "another id (replacing would change the other scenario's too)"
)
"""As :data:`REPLACE_A_STORED_SPEC`, where ``about`` (``robot 'r1' is``) is shared by scenarios."""
FIX_THE_STORE = "{about} can be fixed, when asked to fix them"
"""Findings of ``store check`` that ``fix`` mends (``about``: how many)."""
REBUILD_THE_BASELINE = "build it again from its specification"
"""Oracles learnt from runs the store no longer holds."""
STORE_THE_SCENARIO = "add it: store its specification"
"""A run whose scenario the store does not hold."""
ANOTHER_STORE = "stop that process, or open the store through a SPARQL endpoint (for example one serving it)"
"""An embedded store another process has open."""
LIST_THE_QUERIES = "the query library lists them all"
"""A query name the library does not hold."""
GIVE_A_RUN_ID = "give a run's uuid, a prefix of it ({about} characters at least) or its IRI"
"""Text that is no run id (``about``: the shortest prefix)."""
NO_RUNS_AT_ALL = "it holds no runs at all: ingesting bags adds them"
"""A run asked of a store without runs."""
CLOSEST_RUNS = "the closest ids:\n{about}"
MIGRATE_THE_STORE = "migrate the store: that writes them from its runs' own statements"
"""A store written before the run summaries (the scenario-wide queries read them)."""
"""A run the store lacks (``about``: the closest ids, one a line)."""
SELECT_OR_ASK = "ask a SELECT or an ASK query"
"""A query whose answer is a graph, where rows or a truth are wanted."""
SERVE_A_FOLDER = "it serves an embedded store"
"""A store to serve that is an endpoint already."""

STRICT_STORES_NONE = "a strict ingest stores no run with a missing metric{about}"
"""A run a strict ingest refuses (``about``: ``:`` and the run's problems, one an indented line,
or nothing)."""

# baselines, verdicts, campaigns
LEARN_FROM_EVERY_RUN = "ingest runs that pass, or include every run"
"""Every stored run of a scenario left out of what a baseline learns from."""
BUILD_A_BASELINE = "build its baseline first"
"""A scenario to verify without oracles (``about``: its id)."""
VERIFY_THE_RUN = "verify the run"
"""A run without verdicts."""
VERIFY_AGAIN = "verifying the run judges it again{about}"
"""A replaced run whose verdicts were dropped (``about``: what follows in the message, or nothing)."""
REPRODUCE_IT = "verify the runs {about[0]} against {about[1]}"
REPLAY_IT = "simulate {about[0]} again with seed {about[1]} ({about[2]} runs): the same bags"
"""A campaign's smallest violating derivation, played again by its seed by the kinematic executor
(``about``: its file, the seed, the runs)."""
REPLAY_IN_IRSIM = (
    "simulate {about[0]} again in IR-SIM with seed {about[1]} ({about[2]} runs, behaviour {about[3]}, "
    "scans by {about[4]}): the same bags"
)
"""The same, played by IR-SIM (``about``: its file, the seed, the runs, the behaviour, the scans)."""
"""A campaign's smallest violating derivation (``about``: its bags' folder, its file)."""
INSTALL_DASK = "pip install 'exsce[dask]'"
"""A Dask cluster without Dask's distributed package."""
BUILT_IN_OPTIONS = (
    "faults, the stand-in, a master of its own and a speed-up are for the built-in executors {about}"
)
"""Options given to a plug-in executor (``about``: the built-ins and the plug-in)."""
ONE_EXECUTOR = "give one of faults (the simulator), an executor command and an executor"
"""Several ways of playing a campaign's runs at once."""
ROS1_OPTIONS = (
    "the stand-in, a master of its own and a speed-up go with the ros1 executor "
    "(the stand-in and a speed-up with ros2 too)"
)
"""Options of the ros1 executor without it."""
FAULTS_NEED_THE_STAND_IN = "ask for the stand-in"
"""Faults planted by the ros1 executor, which plants them in the stand-in."""
STAND_IN_ONLY = (
    "ask for the stand-in (a campaign starts each derived scenario from its own start poses, and "
    "exsce cannot yet move a real stack's robots there between runs; a script that resets your "
    "simulator and executes the scenario on ROS 1 can be an executor command)"
)
"""The ros1 executor without the stand-in."""

# live runs
START_A_MASTER = "start roscore and export it, or ask for a roscore of the run's own"
"""A live run without a ROS master to talk to."""
STAND_IN_FOR_FAULTS = "give stand_in=True with them"
"""Faults or a seed for a live run without the stand-in."""

# servers
MAKE_A_TOKEN = "give no token, and leave EXSCE_STORE_TOKEN unset, to have one made"
"""An update token too short to be a secret."""
READ_ONLY = (
    "stop the server to write to its store directly, or restart it allowing updates and send its "
    "bearer token (exsce's commands send EXSCE_STORE_TOKEN)"
)
"""An update sent to a read-only endpoint."""
SEND_THE_TOKEN = "exsce's commands send EXSCE_STORE_TOKEN"
"""An update without the endpoint's token."""
ALLOW_THE_HOST = "ask it by the address it listens on, or start it allowing that host name"
"""A request naming a host the endpoint does not answer for."""
ALLOW_FEDERATION = "the endpoint reaches a host only when started allowing federation to it"
"""A query or update that would reach another server."""
LONGER_TIME_LIMIT = "ask for less: LIMIT, fewer runs; or start the server with a longer time limit"
"""A request to the MCP server over its time limit."""

# the report
GIVE_THE_SPECS = "give the scenarios' files to draw paths on their maps"
"""A report made without the scenarios' files."""
ADD_ITS_SPEC = "add its file to the files given"
"""A report's scenario (``about``) that no file given declares."""
