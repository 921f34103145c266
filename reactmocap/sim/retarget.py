"""Retarget a Motion onto another skeleton through the 16 simulated bodies both map to.

Why here and not in ``library``: the mapping runs on the physics characters (their bodies are
the common vocabulary of every mapped skeleton), and no listed library retargets between
arbitrary BVH hierarchies with different rest poses.

How: each body gets an *anatomical frame*, built from its character's reference pose: x along
the bone (toward its child body; leaves use their parent's bone, feet the facing direction),
y from the first of (left, forward, up) of the character that is not nearly parallel to x,
chosen the same for both characters. Stored in body coordinates, ``B = R_ref^T A``. A source
body rotation ``R`` maps to ``R' = R B_src B_tgt^T`` on the target, so every bone points the
same way in the world as in the source; the pelvis path is scaled by the leg-length ratio.
Joints the target does not simulate (fingers, toes, clavicles) keep the target's reference
pose. Twist about a bone follows the y-axis choice and is the least certain part.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import MotionError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_from_matrix, quat_normalize, quat_to_matrix
from reactmocap.sim.character import SIM_BODIES, Character, build_character

__all__ = ["Retargeter", "retarget"]

F64 = NDArray[np.float64]
_IDX = {b: i for i, b in enumerate(SIM_BODIES)}
# the body whose origin each body's bone points to (None: a leaf)
_CHILD = {
    "pelvis": "chest", "waist": "chest", "chest": "head", "head": None,
    "l_upper_arm": "l_forearm", "l_forearm": "l_hand", "l_hand": None,
    "r_upper_arm": "r_forearm", "r_forearm": "r_hand", "r_hand": None,
    "l_thigh": "l_shin", "l_shin": "l_foot", "l_foot": None,
    "r_thigh": "r_shin", "r_shin": "r_foot", "r_foot": None,
}  # fmt: skip
_LEAF_PARENT = {"head": "chest", "l_hand": "l_forearm", "r_hand": "r_forearm"}


def _unit(v: F64) -> F64:
    n = np.linalg.norm(v)
    if n < 1e-9:
        raise MotionError("degenerate reference pose: two body origins coincide")
    return v / n


def _reference_pose(ch: Character) -> tuple[F64, F64]:
    """World body positions ``(16, 3)`` and rotations ``(16, 4)`` of the reference pose (the
    ball joints are identity there by construction)."""
    moved = np.any(np.abs(ch.ref_translations - ch.skeleton.offsets) > 1e-12)
    trans = ch.ref_translations[None] if moved else None
    ref = Motion(ch.skeleton, 30.0, ch.ref_root[None], ch.ref_rotations[None], trans)
    qpos = ch.qpos_from_motion(ref)
    pos, rot = ch.body_transforms_from_qpos(qpos)
    return pos[0], rot[0]


def _axes(pos: F64) -> tuple[dict[str, F64], dict[str, F64]]:
    """Primary (bone) direction per body and the character's left/forward/up (world)."""
    i = _IDX
    left = _unit(pos[i["l_thigh"]] - pos[i["r_thigh"]])
    up = _unit(pos[i["chest"]] - pos[i["pelvis"]])
    up = _unit(up - left * (up @ left))
    forward = np.cross(left, up)
    prim: dict[str, F64] = {}
    for b in SIM_BODIES:
        child = _CHILD[b]
        if child is not None:
            prim[b] = _unit(pos[i[child]] - pos[i[b]])
    for leaf, parent in _LEAF_PARENT.items():
        prim[leaf] = prim[parent]
    prim["l_foot"] = prim["r_foot"] = forward
    return prim, {"left": left, "forward": forward, "up": up}


class Retargeter:
    """Maps motions of ``source`` skeleton onto ``target``'s, both given as Characters (their
    reference poses define the anatomical frames; build them from standing frames)."""

    def __init__(self, source: Character, target: Character) -> None:
        self.source = source
        self.target = target
        (ps, rs), (pt, rt) = _reference_pose(source), _reference_pose(target)
        prim_s, ax_s = _axes(ps)
        prim_t, ax_t = _axes(pt)
        b_src = np.empty((len(SIM_BODIES), 3, 3))
        b_tgt = np.empty((len(SIM_BODIES), 3, 3))
        for k, b in enumerate(SIM_BODIES):  # once per pair of skeletons
            name = next(
                n for n in ("left", "forward", "up")
                if abs(prim_s[b] @ ax_s[n]) < 0.8 and abs(prim_t[b] @ ax_t[n]) < 0.8
            )  # fmt: skip
            for out, prim, ax, rot in ((b_src, prim_s, ax_s, rs), (b_tgt, prim_t, ax_t, rt)):
                x = prim[b]
                y = _unit(ax[name] - x * (ax[name] @ x))
                frame = np.column_stack([x, y, np.cross(x, y)])
                out[k] = quat_to_matrix(rot[k]).T @ frame
        self._offset = np.einsum("kij,klj->kil", b_src, b_tgt)  # B_src B_tgt^T
        leg = lambda ch: float(  # noqa: E731
            np.linalg.norm(ch.body_pos[_IDX["l_shin"]])
            + np.linalg.norm(ch.body_pos[_IDX["l_foot"]])
        )
        self.scale = leg(target) / leg(source)

    def __call__(self, motion: Motion, name: str | None = None) -> Motion:
        """``motion`` (on the source skeleton) as a Motion on the target skeleton."""
        qpos = self.source.qpos_from_motion(motion)
        pos, rot = self.source.body_transforms_from_qpos(qpos)
        mats = quat_to_matrix(rot) @ self._offset[None]
        quat = quat_normalize(quat_from_matrix(mats))
        out_pos = np.zeros_like(pos)
        out_pos[:, 0] = pos[:, 0] * self.scale
        return self.target.motion_from_body_transforms(
            out_pos, quat, motion.fps, name=motion.name if name is None else name
        )


def retarget(
    motion: Motion, target: Motion, target_frame: int = 0, source_frame: int = 0
) -> Motion:
    """``motion`` retargeted onto ``target``'s skeleton; the two frames are the standing
    reference poses that define each side's anatomical frames."""
    src = build_character(motion, frame=source_frame)
    tgt = build_character(target, frame=target_frame)
    return Retargeter(src, tgt)(motion)
