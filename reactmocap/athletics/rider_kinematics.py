"""The rider's body geometry in the bicycle's frame (Hodgins et al. 1995, "Bicycling"): the
riding posture (:class:`Posture`) and its trunk (:func:`trunk_pose`), closed-form two-link limb
inverse kinematics (:func:`two_link`), the pedalling ankle pattern (:func:`ankle_pitch`) and the
small-array quaternion helpers the rider's control tick uses. The rider itself:
:mod:`reactmocap.athletics.rider`."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import Athlete
from reactmocap.rotations import cross_rows, unit_rows
from reactmocap.sim.bodies import SIM_BODY_INDEX, SIM_PARENTS

__all__ = [
    "SIT_OFFSET",
    "Posture",
    "ankle_pitch",
    "minrot",
    "qconj",
    "qmul",
    "qrot",
    "quat_y",
    "trunk_pose",
    "two_link",
]

F64 = NDArray[np.float64]
#: sit bones relative to the pelvis origin (anatomical frame: x forward, y left, z up; m)
SIT_OFFSET = (-0.03, 0.06, -0.09)
# small-array quaternion helpers for the control tick (the general ones of
# reactmocap.rotations cost 25-40 us a call on (4, 3) arrays, these 5-10 us)
_HAMILTON = np.zeros((4, 4, 4))
for _i, _j, _k, _s in ((0, 0, 0, 1), (0, 1, 1, -1), (0, 2, 2, -1), (0, 3, 3, -1),
                       (1, 0, 1, 1), (1, 1, 0, 1), (1, 2, 3, 1), (1, 3, 2, -1),
                       (2, 0, 2, 1), (2, 1, 3, -1), (2, 2, 0, 1), (2, 3, 1, 1),
                       (3, 0, 3, 1), (3, 1, 2, 1), (3, 2, 1, -1), (3, 3, 0, 1)):  # fmt: skip
    _HAMILTON[_i, _j, _k] = _s
_HAMILTON_T = _HAMILTON.reshape(4, 16).T.copy()
_CONJ = np.array([1.0, -1.0, -1.0, -1.0])


def qmul(a: F64, b: F64) -> F64:
    """Hamilton product of ``(n, 4)`` or ``(4,)`` quaternions (w, x, y, z), broadcast."""
    outer = a[..., :, None] * b[..., None, :]
    return outer.reshape(*outer.shape[:-2], 16) @ _HAMILTON_T


def qconj(q: F64) -> F64:
    """Conjugates of ``(..., 4)`` quaternions."""
    return q * _CONJ


def qrot(q: F64, v: F64) -> F64:
    """Rotate ``(..., 3)`` vectors by ``(..., 4)`` unit quaternions."""
    u = q[..., 1:]
    t = 2.0 * cross_rows(u, v)
    return v + q[..., :1] * t + cross_rows(u, t)


def minrot(u: F64, v: F64) -> F64:
    """``(n, 4)`` shortest-arc rotations taking unit vectors ``u`` to ``v`` ``(n, 3)``."""
    q = np.empty((u.shape[0], 4))
    q[:, 0] = 1.0 + np.einsum("ij,ij->i", u, v)
    q[:, 1:] = cross_rows(u, v)
    bad = q[:, 0] < 1e-9
    if np.any(bad):  # opposite: any perpendicular axis
        q[bad, 0] = 0.0
        q[bad, 1:] = cross_rows(u[bad], np.array([1.0, 0.0, 0.0]))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def quat_y(angle: F64 | float) -> F64:
    """``(..., 4)`` rotations by ``angle`` (rad) about +Y."""
    a = np.asarray(angle, dtype=np.float64)
    return np.stack([np.cos(a / 2), np.zeros_like(a), np.sin(a / 2), np.zeros_like(a)], axis=-1)


def two_link(base: F64, target: F64, l1: F64, l2: F64, pole: F64) -> tuple[F64, F64]:
    """Unit directions ``(n, 3)`` of the first and second links of two-link chains from
    ``base`` to ``target`` (``(n, 3)``), lengths ``l1, l2`` ``(n,)``, bending toward ``pole``;
    an unreachable target is approached along the straight line."""
    d = target - base
    dist = np.linalg.norm(d, axis=1)
    dist = np.clip(dist, np.abs(l1 - l2) + 1e-6, (l1 + l2) * 0.9999)
    dh = unit_rows(d)
    cos_a = np.clip((l1**2 + dist**2 - l2**2) / (2 * l1 * dist), -1.0, 1.0)
    n = pole - np.einsum("ij,ij->i", pole, dh)[:, None] * dh
    n = unit_rows(n)
    u1 = cos_a[:, None] * dh + np.sqrt(1.0 - cos_a**2)[:, None] * n
    elbow = base + l1[:, None] * u1
    u2 = unit_rows(base + dist[:, None] * dh - elbow)
    return u1, u2


def ankle_pitch(crank: F64 | float) -> F64:
    """Toes-down pitch (rad) of a foot relative to the bicycle for its crank angle (0: that
    pedal at the top, increasing forward). Stated approximation of recorded pedalling (ankle
    angle data of Ericson et al. 1985 and Hull & Jorge 1985, as summarised by Bini et al.
    2011): the sole 15 degrees toes-down on average, 10 degrees either way, flattest (heel
    down) just after the top of the power stroke (crank 110 degrees), most toes-down on the
    up-stroke (crank 290 degrees)."""
    return np.radians(15.0) - np.radians(10.0) * np.cos(np.asarray(crank) - math.radians(110.0))


@dataclass(frozen=True)
class Posture:
    """The riding posture: pelvis tilt forward on the saddle, waist and back pitch (anatomical,
    > 0 forward), neck pitch (< 0 lifts the head to look ahead), rad."""

    pelvis: float = math.radians(15.0)
    waist: float = math.radians(12.0)
    back: float = math.radians(12.0)
    neck: float = math.radians(-30.0)


def trunk_pose(athlete: Athlete, posture: Posture) -> tuple[F64, F64, F64]:
    """The posture's trunk in the bicycle frame with the pelvis origin at 0: anatomical
    rotations ``(16, 4)`` (pelvis, waist, chest and head rows; the rest identity), the
    shoulders' and hips' offsets ``(4, 3)`` (left and right shoulder, left and right hip) and
    the sit bones' midpoint ``(3,)``."""
    n, bpos = athlete.neutral, athlete.character.body_pos
    a = np.tile([1.0, 0.0, 0.0, 0.0], (16, 1))
    a[SIM_BODY_INDEX["pelvis"]] = quat_y(posture.pelvis)
    a[SIM_BODY_INDEX["waist"]] = qmul(a[SIM_BODY_INDEX["pelvis"]], quat_y(posture.waist))
    a[SIM_BODY_INDEX["chest"]] = qmul(a[SIM_BODY_INDEX["waist"]], quat_y(posture.back))
    a[SIM_BODY_INDEX["head"]] = qmul(a[SIM_BODY_INDEX["chest"]], quat_y(posture.neck))
    g = qmul(a, n)
    pos = np.zeros((16, 3))
    for b in ("waist", "chest"):
        i = SIM_BODY_INDEX[b]
        pos[i] = pos[SIM_PARENTS[i]] + qrot(g[SIM_PARENTS[i]], bpos[i])
    bases = np.empty((4, 3))
    for k, b in enumerate(("l_upper_arm", "r_upper_arm", "l_thigh", "r_thigh")):
        i = SIM_BODY_INDEX[b]
        bases[k] = pos[SIM_PARENTS[i]] + qrot(g[SIM_PARENTS[i]], bpos[i])
    sit = qrot(a[0], np.array([SIT_OFFSET[0], 0.0, SIT_OFFSET[2]]))
    return a, bases, sit
