"""Quality metrics on constructed motions with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from reactmocap import metrics
from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_exp, quat_mul
from tests.library.test_motion import NAMES, random_motion


def parts_for(m: Motion) -> BodyPartMap:
    return BodyPartMap(m.skeleton, {"pelvis": 0, "l_foot": NAMES.index("LeftLeg"),
                                    "r_foot": NAMES.index("RightLeg")})  # fmt: skip


def test_penetration_and_fall() -> None:
    m = random_motion(t=20)
    pos = m.global_positions()
    lowest = pos[..., 2].min()
    sunk = m.replace(root_positions=m.root_positions - [0, 0, lowest + 0.05])
    assert abs(metrics.penetration_max_m(sunk) - 0.05) < 1e-9
    assert metrics.penetration_max_m(m) == 0.0
    parts = parts_for(m)
    assert not metrics.fell(m, parts)
    drop = m.root_positions.copy()
    drop[10:, 2] = 0.3
    assert metrics.fell(m.replace(root_positions=drop), parts)
    assert metrics.intended_fall(m.replace(root_positions=drop), parts, from_frame=0)
    assert not metrics.intended_fall(m, parts)


def test_foot_skate_counts_only_planted_sliding() -> None:
    base = random_motion(t=60, fps=60)
    still = base.replace(
        rotations=np.broadcast_to(base.rotations[:1], base.rotations.shape),
        root_positions=np.broadcast_to([0.0, 0.0, 0.95], (60, 3)),
    )
    assert metrics.foot_skate_m(still, parts_for(still)) == 0.0
    slide = still.replace(root_positions=np.stack([np.linspace(0, 0.1, 60), np.zeros(60),
                                                   np.full(60, 0.95)], 1))  # fmt: skip
    assert abs(metrics.foot_skate_m(slide, parts_for(slide)) - 2 * 0.1) < 1e-9
    fast = still.replace(root_positions=np.stack([np.linspace(0, 3, 60), np.zeros(60),
                                                  np.full(60, 0.95)], 1))  # fmt: skip
    assert metrics.foot_skate_m(fast, parts_for(fast)) == 0.0  # moving, not planted


def test_stitch_jump_and_blend_corrections() -> None:
    m = random_motion(t=40, fps=30)
    smooth = metrics.stitch_velocity_jump_rad_s(m, [20])
    rot = m.rotations.copy()
    rot[20:, 1] = quat_exp(np.array([0.0, 0.0, 0.3]))
    jumped = m.replace(rotations=rot)
    assert metrics.stitch_velocity_jump_rad_s(jumped, [20]) > smooth + 1.0
    assert metrics.blend_joint_correction_max_rad(m, m) < 1e-7
    shifted = m.transformed(0.0, (0.2, 0.0))
    assert abs(metrics.blend_root_offset_max_m(m, shifted, parts_for(m)) - 0.2) < 1e-12


def test_the_roots_turn_is_its_own_field_not_a_joints_correction() -> None:
    m = random_motion(t=30, fps=30)
    turned = m.transformed(0.15, (0.0, 0.0))  # the whole body turned 0.15 rad about the vertical
    assert metrics.blend_root_turn_max_rad(m, turned) == pytest.approx(0.15, abs=1e-9)
    assert metrics.blend_joint_correction_max_rad(m, turned) < 1e-7  # no joint was bent
    rot = m.rotations.copy()
    rot[5:, 2] = quat_mul(rot[5:, 2], quat_exp(np.array([0.0, 0.4, 0.0])))
    bent = m.replace(rotations=rot)
    assert metrics.blend_joint_correction_max_rad(m, bent) == pytest.approx(0.4, abs=1e-9)
    assert metrics.blend_root_turn_max_rad(m, bent) < 1e-7
    # a large root turn still counts against the warning threshold
    rot = m.rotations.copy()
    rot[:, 0] = quat_mul(quat_exp(np.array([0.0, 0.0, 0.9])), rot[:, 0])  # turned in place
    far = m.replace(rotations=rot)
    parts = parts_for(m)
    assert metrics.blend_root_offset_max_m(m, far, parts) < 1e-9
    assert metrics.blend_correction_over_warning(m, far, parts) == pytest.approx(
        0.9 / metrics.WARN_ROOT_TURN_RAD, abs=1e-6
    )


def test_lift_above_source_measures_a_body_held_in_the_air() -> None:
    from reactmocap.library.bodyparts import map_body_parts
    from reactmocap.library.bvh import read_bvh
    from tests.conftest import SYNTHETIC

    m = read_bvh(SYNTHETIC / "front_kick.bvh")
    parts = map_body_parts(m.skeleton)
    assert metrics.lift_above_source_m(m, m, parts) == 0.0
    up = m.root_positions.copy()
    up[m.num_frames // 2 :, 2] += 0.4  # its second half 0.4 m up
    assert metrics.lift_above_source_m(m.replace(root_positions=up), m, parts) == pytest.approx(0.4)
    up[:, 2] -= 0.4  # lowered: never above the clip
    assert metrics.lift_above_source_m(m.replace(root_positions=up), m, parts) == pytest.approx(0.0)
