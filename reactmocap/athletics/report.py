"""What an athletic run achieved, measured from its per-tick log: heights, distances, ground
forces, whether the athlete fell or landed, and the peak joint torques and powers checked
against a stated strength model (``docs/athletics.md`` cites it)."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.machine import Context
from reactmocap.sim.bodies import BALL_JOINTS

__all__ = [
    "FEMALE_STRENGTH",
    "STRENGTH",
    "fell",
    "ground_force",
    "joint_peaks",
    "plausibility",
    "report_json",
    "standing_balanced",
]

F64 = NDArray[np.float64]
#: the strength model: peak voluntary joint torque (N m per kg of body mass) a strong young man
#: can make, per joint kind and leg or arm (docs/athletics.md: Anderson, Madigan & Nussbaum
#: 2007; values at the upper end of their young men's isometric peaks)
_STRENGTH = {
    "hip": 4.0, "knee": 3.5, "ankle": 3.0, "waist": 4.0, "back": 4.0, "shoulder": 1.5,
    "elbow": 1.0, "neck": 0.6, "wrist": 0.3,
}  # fmt: skip
STRENGTH: Mapping[str, float] = MappingProxyType(_STRENGTH)
#: women's peak torques per kg are about 80% of men's in the same studies
FEMALE_STRENGTH: Mapping[str, float] = MappingProxyType({k: 0.8 * v for k, v in STRENGTH.items()})
#: a pelvis lower than this fraction of its standing height means a fall
FALL_HEIGHT = 0.5
#: balanced: COM slower than this (m/s) and over the support area
STILL_SPEED = 0.1


def report_json(report: Mapping[str, Any]) -> str:
    """An athletic run's report as JSON text: numpy scalars as Python's, floats rounded to 4
    places (the figures' precision; a long float is noise in a diff), NaN and inf as null."""
    return json.dumps(_jsonable(report), indent=2) + "\n"


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return None if not math.isfinite(v) else round(v, 4)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, Path):
        return str(value)
    return value


def _kind(joint: str) -> str:
    return joint[2:] if joint[:2] in ("l_", "r_") else joint


def ground_force(log: dict[str, np.ndarray], mass: float, gravity: F64) -> tuple[F64, F64]:
    """The ground force (N, world) averaged over each control tick, from the body's momentum:
    ``m dv_com/dt - m g``, exact while only the floor touches the athlete. Returns the ticks'
    end times ``(n-1,)`` and forces ``(n-1, 3)``. Why not the contact forces sampled at each
    tick (``log["grf"]``): one physics step in every tick is sampled, and a contact that
    chatters between steps reads far from its mean (at a leap's push-off from a 40% miss at
    the peak to 0 while the body still accelerates at 1.5 g)."""
    t, vel = log["t"], log["com_vel"]
    if t.size < 2:
        return np.zeros(0), np.zeros((0, 3))
    acc = np.diff(vel, axis=0) / np.diff(t)[:, None]
    return t[1:], mass * (acc - np.asarray(gravity, dtype=np.float64)[None])


def joint_peaks(
    ctx: Context, start: float = 0.0, end: float = np.inf
) -> dict[str, dict[str, float]]:
    """Peak torque (N m) and positive power (W) of each joint kind (both sides together) over
    the log's ticks in ``[start, end)``."""
    log = ctx.log.arrays()
    t = log["t"]
    sel = (t >= start) & (t < end)
    out: dict[str, dict[str, float]] = {}
    if not sel.any():
        return out
    torque, power = log["torque"][sel], log["power"][sel]
    for j, name in enumerate(BALL_JOINTS):
        kind = _kind(name)
        row = out.setdefault(kind, {"torque_nm": 0.0, "power_w": 0.0})
        row["torque_nm"] = max(row["torque_nm"], float(torque[:, j].max()))
        row["power_w"] = max(row["power_w"], float(power[:, j].max()))
    return out


def plausibility(
    peaks: Mapping[str, Mapping[str, float]], mass: float, female: bool = False
) -> tuple[bool, dict[str, float]]:
    """Whether every peak torque is within the strength model; the joints over it with the
    ratio of their peak to the model's limit."""
    model = FEMALE_STRENGTH if female else STRENGTH
    over = {
        kind: round(v["torque_nm"] / (model[kind] * mass), 2)
        for kind, v in peaks.items()
        if v["torque_nm"] > model[kind] * mass
    }
    return not over, over


def fell(ctx: Context, standing_pelvis: float) -> bool:
    """Anything but the feet touched the floor at some tick, or the pelvis dropped below
    :data:`FALL_HEIGHT` of its standing height (both above the floor plane, along its normal)."""
    log = ctx.log
    low = min(log.pelvis, default=standing_pelvis) < FALL_HEIGHT * standing_pelvis
    return bool(any(log.others) or low)


def standing_balanced(ctx: Context) -> bool:
    """At the last tick: only the feet touch, the COM is still and over the support area."""
    s = ctx.senses
    if s.other_contact or not s.foot_contact.any():
        return False
    if float(np.linalg.norm(s.com_vel)) > STILL_SPEED:
        return False
    lo, hi = s.support_extent()
    c = s.local(s.com)
    return bool(np.all(c >= lo - 0.01) and np.all(c <= hi + 0.01))
