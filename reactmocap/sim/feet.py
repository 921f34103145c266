"""A character's feet: sole boxes, their corners, and which soles touch the floor."""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError
from reactmocap.rotations import quat_conj, quat_rotate
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
    of each box in the box frame ``(2, 4, 3)``; a sole split at the ball (``forefoot``) has six,
    its two ends' corners and, between them, the ball line's ``(2, 6, 3)``. ``who`` names the
    caller in the error."""
    m = world.model
    wc = world.characters[character]
    feet = np.array([wc.body_ids[SIM_BODIES.index(f)] for f in FEET])
    sole = wc.sole_ids
    if sole.shape != (2,) or np.any(m.geom_type[sole] != mujoco.mjtGeom.mjGEOM_BOX):
        raise ConfigError(f"{who} needs a sole box geom per foot")
    corners = np.stack(
        [np.column_stack([_SIGNS * h[:2], np.full(4, -h[2])]) for h in m.geom_size[sole]]
    )
    if wc.sole_contacts.shape[1] == 2:  # split at the ball: the toe's tip, the ball line
        tip = _in_sole(m, sole, wc.sole_contacts[:, 1], 1.0)
        ball = _in_sole(m, sole, wc.sole_contacts[:, 0], 1.0)
        import os

        if os.environ.get("RM_PLAN") == "heel":  # EXPERIMENT
            corners = np.concatenate([ball, corners[:, 2:]], axis=1)
        else:
            corners = np.concatenate([tip, ball, corners[:, 2:]], axis=1)
    return feet, sole, corners


def _in_sole(m: mujoco.MjModel, sole: NDArray[np.int64], geoms: NDArray[np.int64], x: float) -> F64:
    """``(2, 2, 3)`` the bottom corners at the ``x`` (+-1) end of each foot's box ``geoms``,
    in the frame of its sole box ``sole``."""
    out = np.empty((2, 2, 3))
    for f in range(2):
        g, s = int(geoms[f]), int(sole[f])
        h = m.geom_size[g]
        local = np.column_stack([np.full(2, x * h[0]), [h[1], -h[1]], np.full(2, -h[2])])
        body = quat_rotate(m.geom_quat[g], local) + m.geom_pos[g]
        out[f] = quat_rotate(quat_conj(m.geom_quat[s]), body - m.geom_pos[s])
    return out


def sole_corners_world(d: mujoco.MjData, sole: NDArray[np.int64], corners: F64) -> F64:
    """``(2, 4, 3)`` world positions of the sole corners from :func:`foot_soles`."""
    rot = d.geom_xmat[sole].reshape(2, 3, 3)
    return np.einsum("fij,fkj->fki", rot, corners) + d.geom_xpos[sole][:, None]
