"""The targets of issue 52 that bench/store.py measures against, and the store's bytes on disk.

Targets, embedded store, p50: every library query over a scenario's runs (or the whole store)
< 50 ms up to 10⁴ runs and < 250 ms up to 10⁵; over a list of runs (20, or one) < 20 ms at any
size; the run-id prefix lookup (``run_ids``) < 5 ms; writes ≥ 1.5 × pyoxigraph's ``Store.extend``
on the same quads.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

WRITE_TARGET = 1.5
"""The batch path's write rate over pyoxigraph's ``Store.extend``, at least."""


def target_ms(name: str, scope: str, size: int) -> float:
    """The p50 query ``name`` (reading ``scope``) must stay under in a store of ``size`` runs."""
    if name == "run_ids":
        return 5.0
    if scope.endswith("run") or scope.endswith("runs"):
        return 20.0
    return 50.0 if size <= 10_000 else 250.0


@dataclass(frozen=True)
class Timed:
    """One library query's figures at one size."""

    name: str
    scope: str
    samples: int
    p50: float
    p95: float
    rows: int
    target: float
    partial: bool = False
    """It reads graphs that the partial runs of the fill lack: its figure is over fewer runs."""

    @property
    def met(self) -> bool:
        return self.p50 * 1e3 < self.target

    def line(self) -> str:
        verdict = "yes" if self.met else "NO"
        note = "  (partial runs: see above)" if self.partial else ""
        return (
            f"    {self.name:28s} {self.scope:14s} {self.samples:3d} {self.p50 * 1e3:10,.2f} "
            f"{self.p95 * 1e3:10,.2f} {self.rows:7,d} {'< ' + format(self.target, ',.0f'):>8s} "
            f"{verdict:>4s}{note}"
        )


HEADER = (
    f"    {'query':28s} {'reads':14s} {'n':>3s} {'p50 ms':>10s} {'p95 ms':>10s} {'rows':>7s} "
    f"{'target':>8s} {'met':>4s}"
)


def summary(timed: list[Timed]) -> str:
    """How many targets were met, and the figures of those that were not."""
    missed = [t for t in timed if not t.met]
    text = f"  query targets met: {len(timed) - len(missed)} of {len(timed)}"
    if missed:
        text += "; not met: " + ", ".join(
            f"{t.name} {t.p50 * 1e3:,.1f} ms (< {t.target:,.0f})" for t in missed
        )
    return text


def folder_bytes(folder: Path) -> int:
    """Bytes of the files under ``folder`` (what ``du -sb`` says, without directories' own)."""
    total = 0
    for root, _, files in os.walk(folder):
        for name in files:
            try:
                total += (Path(root) / name).stat().st_size
            except FileNotFoundError:  # RocksDB removed it meanwhile
                pass
    return total
