"""What a platform dive (thesis ch. 8's dives) adds to a maneuver: the platform, the stretch for
the entry, and the entry's report (:func:`reactmocap.athletics.routines.dive` composes it:
balance on the platform, leap with rotation, tumble, stretch, the water ``height`` m below).

The platform is the athletics floor; once the athlete has left it the floor drops away (it is
moved far below the water: after lift-off nothing touches it again, so this is the same as
leaping off a platform's edge), and the water is a horizontal plane at ``-height`` that the
report looks for (no water forces are simulated). The report's ``landed`` is a clean entry:
the pelvis-to-head line within :data:`ENTRY_TOLERANCE` of straight down, head first, when the
COM reaches the water; ``fell`` is its opposite."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from reactmocap.athletics.machine import Basis, Context, law
from reactmocap.athletics.rig import joint_index, per_joint
from reactmocap.athletics.scene import Slope
from reactmocap.athletics.tumble import TUMBLE_STIFFNESS
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.controllers.machine import State
from reactmocap.sim.world import World

__all__ = [
    "ENTRY_TOLERANCE",
    "PLATFORM_MAX",
    "Platform",
    "Stretch",
    "entry_report",
    "stretch_angles",
]

NJ = len(BALL_JOINTS)
#: largest angle (deg) between the pelvis-to-head line and straight down at a clean entry
ENTRY_TOLERANCE = 30.0
#: highest platform (m): a higher fall outruns the rollout's kinetic-energy check
PLATFORM_MAX = 7.5


def stretch_angles() -> np.ndarray:
    """``(15, 3)`` the entry pose: straight, arms over the head."""
    out = np.zeros((NJ, 3))
    for side in "lr":
        out[joint_index(f"{side}_shoulder")] = (-2.9, 0.0, 0.0)
    return out


class Stretch(Basis):
    """Straighten for the entry (arms over the head) over ``seconds`` and hold to the end."""

    name = "stretch"
    initial = "stretch"

    def __init__(self, seconds: float = 0.2) -> None:
        self.seconds = seconds

    def states(self, ctx: Context) -> list[State]:
        def enter(world: World, t: float) -> None:
            del world
            ctx.rig.set_stiffness(per_joint(TUMBLE_STIFFNESS))
            ctx.rig.offset[:] = 0.0
            ctx.rig.move(stretch_angles(), self.seconds, t)

        return [State("stretch", law(lambda w, t: None, ctx.control_every), enter, ())]


@dataclass(eq=False)
class Platform:
    """The platform: the floor while the athlete stands on it; dropped far below the water
    once the leap has left it (``ctx.liftoff_time`` set)."""

    ctx: Context
    height: float
    control_every: int = 8

    def __post_init__(self) -> None:
        world = self.ctx.world
        self._up = Slope(world, 0.0, ramp=0.0)
        self._down = Slope(world, 0.0, ramp=0.0, pivot=np.array([0.0, 0.0, -self.height - 50.0]))
        self.dropped: float | None = None

    def reset(self, world: World) -> None:
        del world
        self._up.tilt(0.0)
        self.dropped = None

    def control(self, world: World, t: float) -> None:
        del world
        if self.dropped is None and self.ctx.liftoff_time is not None:
            self._down.tilt(0.0)
            self.dropped = t


def entry_report(ctx: Context, height: float, ok: bool) -> dict[str, Any]:
    """The entry at the water ``height`` m below the platform: the first tick the COM is at or
    below it; ``rotation_deg`` and ``twist_deg`` there, ``entry_angle_deg`` (the angle between the
    pelvis-to-head line and straight down, in 3D), ``landed`` (a clean entry, within :data:`ENTRY_TOLERANCE`) and ``fell``. ``ok``:
    the simulation ran to its end."""
    log = ctx.log.arrays()
    t, com = log["t"], log["com"]
    below = np.flatnonzero(com[:, 2] <= -height)
    i = int(below[0]) if below.size else t.size - 1
    rot = math.degrees(float(log["rotation"][i])) if t.size else 0.0
    # the pelvis-to-head line from straight down (in 3D: a twisted body leaves the plane)
    down = float(-log["trunk"][i, 2]) if t.size else -1.0
    angle = math.degrees(math.acos(float(np.clip(down, -1.0, 1.0))))
    entered = bool(below.size) and ok
    clean = entered and angle <= ENTRY_TOLERANCE
    rep: dict[str, Any] = {
        "platform_m": height, "rotation_deg": rot,
        "twist_deg": math.degrees(float(log["twist"][i])) if t.size else 0.0,
        "entry_angle_deg": angle, "entry_s": float(t[i]) if entered else None,
        "entry_speed_mps": float(np.linalg.norm(log["com_vel"][i])) if entered else None,
        "landed": clean, "fell": not clean,
    }  # fmt: skip
    lift = ctx.liftoff_time
    if lift is not None and entered:
        m = log["momentum"][(t > lift + 0.01) & (t <= t[i])]
        if m.shape[0] > 2:
            ref = max(float(np.linalg.norm(m[0])), 1e-9)
            rep["flight_momentum_drift"] = float(np.abs(m - m[0]).max() / ref)
    return rep
