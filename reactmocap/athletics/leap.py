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
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Any

import numpy as np

from reactmocap.athletics.balance import (
    BALANCE_GAINS,
    BalanceLaw,
    Posture,
    hold_pelvis_and_feet,
)
from reactmocap.athletics.machine import NEXT, Basis, Context, apex, law, liftoff
from reactmocap.athletics.rig import joint_index, per_joint
from reactmocap.athletics.senses import Senses
from reactmocap.errors import ConfigError
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.controllers.machine import Event, State, after
from reactmocap.sim.world import World

__all__ = [
    "BROAD_TIMING",
    "COM_PUSH_LEG",
    "COM_PUSH_LEGS",
    "COM_PUSH_SPIN",
    "COM_PUSH_STIFFNESS",
    "HANDOVERS",
    "LEAP_STIFFNESS",
    "PUSHES",
    "VERTICAL_TIMING",
    "Leap",
    "LeapParams",
    "com_push",
]

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
#: how a vertical leap pushes off (see LeapParams.push)
PUSHES = ("timed", "com")
#: joint stiffness during the "com" push (units of m g L N m/rad): the hips hold the pelvis's
#: pitch and the ankles the feet flat, the knees are free (the push is the feed-forward). Soft:
#: a stiff servo's damping (critical, against the joints' speed) took the push's force once
#: the legs extended fast (hips and ankles at 6 and 3: the feet left at 2.6 m/s, knees at 0.8)
COM_PUSH_STIFFNESS = {
    "waist": 3.0, "back": 3.0, "neck": 0.3, "shoulder": 0.6, "elbow": 0.15, "wrist": 0.05,
    "hip": 1.0, "knee": 0.0, "ankle": 1.0,
}  # fmt: skip
#: the "com" push's hip and ankle stiffness per body (LeapParams.push_hip, push_ankle; others
#: keep COM_PUSH_STIFFNESS's 1 and 1): the servo's critical damping acts on the joints' whole
#: speed, and at 1 it took the push's force as the legs straightened fast (the feed-forward's
#: gain rose to its cap of 3 and asks of 1.4-2.2 BW made 0.2-0.4 in the last ticks). Over the
#: ten Fig. 4.1 commands (max |error|, landed of 10; 2026-12-02): male hip/ankle 1/1 3.4 cm
#: 10, 0.5/1 1.7 cm 10, 1/0.5 2.7 cm 9, 0.5/0.5 3.6 cm 8; female 1/1 3.6 cm 9, 0.5/1 3.0 cm 8,
#: 1/0.5 5.3 cm 9, 0.5/0.5 2.9 cm 9 (docs/athletics.md)
COM_PUSH_LEGS: Mapping[str, tuple[float, float]] = MappingProxyType(
    {"male": (0.5, 1.0), "female": (0.5, 0.5)}
)
#: a "com" push whose plan needs more than push_limit may ask this much over its plan
PUSH_HEADROOM = 1.1
#: the "com" push's centre of pressure: metres ahead per unit of pitch momentum error (in
#: m L^2 rad/s) and its range about the sole centres (m)
COP_GAIN = 2.0
COP_RANGE = (-0.08, 0.15)
#: the "com" push's crouch (leg fraction; trunk upright: a leaning trunk's hip torque made
#: most of the force, beyond the feed-forward's reach) and its take-off pitch momentum
#: (kg m^2/s) per body: the landing after a vertical leap is tuned for the timed push's
#: backward take-off (-3.4 / -1.3 at 0.5 m). Female over the ten Fig. 4.1 commands: 0 landed
#: 6, -1.3 landed 7; male -3.4 lost the 0.1 m leap that -2 lands (2026-12-02)
COM_PUSH_LEG = 0.6
COM_PUSH_SPIN: Mapping[str, float] = MappingProxyType({"male": -2.0, "female": -1.3})
#: the "com" push's horizontal COM servo through the ankles (rad/m, rad s/m; the balance's)
ANKLE_KP, ANKLE_KV = 2.0, 0.5
#: the largest hip roll and yaw offset (rad) the push's tilt feedback may make (tilt_gain)
TILT_LIMIT = 0.3
#: the most weight share the "com" push's roll feedback moves between the feet (roll_gain)
ROLL_SHIFT = 0.5
#: the tilt feedback's yaw gain as a multiple of its roll gain (tilt_gain): the yaw
#: momentum is the smaller, and the one that told the female back tuck's landings apart
TILT_YAW = 4.0
#: the most the "com" push's yaw feedback tilts each foot's ground force fore or aft (a
#: fraction of the force; yaw_gain): 0.15 at 2.5 kN a foot 20 cm apart is a 75 N m couple
YAW_TILT = 0.15
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
    #: the crouch moves the COM target to ``com_offset`` over the crouch, not at once (the
    #: step kicks the ankles: the broad jump's 17 cm hopped the body off the floor and a
    #: perturbed start came down on one foot); off by default: the tables were measured so
    com_ease: bool = False
    #: the crouch moves the COM target to ``com_offset`` over this many seconds (Hermite), not
    #: at once: the 10 cm step of the back handspring's target stepped the ankles 0.2 rad in
    #: one tick, 4.3 kN a foot, and hopped both feet off the floor for ~0.1 s, and a perturbed
    #: start came down on one foot. 0.2 s keeps them down (the male back handspring's since
    #: 2026-12-04, with its landing re-tuned: docs/athletics.md); 0: off (as before;
    #: ``com_ease`` eases over the whole crouch instead)
    com_ramp: float = 0.0
    #: the crouch's sideways COM servo gains as a multiple of the balance's
    #: (:attr:`BalanceGains.side`): on feet yawed apart by a perturbed start the crouch's knees
    #: carried the COM sideways and the broad jump left at up to 0.5 m/s sideways; 1: as the
    #: balance (the tables were measured so)
    crouch_side: float = 1.0
    #: when the leap hands over: ``"auto"`` (at the apex for a vertical leap, at lift-off for
    #: a broad jump), ``"apex"`` or ``"liftoff"`` (a somersault tucks at once)
    handover: str = "auto"
    #: the largest hip offset (rad) the angular-momentum feedback may make
    spin_limit: float = 0.6
    #: how a vertical leap pushes off: ``"timed"`` (the thesis's: hips, knees and ankles
    #: extend on fixed timing under stiff servos) or ``"com"`` (a servo on the COM's height and
    #: vertical speed along a planned constant acceleration, its ground force fed forward
    #: through the legs; the broad jump always pushes ``"timed"``)
    push: str = "timed"
    #: the "com" push's planned apex COM rise over standing (m)
    rise: float = 0.5
    #: the "com" push ends with the COM this far (m) above its standing height (< 0: below)
    push_end: float = -0.03
    #: the "com" push's largest planned ground force (body weights)
    push_limit: float = 3.0
    #: seconds over which the "com" push's acceleration comes in
    push_ramp: float = 0.1
    #: the "com" push's hip and ankle stiffness (m g L N m/rad; see COM_PUSH_LEGS)
    push_hip: float = 1.0
    push_ankle: float = 1.0
    #: the timed push also servos the whole-body angular momentum's roll (about the heading's
    #: forward axis: cartwheel) and yaw (twist) to zero through the hips' roll and yaw (rad per
    #: unit of momentum in m L^2 rad/s, as ``spin_gain``; yaw ``TILT_YAW`` times it; at most
    #: ``TILT_LIMIT``): a take-off's yaw and cartwheel momentum twist a somersault's opening
    #: body; 0: off (as before)
    tilt_gain: float = 0.0
    #: the "com" push also servos the whole-body roll (cartwheel) momentum about the heading's
    #: forward axis to zero by moving the push's weight shares between the feet (share per
    #: unit of momentum in m L^2 rad/s, at most ``ROLL_SHIFT``): a perturbed start's small
    #: roll grew ~10 times over the push (the centre of pressure 2-6 cm to the side of the
    #: COM), and the forward tuck touched down with the feet staggered and to the side of
    #: the COM, stood up on one foot and fell (docs/athletics.md); 0: off (as before)
    roll_gain: float = 0.0
    #: the "com" push keeps a weight share on a foot off the floor (both feet's shares from
    #: where the COM lies between the sole centres while only one foot is down): a perturbed
    #: start whose other foot was unloaded pushed on the one foot alone, to the side of the
    #: COM, and left with 12-100 kg m^2/s of roll; the lifted leg's share presses it back
    #: down. False: off (as before)
    push_both: bool = False
    #: the "com" push also servos the whole-body momentum about the vertical (yaw, twist) to
    #: zero by tilting the feet's ground forces fore and aft in opposite senses, a couple about
    #: the vertical (tilt per unit of momentum in m L^2 rad/s, at most ``YAW_TILT``): the
    #: forward tuck's take-off yaw became the pelvis's roll at touchdown (r = +0.74), and the
    #: hips' yaw (``tilt_gain``'s way) put a cartwheel in; 0: off (as before)
    yaw_gain: float = 0.0
    #: the crouch plants both feet (:attr:`Posture.plant`: the COM target the middle of both
    #: soles, not of those in contact, and a hanging foot brought down): a perturbed start's
    #: crouch that lost one foot's contact servoed the COM over the other and the push began
    #: on one foot (docs/athletics.md). False: off (as before)
    crouch_plant: bool = False
    #: the crouch ends on the body's state, not at ``crouch + hold``: ``(side_m,
    #: side_speed_m_s, cap_s)``: from ``crouch + hold`` on it waits until both feet are down
    #: and the COM lies within ``side_m`` sideways of the soles' middle (both soles, as
    #: ``crouch_plant``'s target) moving sideways under ``side_speed_m_s``, at most ``cap_s``
    #: more (then it thrusts as before): a perturbed start's crouch ended over one foot or
    #: moving sideways and the push began on one foot (docs/athletics.md). ``()``: off (as
    #: before)
    crouch_until: tuple[float, ...] = ()
    #: from the crouch's end on (the hold, ``hold``), the COM target's forward offset is
    #: where the COM stands then, not ``com_offset``: the COM lagged the eased target over
    #: the crouch and then went on past it through the hold, and a later thrust left with
    #: more pitch (docs/athletics.md). False: off (as before)
    hold_com: bool = False
    #: the crouch's COM target lies over the middle of both soles sideways, along the feet
    #: as before (:attr:`Posture.side_both`): a settled back handspring start crouched onto
    #: one foot, its target following the loaded sole, and ``crouch_plant``'s whole target
    #: made it fall back (docs/athletics.md). False: off (as before)
    crouch_middle: bool = False
    #: the crouch's legs servo the hips level (:attr:`Posture.level_hips`, this gain): a back
    #: handspring crouch whose feet stayed down (``com_ramp``) rolled the pelvis 8 deg and the
    #: feet left turning about the vertical; 10 took that within +-1.2 kg m^2/s in 7 of 8
    #: starts, yet landed none of them (docs/athletics.md); 0: off
    crouch_level: float = 0.0
    #: the timed push holds the leap's height: once the COM's ballistic apex (its rise over
    #: standing plus v_z^2 / 2g) reaches this rise (m), the knees' and ankles' targets stop
    #: where the joints stand, so the extension ends and the COM flies on (the hips' spin
    #: feedback goes on): the male back handspring's late perturbed starts rose 0.89-1.09 m
    #: against the landers' 0.45-0.67 with the same take-off momentum and ran over the hands'
    #: contact (docs/athletics.md); 0: off (as before)
    rise_cap: float = 0.0
    #: the cap looks ahead (s): it fires on the apex this far ahead at the apex's rate over
    #: the last control tick. The push's last ticks raise the apex 0.1-0.2 m each, faster
    #: in an over-leap than in an ordinary leap, so a cap on the tick's own apex cut both
    #: (docs/athletics.md); 0: the apex as it stands (as before)
    rise_lead: float = 0.0
    #: the hips' spin allowance (rad) once the cap has fired (the cut push left 3-10 kg m^2/s
    #: less spin); 0: ``spin_limit`` (as before)
    rise_spin_limit: float = 0.0
    #: ``rise_spin_limit`` applies already once the apex climbs faster than this (m/s, over
    #: the last control tick), a tick or two before the cap: an over-leap's apex climbs at
    #: 34-43 m/s the tick before the cap, an ordinary leap's at most 32, and the spin the cut
    #: push loses is made in those last ticks (docs/athletics.md); 0: off (as before)
    rise_spin_rate: float = 0.0

    def __post_init__(self) -> None:
        vals = [self.leg, self.pitch, self.com_offset, self.arms, self.arms_back, self.crouch,
                self.hold, *self.timing, self.ankle_gain, self.ankle_extension, self.liftoff_hip,
                self.stiffness, self.lean, self.crouch_side,
                self.spin, self.spin_gain, self.spin_limit, self.rise, self.push_end,
                self.push_ramp, self.push_limit, self.push_hip, self.push_ankle,
                self.tilt_gain, self.roll_gain, self.yaw_gain, self.com_ramp,
                self.crouch_level, self.rise_cap, self.rise_lead, self.rise_spin_limit,
                self.rise_spin_rate]  # fmt: skip
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in vals):
            raise ConfigError(f"leap parameters must be finite numbers, got {self}")
        if not 0.0 < self.crouch_side <= 5.0:
            raise ConfigError(
                f"leap crouch_side must be in (0, 5] (a multiple of the balance's sideways "
                f"gains), got {self.crouch_side}"
            )
        if not 0.3 <= self.leg <= 1.0:
            raise ConfigError(f"leap crouch leg fraction must be in [0.3, 1.0], got {self.leg}")
        if min(self.timing) <= 0 or self.crouch <= 0 or self.hold < 0 or self.ankle_gain <= 0:
            raise ConfigError("leap timing, crouch and ankle gain must be > 0")
        if self.push not in PUSHES:
            raise ConfigError(f"leap push must be one of {list(PUSHES)}, got {self.push!r}")
        if not 0.0 < self.rise <= 2.0 or self.push_ramp < 0 or self.push_limit <= 1.0:
            raise ConfigError(
                f"leap rise must be in (0, 2] m, push_ramp >= 0 and push_limit > 1 BW, got "
                f"{self.rise}, {self.push_ramp}, {self.push_limit}"
            )
        if not (0.0 <= self.push_hip <= 10.0 and 0.0 <= self.push_ankle <= 10.0):
            raise ConfigError(
                f"leap push_hip and push_ankle must be in [0, 10] m g L/rad, got "
                f"{self.push_hip}, {self.push_ankle}"
            )
        if not 0.0 <= self.com_ramp <= 5.0:
            raise ConfigError(f"leap com_ramp must be in [0, 5] s, got {self.com_ramp}")
        if not 0.0 <= self.rise_cap <= 2.0:
            raise ConfigError(f"leap rise_cap must be in [0, 2] m (0: off), got {self.rise_cap}")
        if not 0.0 <= self.rise_lead <= 0.1:
            raise ConfigError(
                f"leap rise_lead must be in [0, 0.1] s (0: off), got {self.rise_lead}"
            )
        if not 0.0 <= self.rise_spin_limit <= 3.0:
            raise ConfigError(
                f"leap rise_spin_limit must be in [0, 3] rad (0: spin_limit), got "
                f"{self.rise_spin_limit}"
            )
        if not 0.0 <= self.rise_spin_rate <= 100.0 or (
            self.rise_spin_rate > 0 and (self.rise_cap == 0 or self.rise_spin_limit == 0)
        ):
            raise ConfigError(
                f"leap rise_spin_rate must be in [0, 100] m/s (0: off) and needs rise_cap and "
                f"rise_spin_limit, got {self.rise_spin_rate}"
            )
        if not 0.0 <= self.tilt_gain <= 100.0:
            raise ConfigError(f"leap tilt_gain must be in [0, 100] rad, got {self.tilt_gain}")
        if not 0.0 <= self.roll_gain <= 100.0:
            raise ConfigError(f"leap roll_gain must be in [0, 100], got {self.roll_gain}")
        if not 0.0 <= self.yaw_gain <= 100.0:
            raise ConfigError(f"leap yaw_gain must be in [0, 100], got {self.yaw_gain}")
        if self.crouch_until and not (
            len(self.crouch_until) == 3
            and all(isinstance(v, (int, float)) and math.isfinite(v) for v in self.crouch_until)
            and min(self.crouch_until[:2]) > 0.0
            and self.crouch_until[2] >= 0.0
        ):
            raise ConfigError(
                f"leap crouch_until must be () or (side_m > 0, side_speed_m_s > 0, cap_s >= 0), "
                f"got {self.crouch_until}"
            )
        if self.handover not in HANDOVERS:
            raise ConfigError(
                f"leap handover must be one of {list(HANDOVERS)}, got {self.handover!r}"
            )


