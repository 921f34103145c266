"""Heading (the body frame's twist about +Z) and placing a clip in the world."""

from __future__ import annotations

import numpy as np
import pytest

from reactmocap.library.bodyparts import map_body_parts
from reactmocap.library.motion import Motion
from reactmocap.library.placement import heading, place
from reactmocap.rotations import quat_exp, quat_from_yaw, quat_mul


@pytest.fixture(scope="module")
def clips() -> dict[str, Motion]:
    from reactmocap.library.synth import synthetic_clips

    return synthetic_clips(60.0)


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def test_heading_is_the_one_the_search_uses(clips: dict[str, Motion]) -> None:
    from reactmocap.search import calibrate, frame_features, get_feature_set

    for name, m in clips.items():
        parts = map_body_parts(m.skeleton)
        feats = frame_features(m, calibrate(m.skeleton, get_feature_set("paper"), parts))
        np.testing.assert_allclose(_wrap(heading(m, parts) - feats.heading), 0, atol=1e-12)
        assert abs(heading(m, parts)[0]) < np.radians(10), name  # they start facing +X


def test_heading_follows_yaw_and_ignores_tilt(clips: dict[str, Motion]) -> None:
    m = clips["guard"].slice(0, 20)
    parts = map_body_parts(m.skeleton)
    base = heading(m, parts)
    np.testing.assert_allclose(
        _wrap(heading(m.transformed(2.0, (1, 2)), parts) - base - 2.0), 0, atol=1e-12
    )
    # face down: the pelvis pitched 90 degrees forward (about the left axis, +Y at heading 0),
    # then turned; the hip axis stays horizontal but forward points at the floor
    rot = np.array(m.rotations)
    down = quat_mul(quat_from_yaw(0.7), quat_exp(np.array([0.0, np.pi / 2, 0.0])))
    rot[:, 0] = quat_mul(down, rot[:, 0])
    lying = m.replace(rotations=rot)
    np.testing.assert_allclose(_wrap(heading(lying, parts) - base - 0.7), 0, atol=1e-9)


def test_heading_is_stable_while_falling_sideways(clips: dict[str, Motion]) -> None:
    """At the end of the sideways fall the hip axis is nearly vertical, so its ground projection
    (the former definition) swings by tens of degrees; the twist of the body frame does not."""
    m = clips["fall_sideways"]
    parts = map_body_parts(m.skeleton)
    pos = m.global_positions()
    hips = pos[-1, parts.joint_of("l_thigh")] - pos[-1, parts.joint_of("r_thigh")]
    assert abs(hips[2]) > 5 * np.linalg.norm(hips[:2])  # lying on its side
    h = heading(m, parts)
    assert np.max(np.abs(_wrap(h - h[0]))) < np.radians(10)


def test_place_faces_and_positions_the_clip(clips: dict[str, Motion]) -> None:
    m = clips["side_kick"].transformed(1.2, (0.4, -3.0))
    parts = map_body_parts(m.skeleton)
    frame, facing, where = 25, np.radians(135.0), np.array([2.0, -1.0])
    placed = place(m, parts, frame, facing, where)
    assert heading(placed, parts)[frame] == pytest.approx(facing, abs=1e-9)
    pelvis = placed.global_positions()[frame, parts.joint_of("pelvis")]
    np.testing.assert_allclose(pelvis[:2], where, atol=1e-9)
    assert pelvis[2] == pytest.approx(m.global_positions()[frame, parts.joint_of("pelvis"), 2])


def test_ground_root_keeps_the_body_and_unturned_form_holds_world_pelvis(
    clips: dict[str, Motion],
) -> None:
    from reactmocap.library.placement import ground_root
    from reactmocap.response.blend import blend_poses
    from tests.fixtures.one_spine import dummy_root

    m = dummy_root(clips["fall_backward"].transformed(2.0, (1, 2)))  # heading not 0
    parts = map_body_parts(m.skeleton)
    pel = parts.joint_of("pelvis")
    pos, _ = m.forward_kinematics()
    for turn in (True, False):
        g = ground_root(m, parts, turn=turn)
        gp, _ = g.forward_kinematics()
        np.testing.assert_allclose(gp[:, 1:], pos[:, 1:], atol=1e-9)  # the body where it was
        np.testing.assert_allclose(g.root_positions[:, 2], 0.0, atol=1e-12)  # on the ground
        np.testing.assert_allclose(g.root_positions[:, :2], pos[:, pel, :2], atol=1e-9)
    flat = ground_root(m, parts, turn=False)
    np.testing.assert_allclose(np.abs(flat.rotations[:, 0, 0]), 1.0, atol=1e-12)
    # blending a lying pose with an upright one in the unturned form slerps the pelvis's world
    # rotation: halfway it is exactly halfway (grounded with the heading it need not be)
    up, down = flat.slice(0, 1), flat.slice(flat.num_frames - 1, flat.num_frames)
    mid = blend_poses(up, down, [0.5])
    _, r_up = up.forward_kinematics()
    _, r_down = down.forward_kinematics()
    _, r_mid = mid.forward_kinematics()
    from reactmocap.rotations import quat_conj, quat_log, quat_mul

    def angle(a: np.ndarray, b: np.ndarray) -> float:
        return float(np.linalg.norm(quat_log(quat_mul(quat_conj(a), b))))

    total = angle(r_up[0, pel], r_down[0, pel])
    assert total > 1.0  # the fall really turns the pelvis
    assert angle(r_up[0, pel], r_mid[0, pel]) == pytest.approx(total / 2, abs=1e-6)
