"""The robots' laser scanner, and the scans an executor recorded with its own sensor.

The kinematic executor records no scans: the bag writer ray-marches them on the map
(:mod:`exsce_dsl.sim.scan`).  A simulator with sensors of its own (IR-SIM's ``lidar2d``) hands
back what its sensor measured, and the writer writes exactly that.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SCAN_PERIOD = 0.1  # seconds: scans at 10 Hz
SCAN_EVERY = 5  # samples of the kinematic executor's 50 Hz clock: SCAN_PERIOD


@dataclass(frozen=True)
class Laser:
    beams: int = 720
    angle_min: float = -2.356194490192345  # -135°
    angle_max: float = 2.356194490192345
    range_min: float = 0.05
    range_max: float = 10.0
    noise: float = 0.01

    @property
    def angle_increment(self) -> float:
        return (self.angle_max - self.angle_min) / (self.beams - 1)

    def angles(self) -> np.ndarray:
        return self.angle_min + self.angle_increment * np.arange(self.beams)


@dataclass(frozen=True)
class RecordedScans:
    """One robot's scans as a simulator's sensor measured them: ``ranges[k]`` at sample
    ``samples[k]`` of the run's clock; +inf where a beam hit nothing within ``range_max``, -inf
    where it hit inside ``range_min`` (REP 117)."""

    laser: Laser
    samples: np.ndarray  # int, increasing
    ranges: np.ndarray  # float32, scans × beams
