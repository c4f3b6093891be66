"""Occupancy grids in ROS map_server format (a YAML file beside a PGM image): reading, writing, a
nav_msgs/OccupancyGrid's data as one, and which cells and points are free.

The language checks that poses lie in free space (:meth:`OccupancyGrid.state_at`); the planner
(:mod:`exsce_dsl.maps.planning`) plans on :meth:`OccupancyGrid.free_cells`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from exsce_dsl.errors import ExsceError
from exsce_dsl.textfiles import read_bytes, read_text

FREE, OCCUPIED, UNKNOWN, OUTSIDE = "free", "occupied", "unknown", "outside"


@dataclass(frozen=True)
class OccupancyGrid:
    """``cells`` is row 0 = the top of the image, as map_server reads it."""

    cells: np.ndarray  # uint8 grey levels, shape (height, width)
    resolution: float
    origin: tuple[float, float, float]
    occupied_thresh: float
    free_thresh: float
    negate: bool

    @property
    def height(self) -> int:
        return int(self.cells.shape[0])

    @property
    def width(self) -> int:
        return int(self.cells.shape[1])

    def bounds(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the grid in the map frame (origin yaw 0)."""
        ox, oy, _ = self.origin
        return ox, ox + self.width * self.resolution, oy, oy + self.height * self.resolution

    def occupancy(self) -> np.ndarray:
        """Each cell's occupancy, 0 (free) to 1 (occupied), by map_server's reading of the grey
        levels (rows as in :attr:`cells`)."""
        grey = self.cells.astype(np.float64)
        occupancy: np.ndarray = grey / 255.0 if self.negate else (255.0 - grey) / 255.0
        return occupancy

    def free_cells(self) -> np.ndarray:
        """Whether each cell is free space (below ``free_thresh``; rows as in :attr:`cells`)."""
        free: np.ndarray = self.occupancy() < self.free_thresh
        return free

    def state_at(self, x: float, y: float) -> str:
        """free, occupied, unknown or outside, by map_server's thresholds."""
        ox, oy, yaw = self.origin
        dx, dy = x - ox, y - oy
        if yaw:
            c, s = math.cos(-yaw), math.sin(-yaw)
            dx, dy = c * dx - s * dy, s * dx + c * dy
        col = math.floor(dx / self.resolution)
        row_from_bottom = math.floor(dy / self.resolution)
        if not (0 <= col < self.width and 0 <= row_from_bottom < self.height):
            return OUTSIDE
        grey = int(self.cells[self.height - 1 - row_from_bottom, col])
        occupancy = grey / 255.0 if self.negate else (255 - grey) / 255.0
        if occupancy > self.occupied_thresh:
            return OCCUPIED
        if occupancy < self.free_thresh:
            return FREE
        return UNKNOWN


def map_image(yaml_path: Path) -> Path | None:
    """The image a map_server YAML names, or None when the YAML cannot be read or names none."""
    try:
        meta = _map_yaml(yaml_path)
    except ExsceError:
        return None
    if not isinstance(meta, dict) or "image" not in meta:
        return None
    return yaml_path.parent / str(meta["image"])


def _map_yaml(yaml_path: Path) -> object:
    """The data of a map's YAML file, read with bounds (:func:`~exsce_dsl.textfiles.read_text`);
    an error names the place of a YAML mistake but quotes nothing of the file (a map may name
    any file, and its content is not ours to show)."""
    try:
        text = read_text(yaml_path, "map file")
    except ExsceError as exc:
        told = f"cannot read {yaml_path}"
        if not exc.message.startswith(told):
            raise
        raise ExsceError(f"cannot read map file {yaml_path}{exc.message.removeprefix(told)}") from None
    try:
        return yaml.safe_load(text)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        raise ExsceError(f"map file {yaml_path} is not valid YAML{where}") from None
    except (yaml.YAMLError, RecursionError):
        raise ExsceError(f"map file {yaml_path} is not valid YAML (or is nested too deeply)") from None


def load_occupancy_grid(yaml_path: Path) -> OccupancyGrid:
    """Read a map_server YAML and its PGM image (binary P5 or ASCII P2), each a regular file of
    at most :func:`~exsce_dsl.textfiles.max_file_bytes`."""
    meta = _map_yaml(yaml_path)
    if not isinstance(meta, dict) or "image" not in meta or "resolution" not in meta:
        raise ExsceError(f"map file {yaml_path} is not a map_server YAML (needs image, resolution)")
    image = yaml_path.parent / str(meta["image"])
    try:
        origin = [float(v) for v in (meta.get("origin") or [0.0, 0.0, 0.0])] + [0.0, 0.0, 0.0]
        resolution = float(meta["resolution"])
        thresholds = float(meta.get("occupied_thresh", 0.65)), float(meta.get("free_thresh", 0.196))
    except (TypeError, ValueError):  # the value is not quoted: the file may be anything
        raise ExsceError(
            f"map file {yaml_path}: resolution, origin and thresholds must be numbers"
        ) from None
    return OccupancyGrid(
        cells=_read_pgm(image),
        resolution=resolution,
        origin=(origin[0], origin[1], origin[2]),
        occupied_thresh=thresholds[0],
        free_thresh=thresholds[1],
        negate=bool(meta.get("negate", 0)),
    )


