"""Transition-quality metrics, defined once and reused by the response report and by batch
regression. Every function takes Motions (Z-up metres) and returns a float in the stated unit."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_conj, quat_log, quat_mul

__all__ = [
    "REACTION_WINDOW_S",
    "WARN_ATTACKER_FOOT_SKATE_M",
    "WARN_ATTACKER_LIFT_M",
    "WARN_ATTACKER_SPEED_RATIO",
    "WARN_JOINT_CORRECTION_RAD",
    "WARN_OVERLAP_M",
    "WARN_ROOT_OFFSET_M",
    "WARN_ROOT_TURN_RAD",
    "blend_correction_over_warning",
    "blend_joint_correction_max_rad",
    "direction_error_deg",
    "blend_root_offset_max_m",
    "blend_root_turn_max_rad",
    "fell",
    "foot_skate_m",
    "intended_fall",
    "joint_speed_max_m_s",
    "lift_above_source_m",
    "match_distance",
    "penetration_max_m",
    "planted",
    "reaction_displacement",
    "speed_ratio",
    "stitch_velocity_jump_rad_s",
]

#: a foot point counts as planted below this height above its lowest height in the motion (m)
PLANT_HEIGHT_M = 0.03
#: ... and below this horizontal speed (m/s)
PLANT_SPEED_M_S = 0.5
#: fallen when the pelvis is below this fraction of its first-frame height
FALL_FRACTION = 0.5


def match_distance(distance: float) -> float:
    """The paper's window distance ``D`` of the chosen match (weighted metres + radians)."""
    return float(distance)


def blend_root_offset_max_m(simulated: Motion, blended: Motion, parts: BodyPartMap) -> float:
    """Largest pelvis displacement the final blend applied (m): how far Simulation 2 ended from
    the found clip on its own. 0 means the simulation landed exactly."""
    p = parts.joint_of("pelvis")
    d = blended.global_positions()[:, p] - simulated.global_positions()[:, p]
    return float(np.max(np.linalg.norm(d, axis=-1)))


def _blend_turns(simulated: Motion, blended: Motion) -> NDArray[np.float64]:
    """``(T, J)`` local rotation (rad) the final blend applied to each joint (joint 0: the
    root's orientation in the world)."""
    rel = quat_mul(quat_conj(simulated.rotations), blended.rotations)
    return np.linalg.norm(quat_log(rel), axis=-1)


def blend_joint_correction_max_rad(simulated: Motion, blended: Motion) -> float:
    """Largest local rotation (rad) the final blend applied to a joint of the skeleton, over
    frames; the root's orientation is :func:`blend_root_turn_max_rad`."""
    return float(np.max(_blend_turns(simulated, blended)[:, 1:], initial=0.0))


def blend_root_turn_max_rad(simulated: Motion, blended: Motion) -> float:
    """Largest turn (rad) of the root's world orientation the final blend applied, over
    frames: with :func:`blend_root_offset_max_m`, how far the whole body was moved."""
    return float(np.max(_blend_turns(simulated, blended)[:, 0]))


def stitch_velocity_jump_rad_s(motion: Motion, seams: Sequence[int]) -> float:
    """Largest change (rad/s) of any joint's local angular velocity across the given seam
    frames (the first frame of each new segment), from one-sided finite differences."""
    if motion.num_frames < 3 or not seams:
        return 0.0
    q = motion.rotations
    w = quat_log(quat_mul(q[1:], quat_conj(q[:-1]))) * motion.fps  # w[i]: frame i -> i+1
    jumps = [
        float(np.max(np.linalg.norm(w[s] - w[s - 1], axis=-1)))
        for s in seams
        if 1 <= s < motion.num_frames - 1
    ]
    return max(jumps, default=0.0)


def _foot_points(motion: Motion, parts: BodyPartMap) -> np.ndarray:
    idx = [parts.joint_of(p) for p in ("l_foot", "r_foot", "l_toe", "r_toe") if p in parts.joints]
    return motion.global_positions()[:, idx]


def planted(points: NDArray[np.float64], fps: float) -> NDArray[np.bool_]:
    """``(T - 1, P)`` whether each point of ``points`` ``(T, P, 3)`` is planted on each frame
    pair: within ``PLANT_HEIGHT_M`` of its lowest height in the motion on both frames and
    moving slower than ``PLANT_SPEED_M_S``."""
    low = points[..., 2] <= points[..., 2].min(axis=0) + PLANT_HEIGHT_M
    step = np.linalg.norm(np.diff(points[..., :2], axis=0), axis=-1)
    return np.asarray(low[1:] & low[:-1] & (step * fps < PLANT_SPEED_M_S))


def foot_skate_m(motion: Motion, parts: BodyPartMap) -> float:
    """Horizontal travel (m) of the foot and toe joints while :func:`planted`, summed over the
    motion (a point sliding faster than ``PLANT_SPEED_M_S`` counts as moving, not skating)."""
    p = _foot_points(motion, parts)
    if p.shape[0] < 2:
        return 0.0
    step = np.linalg.norm(np.diff(p[..., :2], axis=0), axis=-1)
    return float(np.sum(step[planted(p, motion.fps)]))


def penetration_max_m(motion: Motion) -> float:
    """Deepest joint or end site below the ground plane z=0 (m, >= 0). Joints and end sites
    stand in for the body surface since metrics do not know the collision geometry."""
    pos = np.concatenate([motion.global_positions(), motion.end_site_positions()], axis=1)
    return float(max(0.0, -pos[..., 2].min()))


def _pelvis_height(motion: Motion, parts: BodyPartMap) -> np.ndarray:
    return motion.global_positions()[:, parts.joint_of("pelvis"), 2]


