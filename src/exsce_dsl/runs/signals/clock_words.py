"""How a bag's clocks are told to a user: one function, so that ``exscec bag info`` and
``exscec ingest -v`` (and the run's PROV) say the same words of the same bag.

A bag holds the recorder's log time and the stamps inside messages.  Usually log time is the
wall clock and the stamps are either the same clock or, on a simulated robot, simulated time (a
few hundred seconds).  But a recorder that itself runs on simulated time (``use_sim_time``) logs
simulated time too: its log times start a few seconds or minutes after 1970.  Such a log time is
no date, and a run recorded on it is never dated 1970: it has no date (its times are seconds of
simulated time, said as such).
"""

from __future__ import annotations

SIMULATED_LOG_BEFORE = 365 * 24 * 3600.0
"""Seconds: log times before this (one year after the epoch) are not the wall clock of any
recorder, but a simulation's clock (with ``/clock``) or a clock never set."""


def log_time_is_dated(log_start: float) -> bool:
    """Whether log times from ``log_start`` (seconds) are dates of the wall clock."""
    return log_start >= SIMULATED_LOG_BEFORE


def describe_clocks(log_start: float, clock_recorded: bool, simulated_stamps: bool) -> str:
    """The bag's clocks in words: ``log_start`` its first log time (s), ``clock_recorded``
    whether it recorded ``/clock``, ``simulated_stamps`` whether the stamps of its messages (or
    ``/clock``) are a simulation's beside wall-clock log times."""
    if not log_time_is_dated(log_start):
        if clock_recorded:
            return (
                f"simulated time (the recorder logged simulated time from {log_start:.3f} s, "
                "with /clock): no date"
            )
        return f"log time from {log_start:.3f} s after 1970 (a clock never set, or a simulation's): no date"
    if simulated_stamps:
        return "simulated time (stamps of a simulation; log time is the wall clock)"
    return "wall clock (log time and stamps agree)"
