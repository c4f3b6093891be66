"""Issue 46, item 9: ``exscec init -o`` followed links planted where it writes the specification
and its map: with ``--force`` it wrote through them, out of the output folder."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from exsce_dsl.errors import ExsceError
from exsce_dsl.runs.spec_draft import draft_spec

from tests.support.bag_factory import ODOMETRY, Topic, header, quaternion, typestore_for, write_bag
from tests.support.cli import exscec_here
from tests.support.real_shapes import ROUTE, SHAPES, pose_topic


def _mapped_bag(folder: Path) -> Path:
    """A robot's odometry and a small free OccupancyGrid around its route."""
    store = typestore_for("ros1")
    t = store.types
    odom = pose_topic(store, "/odom", ODOMETRY, ROUTE, 20.0, frame="map")
    info = t["nav_msgs/msg/MapMetaData"](
        map_load_time=header(store, 0, "map").stamp,
        resolution=0.1,
        width=200,
        height=150,
        origin=t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=-5.0, y=-5.0, z=0.0), orientation=quaternion(store, 0.0)
        ),
    )
    grid = t["nav_msgs/msg/OccupancyGrid"](
        header=header(store, 0, "map"), info=info, data=np.zeros(200 * 150, dtype=np.int8)
    )
    bag = folder / "mapped.bag"
    write_bag(
        bag, "ros1", [odom, Topic("/map", "nav_msgs/msg/OccupancyGrid", [(odom.messages[0][0], grid)])], store
    )
    return bag


def test_init_output_refuses_planted_symlink(tmp_path: Path) -> None:
    store = typestore_for("ros1")
    bag = tmp_path / "jackal.bag"
    write_bag(bag, "ros1", SHAPES["jackal"](store), store)
    outside = tmp_path / "outside.txt"
    outside.write_text("mine\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "draft.exsce").symlink_to(outside)
    done = exscec_here("init", "--from-bag", str(bag), "-o", str(out / "draft.exsce"), "--force")
    assert done.returncode == 2 and "is a symbolic link" in done.stderr, done.stderr
    assert outside.read_text() == "mine\n"


@pytest.mark.parametrize("planted", ["draft_map.yaml", "draft_map.pgm"])
def test_init_refuses_a_link_planted_where_the_map_goes(tmp_path: Path, planted: str) -> None:
    bag = _mapped_bag(tmp_path)
    outside = tmp_path / "outside.txt"
    outside.write_text("mine\n")
    (tmp_path / planted).symlink_to(outside)
    with pytest.raises(ExsceError, match="is a symbolic link"):
        draft_spec(bag, tmp_path / "draft.exsce", force=True)
    assert outside.read_text() == "mine\n"
    assert not (tmp_path / "draft.exsce").exists()  # nothing written


def test_init_writes_the_map_beside_the_spec(tmp_path: Path) -> None:
    draft = draft_spec(_mapped_bag(tmp_path), tmp_path / "draft.exsce")
    assert draft.map_files == (tmp_path / "draft_map.yaml", tmp_path / "draft_map.pgm")
    assert all(p.is_file() and not p.is_symlink() for p in draft.map_files)
    assert 'file "draft_map.yaml"' in draft.spec.read_text()
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["draft.exsce", "draft_map.pgm", "draft_map.yaml", "mapped.bag"]  # nothing else left