def fell(motion: Motion, parts: BodyPartMap, reference_height: float | None = None) -> bool:
    """Whether the pelvis drops below ``FALL_FRACTION`` of ``reference_height`` (default: its
    first-frame height) at any frame."""
    h = _pelvis_height(motion, parts)
    ref = h[0] if reference_height is None else reference_height
    return bool(np.min(h) < FALL_FRACTION * ref)


def intended_fall(found_clip: Motion, parts: BodyPartMap, from_frame: int = 0) -> bool:
    """Whether the found clip itself falls from its matched frame on (pelvis below
    ``FALL_FRACTION`` of its standing height, taken as the clip's highest pelvis height)."""
    h = _pelvis_height(found_clip, parts)
    return bool(np.min(h[from_frame:]) < FALL_FRACTION * np.max(h))


#: how long after the impact the reaction is measured (s)
REACTION_WINDOW_S = 0.6


def _chest_xy(motion: Motion, parts: BodyPartMap) -> NDArray[np.float64]:
    return motion.global_positions()[:, parts.joint_of("chest"), :2]


def reaction_displacement(
    output: Motion, undisturbed: Motion, parts: BodyPartMap, impact_frame: int,
    seconds: float = REACTION_WINDOW_S,
) -> NDArray[np.float64]:  # fmt: skip
    """``(2,)`` the largest horizontal chest displacement (m, world x/y) of ``output`` against
    ``undisturbed`` (the recipient's own clip over the same frames) in the ``seconds`` after
    ``impact_frame``: the reaction itself, zero when the character does nothing."""
    n = min(output.num_frames, undisturbed.num_frames)
    a = min(max(impact_frame, 0), n - 1)
    b = min(n, a + int(round(seconds * output.fps)) + 1)
    d = _chest_xy(output, parts)[a:b] - _chest_xy(undisturbed, parts)[a:b]
    return np.asarray(d[int(np.argmax(np.linalg.norm(d, axis=1)))], dtype=np.float64)


def direction_error_deg(displacement: ArrayLike, impulse: ArrayLike) -> float:
    """Angle (deg) between a horizontal displacement and the horizontal part of an impulse;
    NaN when either is zero (no direction to compare)."""
    a = np.asarray(displacement, dtype=np.float64)[:2]
    b = np.asarray(impulse, dtype=np.float64)[:2]
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na < 1e-9 or nb < 1e-9:
        return float("nan")
    return float(np.degrees(np.arccos(np.clip(a @ b / (na * nb), -1.0, 1.0))))


def joint_speed_max_m_s(motion: Motion) -> float:
    """Fastest joint (or end site) of ``motion`` (m/s), from frame-to-frame displacements."""
    if motion.num_frames < 2:
        return 0.0
    pos = np.concatenate([motion.global_positions(), motion.end_site_positions()], axis=1)
    return float(np.linalg.norm(np.diff(pos, axis=0), axis=-1).max() * motion.fps)


def speed_ratio(output: Motion, source: Motion) -> float:
    """``output``'s fastest joint over ``source``'s (e.g. the attacker's output against its
    source clip): above 1 means the output moves a joint faster than the capture ever did."""
    return joint_speed_max_m_s(output) / max(joint_speed_max_m_s(source), 1e-9)


def lift_above_source_m(output: Motion, source: Motion, parts: BodyPartMap) -> float:
    """How far (m, >= 0) ``output``'s lowest body joint ever rises above the highest that
    ``source``'s lowest body joint gets (its jumps and flights): a body held or blended in the
    air, off the floor, where its capture never is. A dummy top joint above the pelvis (on the
    floor by construction) is not a body joint."""
    body = slice(1, None) if parts.joint_of("pelvis") != 0 else slice(None)
    out = output.global_positions()[:, body, 2].min(axis=1).max()
    src = source.global_positions()[:, body, 2].min(axis=1).max()
    return max(float(out - src), 0.0)


#: report warnings fire above these (the report's ``warnings`` list; ``respond --strict``)
WARN_OVERLAP_M = 0.02
WARN_ROOT_OFFSET_M = 0.3
WARN_JOINT_CORRECTION_RAD = 0.6
#: the root's turn warns where a joint's does (before the two were separate fields, one number
#: covered both)
WARN_ROOT_TURN_RAD = WARN_JOINT_CORRECTION_RAD
WARN_ATTACKER_SPEED_RATIO = 1.5
#: the attacker's ``foot_skate_m`` warns above the recipient's own in 9 of 10 runs of the
#: real-recipient benchmark (p90 0.32-0.34 m in both modes, 2026-12-02; docs/benchmarks.md)
WARN_ATTACKER_FOOT_SKATE_M = 0.3
#: the attacker's ``lift_above_source_m`` warns above this: a body lying on the floor has its
#: lowest joint up to ~0.15 m up (half its thickness), so 0.25 m over the clip's highest is off
#: the floor
WARN_ATTACKER_LIFT_M = 0.25


def blend_correction_over_warning(simulated: Motion, blended: Motion, parts: BodyPartMap) -> float:
    """The final blend's largest joint turn, root turn and root offset, each over its warning
    threshold, the largest of the three (<= 1: the blend warns of none)."""
    turns = _blend_turns(simulated, blended)
    return max(float(np.max(turns[:, 1:], initial=0.0)) / WARN_JOINT_CORRECTION_RAD,
               float(np.max(turns[:, 0])) / WARN_ROOT_TURN_RAD,
               blend_root_offset_max_m(simulated, blended, parts) / WARN_ROOT_OFFSET_M)  # fmt: skip
