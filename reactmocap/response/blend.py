"""Blends of the response pipeline (Zordan et al. 2005, section 4), as pure Motion operations.

* :func:`transition_weights`: the desired-pose schedule of Simulation 2: hold for the reaction
  delay, then ease-in/ease-out (smoothstep) to 1 at the end of the transition.
* :func:`blend_poses`: per-joint slerp and root/translation lerp between two same-skeleton
  motions with a per-frame weight.
* :func:`final_blend`: the paper's final blend: the remaining root position error is
  distributed by a linearly growing root offset, joints are slerped with a linear weight, so the
  result equals the target exactly at the last frame.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from reactmocap.errors import MotionError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_slerp_path

__all__ = ["blend_poses", "final_blend", "smoothstep", "transition_weights"]

F64 = NDArray[np.float64]


def smoothstep(x: ArrayLike) -> F64:
    """Ease-in/ease-out on [0, 1]: 3x^2 - 2x^3, zero slope at both ends."""
    u = np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def transition_weights(times: ArrayLike, start: float, delay: float, end: float) -> F64:
    """Weight of the target clip at ``times``: 0 until ``start + delay``, smoothstep to 1 at
    ``end``, 1 afterwards. If the delay outlasts the transition, the weight jumps at ``end``."""
    t = np.asarray(times, dtype=np.float64)
    move = start + delay
    if end <= move:
        return (t >= end).astype(np.float64)
    return smoothstep((t - move) / (end - move))


def _check_pair(a: Motion, b: Motion) -> None:
    if not a.skeleton.same_structure(b.skeleton):
        raise MotionError(f"cannot blend {a.name!r} and {b.name!r}: different skeletons")
    if a.num_frames != b.num_frames:
        raise MotionError(f"cannot blend {a.num_frames} frames with {b.num_frames} frames")


def blend_poses(a: Motion, b: Motion, weights: ArrayLike, joint_weights: ArrayLike | None = None
                ) -> Motion:  # fmt: skip
    """Frame-wise blend from ``a`` (weight 0) to ``b`` (weight 1): slerp of every local rotation
    (root orientation included; one arc per joint over the frames), lerp of root positions and local translations. With
    ``joint_weights`` ``(T, J)`` the rotations take those instead of the frame weights."""
    _check_pair(a, b)
    w = np.asarray(weights, dtype=np.float64).reshape(-1)
    if w.shape != (a.num_frames,):
        raise MotionError(f"need {a.num_frames} weights, got {w.shape[0]}")
    wj = w[:, None] if joint_weights is None else np.asarray(joint_weights, dtype=np.float64)
    if joint_weights is not None and wj.shape != (a.num_frames, a.num_joints):
        raise MotionError(f"joint weights must be {(a.num_frames, a.num_joints)}, got {wj.shape}")
    rot = quat_slerp_path(a.rotations, b.rotations, wj)  # no jump when a spin passes half a turn
    root = a.root_positions + w[:, None] * (b.root_positions - a.root_positions)
    tr = None
    if a.translations is not None or b.translations is not None:
        ta, tb = a.local_translations(), b.local_translations()
        tr = ta + w[:, None, None] * (tb - ta)
    return a.replace(root_positions=root, rotations=rot, translations=tr)


def final_blend(simulated: Motion, target: Motion, joint_start: ArrayLike | None = None,
                root_start: float = 0.0) -> Motion:  # fmt: skip
    """Land ``simulated`` exactly on ``target`` at the last frame.

    Both cover the same transition frames. The root error at the end is spread by a root offset
    growing linearly from 0 to the full error; every joint is slerped toward the target with the
    same linear weight, so the first frame is the simulation and the last is the target.
    ``joint_start`` ``(J,)`` delays a joint's slerp and ``root_start`` the root offset: each
    starts at that frame and still ends on the target (e.g. a body still touching the other
    character keeps its simulated pose and place).
    """
    _check_pair(simulated, target)
    n = simulated.num_frames
    i = np.arange(n, dtype=np.float64)
    w = np.linspace(0.0, 1.0, n) if n > 1 else np.ones(1)
    offset = target.root_positions[-1] - simulated.root_positions[-1]
    wj = None
    if joint_start is not None and n > 1:
        start = np.clip(np.asarray(joint_start, dtype=np.float64), 0.0, n - 2.0)
        wj = np.clip((i[:, None] - start[None]) / (n - 1.0 - start[None]), 0.0, 1.0)
    out = blend_poses(simulated, target, w, wj)
    wr = w
    if root_start > 0 and n > 1:
        r0 = min(float(root_start), n - 2.0)
        wr = np.clip((i - r0) / (n - 1.0 - r0), 0.0, 1.0)
    root = simulated.root_positions + wr[:, None] * offset
    return out.replace(root_positions=root)
