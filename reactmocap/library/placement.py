"""Where a character stands and faces: the anatomical body frame, the heading derived from it, and
placing a clip in the world. The search uses the same heading, so a placed clip and a search
match agree on which way a character faces.

Heading (radians about +Z, from +X counter-clockwise) is the twist about world +Z of the body
frame ``q_pelvis(t) * B`` (:func:`body_frame`); it stays defined when the character lies down.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import BodyPartMappingError
from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import Skeleton
from reactmocap.rotations import (
    quat_conj,
    quat_from_matrix,
    quat_from_yaw,
    quat_mul,
    quat_rotate,
    quat_yaw,
)

__all__ = ["body_frame", "body_heading", "ground_root", "heading", "place", "rest_pose"]

F64 = NDArray[np.float64]


def rest_pose(skeleton: Skeleton) -> tuple[F64, F64]:
    """Global joint positions ``(J, 3)`` and rotations ``(J, 4)`` with every local rotation
    identity (the skeleton's offsets as they stand)."""
    rot = np.zeros((1, skeleton.num_joints, 4))
    rot[..., 0] = 1.0
    pos, grot = Motion(skeleton, 30.0, np.zeros((1, 3)), rot).forward_kinematics()
    return pos[0], grot[0]


def body_frame(skeleton: Skeleton, parts: BodyPartMap) -> F64:
    """The anatomical body frame ``B`` (wxyz) in the pelvis joint's local frame.

    In the rest pose: ``up`` = pelvis -> chest, ``left`` = right thigh joint -> left thigh joint
    made orthogonal to ``up``, ``forward = left x up``. Stored pelvis-local, it is body-fixed
    whatever the rest pose and the joints' local axes look like.

    Raises:
        BodyPartMappingError: a required part is unmapped, or the rest pose does not define the
            frame (pelvis on the chest, thighs together or in line with the spine).
    """
    pos, grot = rest_pose(skeleton)
    pelvis = parts.joint_of("pelvis")
    up = pos[parts.joint_of("chest")] - pos[pelvis]
    left = pos[parts.joint_of("l_thigh")] - pos[parts.joint_of("r_thigh")]
    if np.linalg.norm(up) < 1e-6 or np.linalg.norm(left) < 1e-6:
        raise BodyPartMappingError("degenerate rest pose: no pelvis frame (joints coincide)")
    z = up / np.linalg.norm(up)
    y = left - np.dot(left, z) * z
    if np.linalg.norm(y) < 1e-6:
        raise BodyPartMappingError("degenerate rest pose: thighs are collinear with the spine")
    y /= np.linalg.norm(y)
    world = quat_from_matrix(np.stack([np.cross(y, z), y, z], axis=1))
    return quat_mul(quat_conj(grot[pelvis]), world)


def body_heading(pelvis_rotations: NDArray[np.floating[Any]], frame: F64) -> F64:
    """Heading (radians) of the body frame ``pelvis_rotations * frame``: its twist about +Z.
    ``pelvis_rotations`` are the pelvis joint's global rotations ``(..., 4)``."""
    return quat_yaw(quat_mul(np.asarray(pelvis_rotations, dtype=np.float64), frame))


def heading(motion: Motion, parts: BodyPartMap) -> F64:
    """``(T,)`` heading of ``motion`` in radians, in ``[-pi, pi)``."""
    _, grot = motion.forward_kinematics()
    return body_heading(grot[:, parts.joint_of("pelvis")], body_frame(motion.skeleton, parts))


def place(
    motion: Motion,
    parts: BodyPartMap,
    frame: int,
    facing: float,
    position: tuple[float, float] | NDArray[np.float64],
) -> Motion:
    """Rotate and shift ``motion`` about +Z so that at ``frame`` the character faces ``facing``
    (radians) with its pelvis over ``position`` (x, y). Height is untouched."""
    pos, grot = motion.slice(frame, frame + 1).forward_kinematics()
    pelvis = parts.joint_of("pelvis")
    yaw = float(facing - body_heading(grot[0, pelvis], body_frame(motion.skeleton, parts)))
    c, s = np.cos(yaw), np.sin(yaw)
    px, py = pos[0, pelvis, :2]
    shift = np.asarray(position, dtype=np.float64) - (c * px - s * py, s * px + c * py)
    return motion.transformed(yaw, (shift[0], shift[1], 0.0))


def ground_root(motion: Motion, parts: BodyPartMap, *, turn: bool = True) -> Motion:
    """``motion`` with a dummy top joint above the pelvis (e.g. Bandai's ``joint_Root``) on the
    ground under the pelvis, turned to the body's heading: the root path game engines extract
    follows the body smoothly and never jumps, whatever clips were stitched or blended. Every
    other joint keeps its world transform (the pelvis's local transform absorbs the change).
    ``turn=False`` leaves the dummy root unturned, so the pelvis's local rotation is its world
    one: blend in that form (a lying body's heading is arbitrary, and slerping the root's yaw
    and the pelvis's local rotation separately would swing the pelvis), then ground again.
    Motions whose top joint is the pelvis, or whose pelvis has no per-frame translation to
    absorb it, come back unchanged."""
    skel = motion.skeleton
    pelvis = parts.joint_of("pelvis")
    if pelvis == 0 or motion.translations is None or int(skel.parents[pelvis]) != 0:
        return motion
    pos, grot = motion.forward_kinematics()
    yaw = (np.unwrap(body_heading(grot[:, pelvis], body_frame(skel, parts))) if turn
           else np.zeros(motion.num_frames))  # fmt: skip
    root_q = quat_from_yaw(yaw)
    root_p = np.column_stack([pos[:, pelvis, :2], np.zeros(motion.num_frames)])
    inv = quat_conj(root_q)
    rot = np.array(motion.rotations)
    tr = np.array(motion.translations)
    rot[:, 0] = root_q
    rot[:, pelvis] = quat_mul(inv, grot[:, pelvis])
    tr[:, pelvis] = quat_rotate(inv, pos[:, pelvis] - root_p)
    return motion.replace(root_positions=root_p, rotations=rot, translations=tr)
