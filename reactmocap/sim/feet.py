"""A character's feet: sole boxes, their corners, and which soles touch the floor."""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError
from reactmocap.rotations import einsum
from reactmocap.sim.character import SIM_BODIES
from reactmocap.sim.world import World

__all__ = ["FEET", "foot_soles", "sole_corners_world"]

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
    rot = d.geom_xmat[sole].reshape(2, 3, 3)
    return einsum("fij,fkj->fki", rot, corners) + d.geom_xpos[sole][:, None]
