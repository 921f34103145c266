"""Leaping (thesis ch. 4): crouch with the balance controller, then extend hips, knees and ankles
in proximal-to-distal order on fixed timing while the arms swing; lift-off hands over to the
landing controller (at the apex for a vertical leap, at once for a broad jump).

Parameters (:class:`LeapParams`): the crouch's hip-to-ankle length and torso pitch and a
forward COM offset (broad jump), the arm swing, the extension timing, the ankle stiffness
multiplier, and the hip angle at lift-off, which tilts the push off the centre of mass and so
sets the angular momentum (section 4.3). A commanded height or distance picks them from a
measured table (:mod:`reactmocap.athletics.tables`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from reactmocap.athletics.balance import BALANCE_GAINS, BalanceLaw, Posture
from reactmocap.athletics.machine import NEXT, Basis, Context, apex, law, liftoff
from reactmocap.athletics.rig import joint_index, per_joint
from reactmocap.athletics.senses import Senses
from reactmocap.errors import ConfigError
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.controllers.machine import Event, State, after
from reactmocap.sim.world import World

__all__ = ["BROAD_TIMING", "HANDOVERS", "LEAP_STIFFNESS", "VERTICAL_TIMING", "Leap", "LeapParams"]

NJ = len(BALL_JOINTS)
#: seconds to full extension of hip, knee and ankle (section 4.1 and 4.2)
VERTICAL_TIMING = (0.10, 0.15, 0.22)
BROAD_TIMING = (0.15, 0.20, 0.45)
#: seconds after which a push that never left the ground hands over anyway
THRUST_TIMEOUT = 1.0
#: seconds over which the push's stiffness comes in (a step in stiffness jolts the feet)
STIFFNESS_RAMP = 0.06
#: seconds over which the angular-momentum feedback comes in at the start of the push
SPIN_RAMP = 0.05
#: joint stiffness during the push-off (units of m g L N m/rad), before the ankle multiplier
LEAP_STIFFNESS = {
    "waist": 3.0, "back": 3.0, "neck": 0.3, "shoulder": 0.6, "elbow": 0.15, "wrist": 0.05,
    "hip": 6.0, "knee": 6.0, "ankle": 3.0,
}  # fmt: skip
#: when a leap may hand over to the next basis controller (see LeapParams.handover)
HANDOVERS = ("auto", "apex", "liftoff")
#: stiffness in the air (the legs only position themselves)
FLIGHT_STIFFNESS = {
    "waist": 2.0, "back": 2.0, "neck": 0.3, "shoulder": 0.3, "elbow": 0.15, "wrist": 0.05,
    "hip": 1.5, "knee": 1.0, "ankle": 0.3,
}  # fmt: skip


@dataclass(frozen=True)
class LeapParams:
    """One leap's low-level parameters (see the module docstring). Angles in radians."""

    leg: float = 0.75
    pitch: float = 0.3
    com_offset: float = 0.0
    arms: float = -2.6
    arms_back: float = 0.5
    crouch: float = 0.6
    hold: float = 0.15
    timing: tuple[float, float, float] = VERTICAL_TIMING
    ankle_gain: float = 4.45
    ankle_extension: float = 0.7
    liftoff_hip: float = 0.0
    broad: bool = False
    stiffness: float = 1.0
    lean: float = 0.0
    spin: float = 0.0
    spin_gain: float = 0.0
    accelerate: bool = False
    #: when the leap hands over: ``"auto"`` (at the apex for a vertical leap, at lift-off for
    #: a broad jump), ``"apex"`` or ``"liftoff"`` (a somersault tucks at once)
    handover: str = "auto"
    #: the largest hip offset (rad) the angular-momentum feedback may make
    spin_limit: float = 0.6

    def __post_init__(self) -> None:
        vals = [self.leg, self.pitch, self.com_offset, self.arms, self.arms_back, self.crouch,
                self.hold, *self.timing, self.ankle_gain, self.ankle_extension, self.liftoff_hip,
                self.stiffness, self.lean,
                self.spin, self.spin_gain, self.spin_limit]  # fmt: skip
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in vals):
            raise ConfigError(f"leap parameters must be finite numbers, got {self}")
        if not 0.3 <= self.leg <= 1.0:
            raise ConfigError(f"leap crouch leg fraction must be in [0.3, 1.0], got {self.leg}")
        if min(self.timing) <= 0 or self.crouch <= 0 or self.hold < 0 or self.ankle_gain <= 0:
            raise ConfigError("leap timing, crouch and ankle gain must be > 0")
        if self.handover not in HANDOVERS:
            raise ConfigError(
                f"leap handover must be one of {list(HANDOVERS)}, got {self.handover!r}"
            )


