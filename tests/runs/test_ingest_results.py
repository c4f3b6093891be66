"""An ingest result keeps its remedy apart from its problem (issue 49: library text names no
flag), so that what the command line prints says it with its option, and what needed the run
(``verify``, a campaign) fails with it too."""

from __future__ import annotations

from pathlib import Path

from exsce_dsl.cli.common import REMEDIES, said_with_options
from exsce_dsl.errors import IngestFailed, Remedied
from exsce_dsl.remedies import POINT_MSG_PATH, REPLACE_THE_RUN
from exsce_dsl.runs.ingest import IngestResult, IngestStatus

SKIPPED = "a.bag: already a run of scenario 's' (run 1)"


def test_a_skipped_run_says_its_remedy_in_words_and_on_the_command_line() -> None:
    remedied = Remedied(SKIPPED, REPLACE_THE_RUN)
    result = IngestResult(Path("a.bag"), IngestStatus.SKIPPED, remedied.said(), "1", remedied=remedied)
    assert "--" not in result.message and result.message.startswith(SKIPPED + "; ")
    assert result.said(REMEDIES) == f"{SKIPPED}; pass --replace to analyse it again under this spec"
    assert result.said() == result.message


def test_a_failed_bag_s_remedy_reaches_the_error_of_what_needed_its_run() -> None:
    problem = "a.bag: no definition of my_msgs/msg/Thing (topic /thing): the bag carries none"
    remedied = Remedied(problem, POINT_MSG_PATH)
    failed = IngestResult(Path("a.bag"), IngestStatus.FAILED, remedied.said(), remedied=remedied).failure()
    assert isinstance(failed, IngestFailed) and failed.remedied == remedied
    assert said_with_options(failed) == (
        f"{problem}; point EXSCE_MSG_PATH (or exscec --msg-path) at a folder of message packages"
    )


def test_a_result_without_a_remedy_fails_with_its_message() -> None:
    failed = IngestResult(Path("b.bag"), IngestStatus.FAILED, "b.bag: not a bag").failure()
    assert failed.remedied is None and said_with_options(failed) == "b.bag: not a bag"
