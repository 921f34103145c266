"""Motion data model: FK, editing ops, velocities (finite differences), mirroring."""

from __future__ import annotations

import numpy as np
import pytest

from reactmocap.errors import MotionError
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import Skeleton, mirror_name_pairs
from reactmocap.rotations import quat_exp, quat_from_yaw, quat_mul, quat_rotate

NAMES = ("Hips", "Spine", "Head", "LeftUpLeg", "LeftLeg", "RightUpLeg", "RightLeg")
PARENTS = (-1, 0, 1, 0, 3, 0, 5)
OFFSETS = np.array(
    [[0, 0, 0], [0, 0, 0.2], [0, 0, 0.5], [0, 0.1, 0], [0, 0, -0.45], [0, -0.1, 0], [0, 0, -0.45]],
    dtype=float,
)


def random_motion(t: int = 30, fps: float = 30.0, seed: int = 0) -> Motion:
    rng = np.random.default_rng(seed)
    skel = Skeleton(NAMES, PARENTS, OFFSETS)
    phase = np.linspace(0, 2 * np.pi, t)[:, None, None]
    axes = rng.normal(size=(1, len(NAMES), 3))
    rot = quat_exp(0.5 * np.sin(phase + rng.uniform(0, 6, (1, len(NAMES), 1))) * axes)
    root = np.stack([np.linspace(0, 1, t), np.zeros(t), 1.0 + 0.05 * np.sin(phase[:, 0, 0])], 1)
    return Motion(skel, fps, root, rot, name="test")


def test_fk_chain_matches_hand_computation() -> None:
    m = random_motion()
    pos, rot = m.forward_kinematics()
    f = 7
    g_hips = m.rotations[f, 0]
    g_spine = quat_mul(g_hips, m.rotations[f, 1])
    p_spine = m.root_positions[f] + quat_rotate(g_hips, OFFSETS[1])
    p_head = p_spine + quat_rotate(g_spine, OFFSETS[2])
    np.testing.assert_allclose(pos[f, 2], p_head, atol=1e-12)
    np.testing.assert_allclose(rot[f, 1], g_spine, atol=1e-12)


def test_arrays_are_read_only_and_validated() -> None:
    m = random_motion()
    with pytest.raises(ValueError):
        m.rotations[0, 0, 0] = 2.0
    with pytest.raises(MotionError, match="rotations must have shape"):
        Motion(m.skeleton, 30, np.zeros((3, 3)), np.zeros((3, 2, 4)))
    with pytest.raises(MotionError, match="NaN"):
        Motion(m.skeleton, 30, np.full((1, 3), np.nan), m.rotations[:1])
    with pytest.raises(MotionError, match="fps"):
        m.replace(fps=0)
    with pytest.raises(MotionError, match="duplicate"):
        Skeleton(("a", "a"), (-1, 0), np.zeros((2, 3)))


def test_slice_concat_round_trip() -> None:
    m = random_motion()
    a, b = m.slice(0, 10), m.slice(10)
    joined = Motion.concatenate([a, b])
    np.testing.assert_array_equal(joined.rotations, m.rotations)
    np.testing.assert_array_equal(joined.root_positions, m.root_positions)
    with pytest.raises(MotionError, match="empty"):
        m.slice(40, 50)
    with pytest.raises(MotionError, match="fps"):
        Motion.concatenate([a, b.replace(fps=60)])


def test_resample_keeps_poses_at_shared_times() -> None:
    m = random_motion(t=31, fps=30)
    up = m.resample(120)
    assert up.num_frames == 121
    np.testing.assert_allclose(up.global_positions()[::4], m.global_positions(), atol=1e-9)
    down = up.resample(30)
    np.testing.assert_allclose(down.global_positions(), m.global_positions(), atol=1e-9)
    # midpoints of rotations are slerp midpoints (unit norm, between neighbours)
    assert np.allclose(np.linalg.norm(up.rotations, axis=-1), 1.0)


def test_linear_velocity_matches_finite_difference() -> None:
    m = random_motion(t=200, fps=200)
    v = m.linear_velocities()
    pos = m.global_positions()
    fd = (pos[101] - pos[99]) * m.fps / 2
    np.testing.assert_allclose(v[100], fd, atol=1e-12)
    # analytic root: x = t-linear -> vx = 1 / duration
    np.testing.assert_allclose(v[50:150, 0, 0], 1.0 / m.duration, rtol=1e-9)


def test_angular_velocity_of_constant_spin() -> None:
    skel = Skeleton(("root",), (-1,), np.zeros((1, 3)))
    omega = np.array([0.3, -0.2, 1.1])
    t = np.arange(100) / 100.0
    rot = quat_exp(t[:, None, None] * omega)
    m = Motion(skel, 100, np.zeros((100, 3)), rot)
    np.testing.assert_allclose(
        m.angular_velocities(), np.broadcast_to(omega, (100, 1, 3)), atol=1e-9
    )


def test_transformed_rotates_everything() -> None:
    m = random_motion()
    yaw = 0.7
    moved = m.transformed(yaw, (1.0, -2.0))
    expected = quat_rotate(quat_from_yaw(yaw), m.global_positions()) + np.array([1.0, -2.0, 0.0])
    np.testing.assert_allclose(moved.global_positions(), expected, atol=1e-12)


def test_mirror_reflects_and_swaps_sides() -> None:
    m = random_motion()
    mir = m.mirror("x")
    pos = m.global_positions()
    mpos = mir.global_positions()
    perm = m.skeleton.mirror_permutation()
    assert perm[NAMES.index("LeftLeg")] == NAMES.index("RightLeg")
    expected = pos[:, perm] * np.array([-1.0, 1.0, 1.0])
    np.testing.assert_allclose(mpos, expected, atol=1e-12)
    twice = mir.mirror("x")
    np.testing.assert_allclose(twice.global_positions(), pos, atol=1e-12)


@pytest.mark.parametrize(
    ("a", "b"),
    [
        ("UpperLeg_L", "UpperLeg_R"),
        ("LeftArm", "RightArm"),
        ("mixamorig:LeftHand", "mixamorig:RightHand"),
        ("lfemur", "rfemur"),
        ("hand.l", "hand.r"),
        ("L_Foot", "R_Foot"),
    ],
)
def test_mirror_name_pairs(a: str, b: str) -> None:
    pairs = mirror_name_pairs([a, b, "Spine", "Hips"])
    assert pairs == {a: b, b: a}