def pitch_momentum(world: World, s: Senses) -> float:
    """Whole-body angular momentum about the COM (kg m^2/s) about the heading frame's pitch
    axis (+Y turned by the heading; > 0 pitches forward). ``mj_subtreeVel`` has run."""
    h = s.heading()
    axis = np.array([-math.sin(h), math.cos(h), 0.0])
    return float(world.data.subtree_angmom[s.root] @ axis)


class Leap(Basis):
    """The leaping basis controller (vertical or broad, by ``params.broad``)."""

    name = "leap"
    initial = "crouch"

    def __init__(self, params: LeapParams) -> None:
        self.params = params

    def states(self, ctx: Context) -> list[State]:
        p = self.params
        bl = BalanceLaw(ctx, BALANCE_GAINS)
        every = ctx.control_every
        memo: dict[str, Any] = {}

        def crouch(world: World, t: float) -> None:
            del world
            s = ctx.sense(t)
            memo["z_stand"] = float(s.com[2])
            if ctx.standing_com is None:
                ctx.standing_com = float(s.com[2])
            bl.set_posture(
                Posture(pitch=p.pitch, leg=p.leg, com_offset=(p.com_offset, 0.0),
                        arms=p.arms_back, settle=p.crouch, lean=p.lean), t)  # fmt: skip

        def thrust(world: World, t: float) -> None:
            del world
            memo["t_thrust"] = t
            memo.pop("ramp", None)
            rig = ctx.rig
            stiff = per_joint(LEAP_STIFFNESS) * p.stiffness
            stiff[[joint_index(f"{s}_ankle") for s in "lr"]] *= p.ankle_gain
            memo["stiff0"] = rig.stiffness.copy()
            memo["stiff1"] = stiff
            rig.move(rig.desired(t) + rig.offset, 0.0, t)
            rig.offset[:] = 0.0
            hip_t, knee_t, ankle_t = p.timing
            goal = np.full((NJ, 3), np.nan)
            dur = np.zeros(NJ)
            for s in "lr":
                for j, val, d in (("hip", p.liftoff_hip, hip_t), ("knee", 0.0, knee_t),
                                  ("ankle", p.ankle_extension, ankle_t)):  # fmt: skip
                    i = joint_index(f"{s}_{j}")
                    goal[i] = (val, 0.0, 0.0)
                    dur[i] = d
                i = joint_index(f"{s}_shoulder")
                goal[i] = (p.arms, 0.0, 0.0)
                dur[i] = max(knee_t, 0.25)
            for j in ("waist", "back"):
                goal[joint_index(j)] = 0.0
                dur[joint_index(j)] = hip_t
            moving = [j for j in range(NJ) if not np.isnan(goal[j]).all()]
            rig.move(goal, dur, t, moving, accelerate=p.accelerate)

        def push(world: World, t: float) -> None:
            s = ctx.sense(t)
            bl._support(s)
            ramp = min(1.0, (t - memo["t_thrust"]) / STIFFNESS_RAMP)
            if memo.get("ramp", -1.0) < 1.0:  # the push's stiffness comes in smoothly
                memo["ramp"] = ramp
                ctx.rig.set_stiffness(memo["stiff0"] + ramp * (memo["stiff1"] - memo["stiff0"]))
            if p.spin_gain > 0:
                # whole-body angular momentum about the COM (mj_subtreeVel has run), pitch
                # axis of the heading frame: the hips tilt the push ahead of or behind the COM
                pitch_l = pitch_momentum(world, s)
                err = (pitch_l - p.spin) / (ctx.athlete.mass * ctx.athlete.leg_length**2)
                ramp = min(1.0, (t - memo["t_thrust"]) / SPIN_RAMP)
                off = float(np.clip(ramp * p.spin_gain * err, -p.spin_limit, p.spin_limit))
                for j in (joint_index("l_hip"), joint_index("r_hip")):
                    ctx.rig.offset[j, 0] = off

        def flight(world: World, t: float) -> None:
            s = ctx.sense(t)
            ctx.handover["liftoff_pitch_momentum"] = pitch_momentum(world, s)
            ctx.rig.set_stiffness(per_joint(FLIGHT_STIFFNESS))
            ctx.rig.support[:] = 0.0
            ctx.rig.support_scale = 1.0
            ctx.rig.support_dir = None

        at_apex = p.handover == "apex" or (p.handover == "auto" and not p.broad)
        flight_exit: Event = apex(ctx) if at_apex else after(0.0)
        return [
            State(
                "crouch", law(bl.control, every), crouch, ((after(p.crouch + p.hold), "thrust"),)
            ),
            State(
                "thrust",
                law(push, every),
                thrust,
                ((liftoff(ctx), "flight"), (after(THRUST_TIMEOUT), "flight")),
            ),
            State("flight", None, flight, ((flight_exit, NEXT),)),
        ]
