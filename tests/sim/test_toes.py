"""Toe segments (``build_character(toes=True)``): the layout with the hinges between the balls,
the toes following a clip's toe joints, the default body untouched, a short track."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from reactmocap.library.motion import Motion
from reactmocap.sim import World, build_character, track_clip
from reactmocap.sim.character import BALL_JOINTS


@pytest.fixture(scope="module")
def walk(shared_mocap_dir: Path) -> Motion:
    from reactmocap.library.bvh import read_bvh

    clip = shared_mocap_dir / "dataset-1_walk_normal_001.bvh"
    if not clip.is_file():
        pytest.skip(f"{clip.name} not in {shared_mocap_dir}")
    return read_bvh(clip)


def test_toes_add_two_hinges_between_the_balls(guard: Motion) -> None:
    plain, toed = build_character(guard), build_character(guard, toes=True)
    assert (plain.model.nq, plain.model.nv) == (67, 51)
    assert (toed.model.nq, toed.model.nv) == (69, 53)
    qi, vi, tq, tv = toed.layout()
    # MuJoCo's preorder: the left toe right after the left ankle, the right toe last
    ankle = 7 + 4 * BALL_JOINTS.index("l_ankle")
    assert tq.tolist() == [ankle + 4, 68] and tv.tolist() == [6 + 3 * 12, 52]
    assert sorted([*qi, *tq]) == list(range(69)) and sorted([*vi, *tv]) == list(range(53))
    # the same mass, the foot's shared with its toe; the sole cut at the ball
    assert sum(toed.segment_masses().values()) == pytest.approx(75.0)
    assert toed.segment_masses()["l_foot"] == pytest.approx(plain.segment_masses()["l_foot"])
    box = [g for g in plain.geoms if g.body == "l_foot" and g.kind == "box" and not g.patch]
    heel = [g for g in toed.geoms if g.body == "l_foot" and g.kind == "box"
            and not (g.patch or g.outline)]  # fmt: skip
    toe = [g for g in toed.geoms if g.body == "l_toe"]
    assert len(box) == len(heel) == len(toe) == 1
    assert heel[0].size[0] + toe[0].size[0] == pytest.approx(box[0].size[0])
    # a world addresses the 67 of the balls around the hinges
    world = World(toed)
    wc = world.characters[0]
    q = toed.qpos_from_motion(guard, [3])[0]
    world.set_pose(0, q)
    assert np.array_equal(world.data.qpos[wc.qpos_slice], q)
    assert np.array_equal(world.data.qpos[wc.toe_qpos], [0.0, 0.0])
    assert len(wc.ball_dofs) == 45 and not set(wc.ball_dofs) & set(wc.toe_dofs)


def test_the_toes_follow_the_clips_toe_joints(walk: Motion) -> None:
    toed = build_character(walk, toes=True)
    assert toed.fk_errors(walk, 0).max() < 1e-9
    angles = toed.toe_angles(walk)
    frame = int(np.argmin(angles[:, 0]))  # the left toes bent most (toe-off)
    assert np.degrees(angles[frame, 0]) < -25.0  # negative: bent up
    err = toed.toe_fk_errors(walk, frame)
    # the hinge follows the bend; what is left is the clip's turn off the hinge axis
    assert np.degrees(err[0]) < 6.0 < np.degrees(abs(angles[frame, 0]))


def test_a_toed_body_tracks_a_standing_clip(guard: Motion) -> None:
    res = track_clip(guard, seconds=1.0, character_kwargs={"toes": True})
    assert res.report.status == "ok", res.report.reason
    world = res.rollout.world
    wc = world.characters[0]
    q = res.rollout.qpos
    assert q.shape[1] == world.model.nq == 69
    # the toes carry weight: they bend, a little, under it
    bend = np.degrees(np.abs(q[:, wc.toe_qpos])).max()
    assert 0.05 < bend < 20.0
