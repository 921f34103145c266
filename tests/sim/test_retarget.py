"""Retargeting through the simulated bodies: identity on the same skeleton, every bone keeps
its world direction across skeletons, and a round trip comes back."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from reactmocap.library.bvh import read_bvh
from reactmocap.library.motion import Motion
from reactmocap.library.synth import synthetic_clips
from reactmocap.sim.character import SIM_BODIES, Character, build_character
from reactmocap.sim.retarget import Retargeter, retarget

BONES = [("l_thigh", "l_shin"), ("l_shin", "l_foot"), ("r_upper_arm", "r_forearm"),
         ("r_forearm", "r_hand"), ("waist", "chest"), ("chest", "head")]  # fmt: skip


@pytest.fixture(scope="module")
def clips() -> dict[str, Motion]:
    return synthetic_clips(30.0)


def _bone_dirs(ch: Character, m: Motion) -> np.ndarray:
    pos, _ = ch.body_transforms_from_qpos(ch.qpos_from_motion(m))
    out = []
    for a, b in BONES:
        d = pos[:, SIM_BODIES.index(b)] - pos[:, SIM_BODIES.index(a)]
        out.append(d / np.linalg.norm(d, axis=-1, keepdims=True))
    return np.stack(out, axis=1)


def test_same_skeleton_is_identity(clips: dict[str, Motion]) -> None:
    kick = clips["front_kick"]
    out = retarget(kick, clips["guard"])
    np.testing.assert_allclose(out.global_positions(), kick.global_positions(), atol=1e-6)


def test_bones_keep_their_world_direction_across_skeletons(
    clips: dict[str, Motion], shared_mocap_dir: Path
) -> None:
    walk = read_bvh(shared_mocap_dir / "dataset-1_walk_normal_001.bvh")
    src = build_character(clips["guard"], frame=0)
    tgt = build_character(walk, frame=0)
    rt = Retargeter(src, tgt)
    kick = clips["front_kick"]
    out = rt(kick)
    assert out.skeleton is walk.skeleton and out.num_frames == kick.num_frames
    assert np.all(np.isfinite(out.global_positions()))
    cos = np.sum(_bone_dirs(src, kick) * _bone_dirs(tgt, out), axis=-1)
    assert np.degrees(np.arccos(np.clip(cos, -1, 1))).max() < 1e-3
    # the pelvis path is scaled by the leg-length ratio
    np.testing.assert_allclose(
        tgt.qpos_from_motion(out)[:, :3], src.qpos_from_motion(kick)[:, :3] * rt.scale, atol=1e-6
    )
    # and back: the source motion again, up to rounding
    back = Retargeter(tgt, src)(out)
    np.testing.assert_allclose(back.global_positions(), kick.global_positions(), atol=1e-6)
