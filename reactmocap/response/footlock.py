"""Foot locking for the final blend: where a foot is planted in the blended transition but
slides, pin its ankle horizontally and bend the leg with analytic two-bone IK.

Why: the paper's blend moves the root by a linearly growing offset and Simulation 2's feet
slide at friction 0.5, so planted feet skate during the transition (``foot_skate_m``). Lock
targets keep the transition's ends exact: a plant that touches the first frame is pinned where
the pre-impact motion left the foot, one that touches the last frame where the found clip puts
it, so the first and last frames (continuity, exact landing) are unchanged. Written by hand:
no listed library does IK on BVH skeletons, and two-bone IK is a few closed-form lines.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.metrics import PLANT_HEIGHT_M, PLANT_SPEED_M_S
from reactmocap.rotations import quat_conj, quat_mul, quat_normalize, quat_rotate, unit_rows

__all__ = ["lock_feet", "place_ankles"]

F64 = NDArray[np.float64]
#: plants whose ankle drifts less than this (m) are left alone
MIN_DRIFT_M = 0.01
#: frames over which a correction fades in before and out after a plant
FADE_FRAMES = 3
#: frames over which corrections ease in from the transition's first frame and out to its last
END_EASE_FRAMES = 4


def _arc(u: F64, v: F64) -> F64:
    """``(n, 4)`` shortest rotations taking unit vectors ``u`` to ``v`` (wxyz)."""
    w = 1.0 + np.sum(u * v, axis=-1, keepdims=True)
    q = np.concatenate([w, np.cross(u, v)], axis=-1)
    return quat_normalize(q)


def _intervals(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Inclusive ``(start, stop)`` runs of True."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1, strict=True))


def _targets(ankle: F64, fps: float) -> tuple[F64, F64]:
    """Per-frame horizontal lock target and weight (0..1) for one ankle track ``(T, 3)``."""
    n = ankle.shape[0]
    speed = np.zeros(n)
    speed[1:] = np.linalg.norm(np.diff(ankle[:, :2], axis=0), axis=-1) * fps
    speed[0] = speed[1] if n > 1 else 0.0
    planted = (ankle[:, 2] <= ankle[:, 2].min() + PLANT_HEIGHT_M) & (speed < PLANT_SPEED_M_S)
    target = ankle[:, :2].copy()
    weight = np.zeros(n)
    for a, b in _intervals(planted):
        drift = np.linalg.norm(ankle[a : b + 1, :2] - ankle[a, :2], axis=-1).max()
        if drift < MIN_DRIFT_M:
            continue
        pin = ankle[b, :2] if b == n - 1 else ankle[a, :2]
        lo, hi = max(0, a - FADE_FRAMES), min(n - 1, b + FADE_FRAMES)
        for k in range(lo, hi + 1):  # a plant is a few frames; not the sim hot path
            if k < a:
                fade = (k - lo + 1) / (a - lo + 1)
            elif k > b:
                fade = (hi - k + 1) / (hi - b + 1)
            else:
                fade = 1.0
            if fade > weight[k]:
                weight[k], target[k] = fade, pin
    # the ends stay exact and their neighbours ease in, so the joint velocities where the
    # transition meets the pre-impact motion and the found clip do not jump
    frame = np.arange(n, dtype=np.float64)
    ramp = np.clip(np.minimum(frame, n - 1 - frame) / END_EASE_FRAMES, 0.0, 1.0)
    return target, weight * ramp * ramp * (3.0 - 2.0 * ramp)


def lock_feet(motion: Motion, parts: BodyPartMap) -> Motion:
    """``motion`` with sliding planted feet pinned (see the module docstring). Legs whose
    knee is not the hip's child or whose ankle is not the knee's child are left as they are."""
    if motion.num_frames < 3:
        return motion
    pos = motion.global_positions()
    goals = {}
    for side in ("l", "r"):
        a = pos[:, parts.joint_of(f"{side}_foot")]
        target_xy, w = _targets(a, motion.fps)
        frames = np.flatnonzero(w > 0)
        if frames.size:
            goal = a[frames].copy()
            goal[:, :2] += w[frames, None] * (target_xy[frames] - a[frames, :2])
            goals[side] = (frames, goal)
    return place_ankles(motion, parts, goals)


def place_ankles(motion: Motion, parts: BodyPartMap,
                 goals: Mapping[str, tuple[NDArray[np.int64], F64]],
                 keep_bend: bool = False) -> Motion:  # fmt: skip
    """``motion`` with each leg's ankle (``goals`` by side, ``"l"``/``"r"``: frames and their
    goals ``(n, 3)``) moved onto its goal by turning the hip and knee (two-bone IK, the knee
    in the plane of its bend toward the goal, or with ``keep_bend`` the bend's direction from
    its hip-ankle line kept; the foot keeping its world turn; a goal out of reach is
    approached along the line to it). Legs whose knee is not the hip's child or whose ankle
    is not the knee's child are left as they are."""
    skel = motion.skeleton
    pos, rot = motion.forward_kinematics()
    local = np.array(motion.rotations)
    changed = False
    for side, (frames, goal) in goals.items():
        hip, knee, ankle = (parts.joint_of(f"{side}_{p}") for p in ("thigh", "shin", "foot"))
        if skel.parents[knee] != hip or skel.parents[ankle] != knee or frames.size == 0:
            continue
        changed = True
        h, k, a = pos[frames, hip], pos[frames, knee], pos[frames, ankle]
        la = np.linalg.norm(k - h, axis=-1)
        lb = np.linalg.norm(a - k, axis=-1)
        c = np.clip(np.linalg.norm(goal - h, axis=-1), np.abs(la - lb) + 1e-6, la + lb - 1e-6)
        u = unit_rows(goal - h)
        bend = k - h
        if keep_bend:
            # the knee bends the way it bent (its offset from the hip-ankle line, made
            # perpendicular to the new one): a goal far from the ankle, passing under the hip,
            # does not flip it
            u0 = unit_rows(a - h)
            bend = bend - u0 * np.sum(bend * u0, axis=-1, keepdims=True)
        # knee stays in the plane of the bend
        v = unit_rows(bend - u * np.sum(bend * u, axis=-1, keepdims=True))
        cos_a = np.clip((la**2 + c**2 - lb**2) / (2 * la * c), -1.0, 1.0)
        knee_new = h + la[:, None] * (cos_a[:, None] * u + np.sqrt(1 - cos_a**2)[:, None] * v)
        # hip: turn the thigh onto the new knee; knee: turn the shin onto the goal
        q_hip = quat_mul(_arc(unit_rows(k - h), unit_rows(knee_new - h)), rot[frames, hip])
        a_moved = knee_new + quat_rotate(q_hip, quat_rotate(quat_conj(rot[frames, hip]), a - k))
        shin_rot = quat_mul(q_hip, quat_mul(quat_conj(rot[frames, hip]), rot[frames, knee]))
        q_knee = quat_mul(_arc(unit_rows(a_moved - knee_new), unit_rows(goal - knee_new)), shin_rot)
        parent = skel.parents[hip]
        g_parent = rot[frames, parent] if parent >= 0 else np.tile([1.0, 0, 0, 0], (frames.size, 1))
        local[frames, hip] = quat_mul(quat_conj(g_parent), q_hip)
        local[frames, knee] = quat_mul(quat_conj(q_hip), q_knee)
        local[frames, ankle] = quat_mul(
            quat_conj(q_knee), rot[frames, ankle]
        )  # foot keeps its turn
    return motion.replace(rotations=local) if changed else motion