def com_push(params: LeapParams, rise: float, body: str | None = None) -> LeapParams:
    """``params`` with the "com" push to a planned apex rise (m): its crouch (upright trunk,
    :data:`COM_PUSH_LEG`), the body's take-off pitch momentum (:data:`COM_PUSH_SPIN`, 0 for
    a body without one) and its hip and ankle stiffness (:data:`COM_PUSH_LEGS`). A broad jump
    is returned unchanged (it always pushes "timed")."""
    if params.broad:
        return params
    hip, ankle = COM_PUSH_LEGS.get(body or "", (1.0, 1.0))
    return replace(params, push="com", rise=rise, leg=COM_PUSH_LEG, lean=0.0, pitch=0.0,
                   spin_gain=0.0, spin=COM_PUSH_SPIN.get(body or "", 0.0), push_hip=hip,
                   push_ankle=ankle)  # fmt: skip


def pitch_momentum(world: World, s: Senses) -> float:
    """Whole-body angular momentum about the COM (kg m^2/s) about the heading frame's pitch
    axis (+Y turned by the heading; > 0 pitches forward). ``mj_subtreeVel`` has run."""
    h = s.heading()
    axis = np.array([-math.sin(h), math.cos(h), 0.0])
    return float(world.data.subtree_angmom[s.root] @ axis)


