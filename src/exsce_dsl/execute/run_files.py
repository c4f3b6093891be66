"""The files one run on a live graph leaves, named as the method names them (its tutorial §6.1.2):
``<ISO date>_<scenario>_run-<first 8 of the run's uuid>`` with ``.bag``, ``.prov.json`` and
``.rosparams`` (``2023-06-13T15-48-07_scenario_c_run-e30df0b6.bag``).

The name comes from :func:`exsce_dsl.model.runs.run_name`, the one function ``simulate`` names
its runs with too.  A run is written in a hidden folder beside its place (:meth:`RunFiles.staged`)
and moved into place when it is whole (:meth:`RunFiles.put_in_place`, the bag last), so that a run
cut short leaves no half-written bag under a run's name.
"""

from __future__ import annotations

import datetime
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from exsce_dsl.model.runs import run_name
from exsce_dsl.runs import ROS1_BAG

BAG, PROV, PARAMETERS = ROS1_BAG.suffix, ".prov.json", ".rosparams"
"""The extensions of a run's files: its bag, its run-time PROV, its parameter-server dump."""
ROS2_BAG, ROS2_PARAMETERS = "", ".params.yaml"
"""A ROS 2 run's: its bag is a rosbag2 folder named as the run, its parameters the dispatcher
node's, as ``ros2 param dump`` writes them."""


@dataclass(frozen=True)
class RunFiles:
    """Where the files of run ``name`` are: ``folder/name.bag``, ``.prov.json``, ``.rosparams``."""

    folder: Path
    name: str
    ros2: bool = False
    """A ROS 2 run: the bag a folder ``name/``, the parameters ``name.params.yaml``."""

    @classmethod
    def of(
        cls, folder: Path, scenario: str, run_id: str, start: datetime.datetime, ros2: bool = False
    ) -> RunFiles:
        """The files of run ``run_id`` (a uuid) of ``scenario``, started at ``start`` (with a time
        zone), in ``folder``; an :class:`~exsce_dsl.errors.ExsceError` for a scenario id that is
        not file-safe, a run id that is not a uuid or a start without a time zone."""
        return cls(folder, run_name(start, scenario, run_id), ros2)

    @property
    def bag(self) -> Path:
        return self.folder / (self.name + (ROS2_BAG if self.ros2 else BAG))

    @property
    def prov(self) -> Path:
        return self.folder / (self.name + PROV)

    @property
    def rosparams(self) -> Path:
        return self.folder / (self.name + (ROS2_PARAMETERS if self.ros2 else PARAMETERS))

    def all(self) -> tuple[Path, Path, Path]:
        """The three files, in the order they are put in place (the bag last)."""
        return self.rosparams, self.prov, self.bag

    @property
    def staging(self) -> Path:
        """The run's hidden folder beside its place: ``folder/.name.partial``."""
        return self.folder / f".{self.name}.partial"

    def staged(self) -> RunFiles:
        """The same files in the run's hidden folder, made empty (what an earlier try left there
        is removed)."""
        self.discard_staged()
        self.staging.mkdir(parents=True)
        return RunFiles(self.staging, self.name, self.ros2)

    def put_in_place(self) -> list[Path]:
        """Move the staged files that exist into :attr:`folder` (each replacing a file of the same
        name), the bag last: a bag in its place is a whole run.  The hidden folder is removed.
        Returns the files put in place."""
        staged = RunFiles(self.staging, self.name, self.ros2)
        placed = []
        for source, target in zip(staged.all(), self.all(), strict=True):
            if source.exists():
                if target.is_dir():  # a ROS 2 bag of an earlier try: os.replace takes empty folders only
                    shutil.rmtree(target)
                os.replace(source, target)
                placed.append(target)
        self.discard_staged()
        return placed

    def discard_staged(self) -> None:
        """Remove the run's hidden folder and what is in it (a run that will not be kept)."""
        if self.staging.is_dir():
            shutil.rmtree(self.staging)
        elif self.staging.exists():
            self.staging.unlink()
