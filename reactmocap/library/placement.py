"""Where a character stands and faces: heading from the hips, and placing a clip in the world.

Heading (yaw about +Z, from +X counter-clockwise) comes from the hip axis: the horizontal
direction from the right thigh joint to the left one, turned -90 degrees, is "forward". This
works for any mapped skeleton whatever its rest pose or local axes.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from reactmocap.library.bodyparts import BodyPartMap
from reactmocap.library.motion import Motion

__all__ = ["heading", "place"]


def heading(
    motion: Motion, parts: BodyPartMap, positions: NDArray[np.float64] | None = None
) -> NDArray[np.float64]:
    """``(T,)`` heading in radians. ``positions`` may pass precomputed FK positions."""
    pos = motion.global_positions() if positions is None else positions
    left = pos[:, parts.joint_of("l_thigh")] - pos[:, parts.joint_of("r_thigh")]
    # forward = left x up, in the ground plane
    return np.arctan2(-left[:, 0], left[:, 1])


def place(
    motion: Motion,
    parts: BodyPartMap,
    frame: int,
    facing: float,
    position: tuple[float, float] | NDArray[np.float64],
) -> Motion:
    """Rotate and shift ``motion`` about +Z so that at ``frame`` the character faces ``facing``
    (radians) with its pelvis over ``position`` (x, y). Height is untouched."""
    pos = motion.global_positions()
    yaw = float(facing - heading(motion.slice(frame, frame + 1), parts, pos[frame : frame + 1])[0])
    c, s = np.cos(yaw), np.sin(yaw)
    pelvis = pos[frame, parts.joint_of("pelvis"), :2]
    rotated = np.array([c * pelvis[0] - s * pelvis[1], s * pelvis[0] + c * pelvis[1]])
    shift = np.asarray(position, dtype=np.float64) - rotated
    return motion.transformed(yaw, (shift[0], shift[1], 0.0))