def roll_momentum(world: World, s: Senses) -> float:
    """Whole-body angular momentum about the COM (kg m^2/s) about the heading frame's forward
    axis (roll, cartwheel). ``mj_subtreeVel`` has run."""
    h = s.heading()
    lw = world.data.subtree_angmom[s.root]
    return float(lw[0] * math.cos(h) + lw[1] * math.sin(h))


class Leap(Basis):
    """The leaping basis controller (vertical or broad, by ``params.broad``)."""

    name = "leap"
    initial = "crouch"

    def __init__(self, params: LeapParams) -> None:
        self.params = params

    def states(self, ctx: Context) -> list[State]:
        p = self.params
        bl = BalanceLaw(ctx, replace(BALANCE_GAINS, side=p.crouch_side))
        every = ctx.control_every
        memo: dict[str, Any] = {}
        knees = [joint_index(f"{k}_knee") for k in "lr"]
        ankles = [joint_index(f"{k}_ankle") for k in "lr"]
        hips = [joint_index(f"{k}_hip") for k in "lr"]
        tilt = np.zeros(2)  # the tilt feedback's roll and yaw momentum (tilt_gain)
        g = float(np.linalg.norm(ctx.world.model.opt.gravity))
        dirs = np.zeros((2, 3))  # each foot's ground force direction (yaw_gain)

        def crouch(world: World, t: float) -> None:
            del world
            s = ctx.sense(t)
            memo["z_stand"] = float(s.com[2])
            memo["t_crouch"] = t
            memo.pop("held", None)
            if ctx.standing_com is None:
                ctx.standing_com = float(s.com[2])
            bl.set_posture(
                Posture(pitch=p.pitch, leg=p.leg, com_offset=(p.com_offset, 0.0),
                        arms=p.arms_back, settle=p.crouch, lean=p.lean, plant=p.crouch_plant,
                        side_both=p.crouch_middle, level_hips=p.crouch_level),
                t, ease_com=p.com_ease or p.com_ramp > 0,
                com_over=p.com_ramp if p.com_ramp > 0 else None)  # fmt: skip

        def crouch_hold(world: World, t: float) -> None:
            # hold_com: at the crouch's end the COM target's forward offset stays where the
            # COM stands (the balance law reads its posture's offset every tick)
            if "held" not in memo and t - memo["t_crouch"] >= p.crouch - 1e-12:
                s = ctx.sense(t)
                h = s.heading()
                now = s.local(s.com - s.support_center(h, both=p.crouch_plant), h)
                memo["held"] = float(now[0])
                bl.set_com_offset((memo["held"], bl.posture.com_offset[1]))
            bl.control(world, t)

        def thrust(world: World, t: float) -> None:
            del world
            memo["t_thrust"] = t
            memo.pop("ramp", None)
            memo.pop("capped", None)
            memo.pop("spun", None)
            memo.pop("apex_prev", None)
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
            bl.support(s)
            ramp = min(1.0, (t - memo["t_thrust"]) / STIFFNESS_RAMP)
            if memo.get("ramp", -1.0) < 1.0:  # the push's stiffness comes in smoothly
                memo["ramp"] = ramp
                ctx.rig.set_stiffness(memo["stiff0"] + ramp * (memo["stiff1"] - memo["stiff0"]))
            # the momentum feedbacks' ramp, and their unit of momentum (m L^2 rad/s)
            spin_ramp = min(1.0, (t - memo["t_thrust"]) / SPIN_RAMP)
            unit = ctx.athlete.mass * ctx.athlete.leg_length**2
            if p.spin_gain > 0:
                # whole-body angular momentum about the COM (mj_subtreeVel has run), pitch
                # axis of the heading frame: the hips tilt the push ahead of or behind the COM
                err = (pitch_momentum(world, s) - p.spin) / unit
                lim = p.spin_limit
                if p.rise_spin_limit > 0 and ("capped" in memo or "spun" in memo):
                    # give back the spin the cut push loses
                    lim = p.rise_spin_limit
                off = float(np.clip(spin_ramp * p.spin_gain * err, -lim, lim))
                ctx.rig.offset[hips, 0] = off
            if p.tilt_gain > 0:
                # roll and yaw momentum to zero, the hips tilting and turning the push about
                # the COM as the pitch feedback above
                tilt[:] = roll_momentum(world, s), world.data.subtree_angmom[s.root][2]
                scale = spin_ramp * p.tilt_gain / unit
                tilt[0] *= scale
                tilt[1] *= TILT_YAW * scale
                ctx.rig.offset[hips, 1:] = np.clip(tilt, -TILT_LIMIT, TILT_LIMIT)
            if p.rise_cap > 0 and "capped" not in memo:
                z_stand = ctx.standing_com if ctx.standing_com is not None else memo["z_stand"]
                vz = float(s.com_vel[2])
                apex = float(s.com[2]) - z_stand + vz * vz / (2.0 * g)
                if p.rise_lead > 0 or p.rise_spin_rate > 0:
                    t0, apex0 = memo.get("apex_prev", (t, apex))
                    memo["apex_prev"] = (t, apex)
                    if t > t0:
                        if 0 < p.rise_spin_rate <= (apex - apex0) / (t - t0) and vz > 0:
                            memo["spun"] = t  # an over-leap's last ticks: open the hips
                        apex += p.rise_lead * (apex - apex0) / (t - t0)
                if vz > 0 and apex >= p.rise_cap:
                    # the apex is reached ballistically: the knees and ankles stop extending
                    memo["capped"] = t
                    goal = np.full((NJ, 3), np.nan)
                    goal[knees + ankles] = ctx.rig.current_angles()[knees + ankles]
                    ctx.rig.move(goal, 0.0, t, knees + ankles)

        def com_thrust(world: World, t: float) -> None:
            # plan: from rest, the COM's acceleration ramps in over push_ramp, then stays
            # constant until the COM has the lift-off speed of the commanded rise, reached
            # push_end above standing (the COM is ballistic after lift-off)
            s = ctx.sense(t)
            rig = ctx.rig
            rig.move(rig.desired(t) + rig.offset, 0.0, t)
            rig.offset[:] = 0.0
            memo["stiff0"] = rig.stiffness.copy()
            memo["stiff1"] = per_joint({**COM_PUSH_STIFFNESS, "hip": p.push_hip,
                                        "ankle": p.push_ankle})  # fmt: skip
            # the balance's joint damping off the legs: at the push's joint speeds (10 rad/s)
            # it took the legs' extension
            rig.set_damping(per_joint({"waist": 0.1, "back": 0.1}))
            memo.pop("ramp", None)
            z0 = float(s.com[2])
            memo["z0"] = z0
            memo["pitch0"] = p.pitch + p.lean * float(np.mean(rig.knee_flexion()))
            z_stand = ctx.standing_com if ctx.standing_com is not None else memo["z_stand"]
            z_end = z_stand + p.push_end
            v_end = math.sqrt(2.0 * g * max(p.rise - p.push_end, 0.01))
            memo.pop("az_prev", None)
            memo.update(gain=1.0, t_thrust=t, t_prev=t, v_end=v_end, pushing=True, z_end=z_end,
                        z_stand=z_stand, acc=v_end**2 / (2.0 * max(z_end - z0, 0.05)),
                        com0=s.com.copy())  # fmt: skip
            goal = np.full((NJ, 3), np.nan)
            dur = v_end / memo["acc"]
            arms = [joint_index(f"{k}_shoulder") for k in "lr"]
            goal[arms] = (p.arms, 0.0, 0.0)
            for j in ("waist", "back"):
                goal[joint_index(j)] = 0.0
            rig.move(goal, dur, t, [*arms, joint_index("waist"), joint_index("back")])

        def com_push(world: World, t: float) -> None:
            s = ctx.sense(t)
            rig = ctx.rig
            tau = t - memo["t_thrust"]
            if memo.get("ramp", -1.0) < 1.0:
                ramp = min(1.0, tau / STIFFNESS_RAMP)
                memo["ramp"] = ramp
                rig.set_stiffness(memo["stiff0"] + ramp * (memo["stiff1"] - memo["stiff0"]))
            dt = t - memo["t_prev"]
            memo["t_prev"] = t
            h = s.heading()
            # the pelvis goes from the crouch's lean to upright over the planned push
            frac = 1.0 - min(1.0, tau * memo["acc"] / memo["v_end"]) ** 2
            pitch = frac * memo["pitch0"]
            hold_pelvis_and_feet(ctx, world.data, pitch, h, t)
            # the COM kept over the feet as the balance servo does: ankle (and half as much,
            # opposite, hip) pitch offsets from the horizontal COM error
            err = s.local(memo["com0"] - s.com, h)[0]
            dx = float(np.clip(ANKLE_KP * err - ANKLE_KV * s.local(s.com_vel, h)[0], -0.35, 0.35))
            rig.offset[:] = 0.0
            for j in ankles:
                rig.offset[j, 0] = -dx
            for j in hips:
                rig.offset[j, 0] = 0.5 * dx
            # the knees' targets follow them while their stiffness ramps out
            now = rig.current_angles()
            goal = np.full((NJ, 3), np.nan)
            goal[knees] = now[knees]
            rig.move(goal, 0.0, t, knees)
            bl.support(s)
            if p.push_both and memo["pushing"] and s.foot_contact.sum() == 1:
                # the shares by where the COM lies between the sole centres, not the contacts
                soles = s.corners.mean(axis=1)[:, :2]
                ab = soles[1] - soles[0]
                w = float(np.clip((s.com[:2] - soles[0]) @ ab / max(float(ab @ ab), 1e-9), 0, 1))
                rig.support[:] = (1.0 - w, w)
            if p.roll_gain > 0 and rig.support.all():
                # the cartwheel (roll) momentum to zero: weight moved onto the foot whose
                # push rolls the body back (the centre of pressure to that side of the COM)
                roll = roll_momentum(world, s) / (ctx.athlete.mass * ctx.athlete.leg_length**2)
                shift = float(np.clip(p.roll_gain * roll, -ROLL_SHIFT, ROLL_SHIFT))
                rig.support[:] = np.clip(rig.support + (-shift, shift), 0.0, 1.0)
            if not memo["pushing"]:
                rig.support_point = None
                rig.support[:] = 0.0
                return
            # the constant acceleration that brings the COM from where it is to the lift-off
            # speed at the push's end (a feedback: a lag asks for more, a lead for less)
            z, vz = float(s.com[2]), float(s.com_vel[2])
            v_need = math.sqrt(2.0 * g * max(p.rise - (z - memo["z_stand"]), 0.0))
            if vz >= v_need:
                memo["pushing"] = False  # the apex is reached ballistically: stop pushing
                rig.support[:] = 0.0
                return
            az = (memo["v_end"] ** 2 - vz * abs(vz)) / (2.0 * max(memo["z_end"] - z, 0.02))
            ramp = min(1.0, tau / p.push_ramp) if p.push_ramp > 0 else 1.0
            plan = 1.0 + memo["acc"] / g
            top = p.push_limit if plan <= p.push_limit else PUSH_HEADROOM * plan
            az = float(np.clip(ramp * az, -g, top * g - g))
            # the legs' feed-forward does not make its force one to one (the trunk and the
            # legs' own inertia add or take some): scale it by the last tick's measured
            # ground force (from the COM's momentum) against the one asked for
            if "az_prev" in memo and dt > 0:
                made = (vz - memo["vz_last"]) / dt + g
                want = memo["az_prev"] + g
                if made > 0.2 * g:
                    gain = memo["gain"] * math.sqrt(want / made)
                    memo["gain"] = float(np.clip(gain, 0.3, 3.0))
            memo["az_prev"], memo["vz_last"] = az, vz
            force = np.array([0.0, 0.0, (g + max(az, -g)) * memo["gain"]])
            size = float(np.linalg.norm(force))
            rig.support_scale = size / g
            rig.support_dir = force / max(size, 1e-9)
            if p.yaw_gain > 0:
                # the momentum about the vertical to zero: the feet's ground forces tilted
                # fore and aft in opposite senses (a couple about the vertical; the roll and
                # pitch untouched)
                yaw = world.data.subtree_angmom[s.root][2] / (
                    ctx.athlete.mass * ctx.athlete.leg_length**2
                )
                c = float(np.clip(p.yaw_gain * yaw, -YAW_TILT, YAW_TILT))
                # left foot's force tilted forward, the right's back, for a positive yaw
                dirs[:] = force / max(size, 1e-9)
                dirs[:, 0] += (c * math.cos(h), -c * math.cos(h))
                dirs[:, 1] += (c * math.sin(h), -c * math.sin(h))
                dirs[:] /= np.linalg.norm(dirs, axis=1, keepdims=True)
                rig.support_dir = dirs
            # the force acts on each foot under the COM (not through the ankle, where it
            # passed behind the COM and pitched the body forward), moved ahead or back by the
            # whole-body pitch momentum's error: the centre of pressure steers the momentum
            fwd = np.array([math.cos(h), math.sin(h), 0.0])
            mid = s.corners.mean(axis=1)  # (2, 3) sole centres
            err_l = (pitch_momentum(world, s) - p.spin) / (
                ctx.athlete.mass * ctx.athlete.leg_length**2
            )
            ahead = np.clip((s.com - mid) @ fwd + COP_GAIN * err_l, *COP_RANGE)
            rig.support_point = mid + ahead[:, None] * fwd

        def flight(world: World, t: float) -> None:
            s = ctx.sense(t)
            ctx.handover["liftoff_pitch_momentum"] = pitch_momentum(world, s)
            ctx.rig.set_stiffness(per_joint(FLIGHT_STIFFNESS))
            ctx.rig.support[:] = 0.0
            ctx.rig.support_scale = 1.0
            ctx.rig.support_dir = None
            ctx.rig.support_point = None

        def crouch_settled(_w: World, t: float, t_in: float) -> bool:
            # crouch_until: both feet down, the COM over the soles' middle sideways and still
            side, speed, cap = p.crouch_until
            if t_in < p.crouch + p.hold - 1e-12:
                return False
            if t_in >= p.crouch + p.hold + cap - 1e-12:
                return True
            s = ctx.sense(t)
            if not s.foot_contact.all():
                return False
            h = s.heading()
            off = s.local(s.com - s.support_center(h, both=True), h)
            return bool(abs(off[1]) < side and abs(s.local(s.com_vel, h)[1]) < speed)

        crouch_exit: Event = crouch_settled if p.crouch_until else after(p.crouch + p.hold)
        at_apex = p.handover == "apex" or (p.handover == "auto" and not p.broad)
        flight_exit: Event = apex(ctx) if at_apex else after(0.0)
        com = p.push == "com" and not p.broad
        return [
            State(
                "crouch",
                law(crouch_hold if p.hold_com else bl.control, every),
                crouch,
                ((crouch_exit, "thrust"),),
            ),
            State(
                "thrust",
                law(com_push, every) if com else law(push, every),
                com_thrust if com else thrust,
                ((liftoff(ctx), "flight"), (after(THRUST_TIMEOUT), "flight")),
            ),
            State("flight", None, flight, ((flight_exit, NEXT),)),
        ]