def _read_pgm(path: Path) -> np.ndarray:
    data = read_bytes(path, "map image")
    magic = data[:2]
    if magic not in (b"P5", b"P2"):
        raise ExsceError(f"map image {path} is not a PGM file (only PGM maps are supported)")
    try:
        width, height, maxval, pos = _pgm_header(data)
    except (ValueError, IndexError):  # the header's words are not numbers: quoted nowhere
        raise ExsceError(f"map image {path} has no valid PGM header (width, height, maxval)") from None
    if width <= 0 or height <= 0 or not 0 < maxval < 65536:
        raise ExsceError(f"map image {path} has no valid PGM header (width, height, maxval)")
    if magic == b"P2":
        try:
            values = np.array(data[pos:].split(), dtype=np.int64)
        except ValueError:
            raise ExsceError(f"map image {path} holds something other than numbers") from None
    else:
        pos += 1  # the single whitespace after maxval
        dtype = np.uint8 if maxval < 256 else np.dtype(">u2")
        if len(data) - pos < width * height * np.dtype(dtype).itemsize:
            raise ExsceError(f"map image {path} is truncated")
        values = np.frombuffer(data, dtype=dtype, count=width * height, offset=pos).astype(np.int64)
    if values.size != width * height:
        raise ExsceError(f"map image {path} is truncated")
    scaled = values * 255 // maxval if maxval != 255 else values
    return scaled.astype(np.uint8).reshape(height, width)


def _pgm_header(data: bytes) -> tuple[int, int, int, int]:
    """Width, height and maxval of a PGM image, and the offset just after them."""
    fields: list[bytes] = []
    pos = 2
    while len(fields) < 3:
        while pos < len(data) and data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        start = pos
        while pos < len(data) and not data[pos : pos + 1].isspace():
            pos += 1
        if start == pos:
            raise ValueError("the header ends early")
        fields.append(data[start:pos])
    width, height, maxval = (int(f) for f in fields)
    return width, height, maxval, pos


FREE_GREY, OCCUPIED_GREY, UNKNOWN_GREY = 254, 0, 205
"""The grey levels map_saver writes for free, occupied and unknown cells."""
FREE_BELOW, OCCUPIED_FROM = 25, 65
"""map_saver's thresholds on a nav_msgs/OccupancyGrid's values (0-100, -1 unknown)."""


def grid_from_ros(
    values: np.ndarray, width: int, height: int, resolution: float, origin: tuple[float, float, float]
) -> OccupancyGrid:
    """An occupancy grid from a nav_msgs/OccupancyGrid's ``data`` (row-major from the origin's
    row, -1 unknown, 0-100 occupied in percent), trinary as map_saver saves it."""
    data = np.asarray(values, dtype=np.int16).reshape(height, width)
    cells = np.full(data.shape, UNKNOWN_GREY, dtype=np.uint8)
    cells[(data >= 0) & (data <= FREE_BELOW)] = FREE_GREY
    cells[data >= OCCUPIED_FROM] = OCCUPIED_GREY
    return OccupancyGrid(np.flipud(cells).copy(), resolution, origin, 0.65, 0.196, False)


def save_occupancy_grid(grid: OccupancyGrid, yaml_path: Path) -> tuple[Path, Path]:
    """Write ``grid`` as map_server reads it: ``yaml_path`` and a binary PGM beside it, of the
    same stem; returns both paths."""
    image = yaml_path.with_suffix(".pgm")
    header = f"P5\n{grid.width} {grid.height}\n255\n".encode("ascii")
    image.write_bytes(header + np.ascontiguousarray(grid.cells, dtype=np.uint8).tobytes())
    meta = {
        "image": image.name,
        "resolution": grid.resolution,
        "origin": [float(v) for v in grid.origin],
        "negate": int(grid.negate),
        "occupied_thresh": grid.occupied_thresh,
        "free_thresh": grid.free_thresh,
    }
    yaml_path.write_text(yaml.safe_dump(meta, sort_keys=False), encoding="utf-8")
    return yaml_path, image
