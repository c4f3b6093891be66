"""``exscec stand-in`` from Python: the kinematic executor as live ROS 1 or ROS 2 robots."""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import ExitStack, contextmanager
from pathlib import Path

from exsce_dsl.execute import DEFAULT_SPEED_UP, Ros2StandIn, StandIn, start_stand_in
from exsce_dsl.execute import master_uri as environment_master_uri
from exsce_dsl.execute import start_master as start_roscore
from exsce_dsl.model import Scenario
from exsce_dsl.model.document import Specification
from exsce_dsl.sim.faults import Fault


@contextmanager
def stand_in(
    spec: Specification | Scenario,
    *,
    scenario: str | None = None,
    master_uri: str | None = None,
    start_master: bool = False,
    seed: int = 0,
    faults: Sequence[str] = (),
    speed_up: float = DEFAULT_SPEED_UP,
    log_dir: str | Path | None = None,
) -> Iterator[StandIn]:
    """``exscec stand-in --ros1``: the scenario's robots as move_base servers on the ROS 1 master at
    ``master_uri`` (else ``$ROS_MASTER_URI``; ``start_master``: a roscore of its own, stopped at the
    end), with ``faults`` as on the command line (``overspeed:tiago1``), simulated time
    ``speed_up`` times faster than wall time; logs in ``log_dir`` (else a new temporary folder,
    removed when the stand-in stops cleanly and kept, for its logs, when it fails)."""
    chosen = spec if isinstance(spec, Scenario) else spec.scenario(scenario)
    parsed = tuple(Fault.parse(f) for f in faults)
    logs = Path(log_dir) if log_dir is not None else Path(tempfile.mkdtemp(prefix="exsce-stand-in-"))
    try:
        with ExitStack() as stack:
            if start_master:
                uri = stack.enter_context(start_roscore(logs / "ros")).uri
            else:
                uri = master_uri or environment_master_uri()
            yield stack.enter_context(
                start_stand_in(chosen, uri, seed=seed, faults=parsed, speed_up=speed_up, log_dir=logs)
            )
    except BaseException:
        if log_dir is None and not any(logs.iterdir()):  # failed before it logged: nothing to read
            logs.rmdir()
        raise
    if log_dir is None:  # stopped cleanly: nothing there to read
        shutil.rmtree(logs, ignore_errors=True)


@contextmanager
def stand_in_ros2(
    spec: Specification | Scenario,
    *,
    scenario: str | None = None,
    seed: int = 0,
    faults: Sequence[str] = (),
    speed_up: float = DEFAULT_SPEED_UP,
    run: int = 0,
    simulator: str = "kinematic",
    behaviour: str | None = None,
) -> Iterator[Ros2StandIn]:
    """``exscec stand-in --ros2``: the scenario's robots as Nav2 robots (``NavigateToPose`` servers,
    odometry, TF, AMCL's pose, scans, velocity commands, ``/clock``) on the ROS 2 graph of this
    process's environment (``ROS_DOMAIN_ID``), with ``faults`` as on the command line, simulated
    time ``speed_up`` times faster than wall time; run ``run`` drives as run ``run`` of ``exscec
    simulate --seed SEED``; ``simulator``: ``irsim`` drives each leg in IR-SIM (``behaviour``).
    Up when the block starts, stopped when it ends."""
    chosen = spec if isinstance(spec, Scenario) else spec.scenario(scenario)
    parsed = tuple(Fault.parse(f) for f in faults)
    with Ros2StandIn(
        chosen, seed=seed, faults=parsed, speed_up=speed_up, run=run, simulator=simulator, behaviour=behaviour
    ) as running:
        yield running
        running.check()
