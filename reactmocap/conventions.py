"""The conventions glossary. Every module converts at its boundary with these names.

* World: right-handed, **Z up**, metres, seconds. Angles are radians inside the code and degrees
  only at user-facing edges (BVH files, TOML files, CLI flags).
* Quaternions are ``(w, x, y, z)`` like MuJoCo. scipy uses ``(x, y, z, w)``: convert with
  :func:`reactmocap.rotations.rotation_from_wxyz` / :func:`reactmocap.rotations.wxyz_from_rotation`.
* Arrays: a motion is ``(T, J, 4)`` local rotations and ``(T, 3)`` root positions.
* Facing: a character's heading is the twist about +Z (radians from +X, counter-clockwise) of its
  anatomical body frame, fixed to the pelvis: up = pelvis to chest, left = right to left thigh
  joint, forward = left x up (:func:`reactmocap.library.placement.heading`; the search uses the
  same). Unlike a projected forward axis it stays defined when the character lies down.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "UNIT_SCALE",
    "UpAxis",
    "Unit",
    "axes_to_z_up",
    "detect_unit",
    "z_up_to_axes",
]

UpAxis = Literal["y", "z"]
Unit = Literal["m", "cm", "mm", "in"]

#: metres per source unit
UNIT_SCALE: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}

# Rotation that takes Y-up coordinates (x right, y up, z toward the viewer) to Z-up:
# +90 deg about X sends y -> z and z -> -y.
_Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def axes_to_z_up(up: UpAxis) -> NDArray[np.float64]:
    """3x3 rotation taking vectors in a file's ``up`` convention to the internal Z-up frame."""
    if up == "y":
        return _Y_UP_TO_Z_UP.copy()
    if up == "z":
        return np.eye(3)
    raise ValueError(f"up axis must be 'y' or 'z', got {up!r}")


def z_up_to_axes(up: UpAxis) -> NDArray[np.float64]:
    """Inverse of :func:`axes_to_z_up`."""
    return axes_to_z_up(up).T.copy()


def detect_unit(extent: float) -> Unit:
    """Guess a file's length unit from a body's largest joint-to-joint span in file units.

    Human spans (fingertip or head to toe) are 1-2.5 m: < 3 reads as metres, < 110 as inches
    (a 1.75 m body spans about 70 in), < 1000 as centimetres, else millimetres.
    """
    if not np.isfinite(extent) or extent <= 0:
        return "cm"
    if extent < 3.0:
        return "m"
    if extent < 110.0:
        return "in"
    if extent < 1000.0:
        return "cm"
    return "mm"
