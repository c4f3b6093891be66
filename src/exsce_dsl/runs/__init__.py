"""Runs: bag files in, metrics and run provenance out."""

# mypy: implicit-reexport
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from exsce_dsl.runs.analyse import run_metrics, wanted_topics
    from exsce_dsl.runs.bag_info import BagInfo, bag_info_of
    from exsce_dsl.runs.bags.formats import ROS1_BAG, ROS2_METADATA
    from exsce_dsl.runs.bags.names import topic_key
    from exsce_dsl.runs.bags.reading import is_bag, names_a_bag
    from exsce_dsl.runs.coverage import PROV_TOPIC
    from exsce_dsl.runs.ingest import IngestResult, IngestStatus, ingest_bags, stored_bag_run_id
    from exsce_dsl.runs.robots import StackRobots
    from exsce_dsl.runs.signals.trajectories import Trajectory, trajectories
    from exsce_dsl.runs.spec_draft import SpecDraft, default_spec_path, draft_spec
else:
    from exsce_dsl.faces import lazy_face

    __getattr__, __dir__ = lazy_face(__name__, __file__)
