"""A character's feet: sole boxes, their corners, and which soles touch the floor."""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError
from reactmocap.rotations import einsum
from reactmocap.sim.character import SIM_BODIES
from reactmocap.sim.world import World

__all__ = ["FEET", "SoleCorners", "foot_soles", "sole_corners_world"]

F64 = NDArray[np.float64]
#: the two foot bodies, left then right (index 0 and 1 everywhere a foot is numbered)
FEET = ("l_foot", "r_foot")
_SIGNS = np.array([[1, 1], [1, -1], [-1, 1], [-1, -1]], dtype=np.float64)


def foot_soles(
    world: World, character: int, who: str
) -> tuple[NDArray[np.int64], NDArray[np.int64], F64]:
    """A character's feet: body ids ``(2,)``, sole box geoms ``(2,)`` and the four sole corners
    of each box in the box frame ``(2, 4, 3)``. ``who`` names the caller in the error."""
    m = world.model
    wc = world.characters[character]
    feet = np.array([wc.body_ids[SIM_BODIES.index(f)] for f in FEET])
    sole = wc.sole_ids
    if sole.shape != (2,) or np.any(m.geom_type[sole] != mujoco.mjtGeom.mjGEOM_BOX):
        raise ConfigError(f"{who} needs a sole box geom per foot")
    corners = np.stack(
        [np.column_stack([_SIGNS * h[:2], np.full(4, -h[2])]) for h in m.geom_size[sole]]
    )
    return feet, sole, corners


def sole_corners_world(d: mujoco.MjData, sole: NDArray[np.int64], corners: F64) -> F64:
    """``(2, 4, 3)`` world positions of the sole corners from :func:`foot_soles`."""
    return SoleCorners(d, sole, corners)()


class SoleCorners:
    """:func:`sole_corners_world` for one MjData, with its arrays read once and buffers made
    once; each call returns a new ``(2, 4, 3)`` array (the one place the corners' formula
    lives). For a per-tick caller whose MjData lives as long as it does."""

    def __init__(self, d: mujoco.MjData, sole: NDArray[np.int64], corners: F64) -> None:
        self._xmat, self._xpos = d.geom_xmat, d.geom_xpos
        self._sole, self._corners = sole, corners
        self._rot = np.empty((len(sole), 9))
        self._rot3 = self._rot.reshape(len(sole), 3, 3)
        self._pos = np.empty((len(sole), 3))
        self._pos_col = self._pos[:, None]
        self._local = np.empty(corners.shape)

    def __call__(self) -> F64:
        self._xmat.take(self._sole, 0, out=self._rot)
        einsum("fij,fkj->fki", self._rot3, self._corners, out=self._local)
        self._xpos.take(self._sole, 0, out=self._pos)
        return self._local + self._pos_col
