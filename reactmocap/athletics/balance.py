"""Balance (thesis ch. 7): keep the centre of mass over the centre of the support area.

A PD servo on the horizontal COM error (heading frame) gives offsets ``delta`` that are added to
the ankles' targets and, at half and with the opposite sign, to the hips' (eqs. 7.1-7.2); the
ankles otherwise keep the feet flat on the floor (eqs. 7.3-7.4, on a slope: flat on the slope),
the hips keep the pelvis at the commanded pitch, and the knees set the pelvis height through
the law of cosines (eq. 7.5), leg by leg (so a leg on the uphill side of a slope bends more).
User parameters: torso pitch, pelvis height and a COM offset (:class:`Posture`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from types import MappingProxyType

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import EULER_ORDER, Athlete
from reactmocap.athletics.machine import NEXT, Basis, Context, law
from reactmocap.athletics.rig import joint_index, per_joint
from reactmocap.athletics.senses import Senses
from reactmocap.errors import ConfigError
from reactmocap.rotations import (
    quat_conj,
    quat_exp,
    quat_from_euler,
    quat_from_yaw,
    quat_mul,
    quat_to_euler,
)
from reactmocap.sim.bodies import BALL_JOINTS, SIM_BODY_INDEX
from reactmocap.sim.controllers.machine import Event, State, after
from reactmocap.sim.world import World

__all__ = [
    "ANKLE_LIMITS",
    "SETTLED",
    "BALANCE_GAINS",
    "STANDING_GAINS",
    "STANDING_BEND_RATE",
    "STANDING_BOW_EASE",
    "STANDING_LEG",
    "STANDING_STEP",
    "Balance",
    "BalanceGains",
    "BalanceLaw",
    "Posture",
    "Step",
    "Stepper",
    "knee_for_length",
    "knee_for_length1",
]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)
#: ankle pitch limits (rad): "joint limits prevent the ankles from extending beyond 90 degrees
#: or flexing beyond -68 degrees" (section 7.1)
ANKLE_LIMITS = (math.radians(-68.0), math.radians(90.0))
#: standing hip-to-ankle length as a fraction of the straight leg (a knee slightly unlocked)
STANDING_LEG = 0.985
_HIP = [joint_index(f"{s}_hip") for s in "lr"]
_KNEE = [joint_index(f"{s}_knee") for s in "lr"]
_ANKLE = [joint_index(f"{s}_ankle") for s in "lr"]
_SPINE = [joint_index(j) for j in ("waist", "back")]
_SHOULDER = np.array([joint_index(f"{s}_shoulder") for s in "lr"])


def knee_for_length(thigh: F64 | float, shin: F64 | float, length: F64 | float) -> F64:
    """Knee flexion (rad) that makes the hip-to-ankle distance ``length`` (eq. 7.5), and the
    hip flexion that keeps the pelvis over the ankle with the hip-ankle line vertical (eq. 7.6,
    returned negative: thigh forward)."""
    ul, ll = np.asarray(thigh, dtype=np.float64), np.asarray(shin, dtype=np.float64)
    # np.clip as the two ufuncs it is for finite bounds (its wrappers cost more than the sums;
    # the runner calls this at every flight tick)
    lh = np.minimum(np.maximum(np.asarray(length, dtype=np.float64), abs(ul - ll) + 1e-3),
                    ul + ll - 1e-6)  # fmt: skip
    knee = np.pi - np.arccos(
        np.minimum(np.maximum((ul**2 + ll**2 - lh**2) / (2 * ul * ll), -1.0), 1.0)
    )
    hip = -np.arccos(np.minimum(np.maximum((ul**2 - ll**2 + lh**2) / (2 * ul * lh), -1.0), 1.0))
    return np.stack([knee, hip])


def knee_for_length1(thigh: float, shin: float, length: float) -> tuple[float, float]:
    """:func:`knee_for_length` of one leg as two floats (the runner's flight ticks): the same
    operations in the same order on floats, and numpy's own ``arccos`` (``math.acos`` may
    round differently), so the same values to the bit (test) for a twentieth of the numpy
    calls. There ``thigh**2`` (a 0-d array) is numpy's square ``x * x``, but ``lh**2`` (the
    numpy scalar its clip returns) is C's ``pow``, as Python's float power is."""
    ul, ll = float(thigh), float(shin)
    lh = min(max(float(length), abs(ul - ll) + 1e-3), ul + ll - 1e-6)
    cos_knee = min(max((ul * ul + ll * ll - lh**2) / (2 * ul * ll), -1.0), 1.0)
    cos_hip = min(max((ul * ul - ll * ll + lh**2) / (2 * ul * lh), -1.0), 1.0)
    return float(np.pi - np.arccos(cos_knee)), float(-np.arccos(cos_hip))


@dataclass(frozen=True)
class Posture:
    """What the balance controller holds.

    Args:
        pitch: torso pitch (rad, forward > 0), made at the hips.
        leg: hip-to-ankle length as a fraction of the straight leg (the pelvis height through
            the law of cosines); :data:`STANDING_LEG` stands.
        com_offset: desired COM ``(x, y)`` relative to the support centre (m, heading frame).
        arms: shoulder pitch (rad; < 0 raises the arms forward).
        settle: seconds the joints take to reach a new posture (Hermite).
        lean: extra torso pitch per radian of knee flexion beyond standing (a squatting
            person leans forward, which keeps the COM over the feet).
        plant: settle a perturbed start onto both feet, flat: the COM target is the middle of
            both feet, not of those in contact (else a hanging foot stays up and the body
            leans over the other); a foot hanging over the floor while the other stands
            lengthens its leg and shortens the other by half its height each (as the slope
            leveling); and the COM servo's ankle pitch offset gives way by
            :data:`PLANT_GAIN` per metre that a standing sole's heel rises above its toes (or
            they above it) past :data:`PLANT_DEADBAND` (an offset past what the foot can
            push stood the body on its toes or heels).
        side_both: the COM target's sideways part (heading frame) is the middle of both
            soles (``plant``'s), along the feet that of the soles in contact (the target
            stays between the feet while one is unloaded; no ankle give, no foot lowered).
        level_hips: the legs' lengths also servo the hips' heights level (each leg
            lengthened by this times half the height by which its hip lies below the other's;
            0 off): a back handspring crouch on both feet rolled the pelvis 8 deg with the
            knees alike, and the thrust's extension about a rolled pelvis twists the body
            (docs/athletics.md).
    """

    pitch: float = 0.0
    leg: float = STANDING_LEG
    com_offset: tuple[float, float] = (0.0, 0.0)
    arms: float = 0.0
    settle: float = 0.5
    lean: float = 0.5
    plant: bool = False
    side_both: bool = False
    level_hips: float = 0.0

    def __post_init__(self) -> None:
        for name in ("plant", "side_both"):
            v = getattr(self, name)
            if not isinstance(v, bool):
                raise ConfigError(f"posture {name} must be true or false, got {v!r}")
        for name in ("pitch", "leg", "arms", "settle", "lean", "level_hips"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ConfigError(f"posture {name} must be a finite number, got {v!r}")
        if not 0.3 <= self.leg <= 1.0:
            raise ConfigError(f"posture leg must be within [0.3, 1.0] of the leg, got {self.leg}")
        if len(self.com_offset) != 2 or not all(math.isfinite(v) for v in self.com_offset):
            raise ConfigError(f"posture com_offset must be 2 finite numbers, got {self.com_offset}")
        if not 0.0 <= self.level_hips <= 20.0:
            raise ConfigError(f"posture level_hips must be in [0, 20], got {self.level_hips}")


@dataclass(frozen=True)
class Step:
    """A step when the capture point leaves the feet (the balance's own ankles and hips cannot
    bring back a COM whose capture point lies past the soles' edge).

    Args:
        margin: the step starts once the capture point (COM + velocity / omega, LIPM) lies
            more than this (m) past the supporting soles' edge along the feet (fore-aft,
            heading frame; :data:`STEP_SIDEWAYS`: across them too) while the COM moves that
            way; the foot farther from the capture point swings.
        reach: the swing foot is aimed this far (m) past the capture point (updated each
            tick), at most :data:`STEP_LONGEST` from the standing foot; the swing leg is
            made as long as it takes to reach the floor there (a level floor).
        lift: knee flexion (rad) added to the swing leg over the swing (a half sine: the
            foot clears the floor).
        seconds: the swing's planned duration; the step ends when the swing foot touches
            down after half of it (or at three times it).
        across: on a step along the feet that would land under its own hip (a closing step
            too), the swing foot lands at least this far (m) past the capture point across
            the feet, on its own side (0: under its hip; opt-in, docs/athletics.md "The
            standing step's first single support").
        ground: from the swing's middle on, the swing leg is aimed from the hip's height as
            it is (not from where the standing knee's bend for the reach will lower it) and
            made at most this fraction of the straight leg, its place pulled in toward the hip
            to where such a leg meets the floor (0: off, :data:`STEP_REACH` and the place past
            the capture point, where the foot hung over the floor until the body sank;
            docs/athletics.md "The standing step's swing shortened"; on the standing
            balance's sideways steps not at all: her 110 N left push was lost;
            :data:`STANDING_STEP` 0.99 with ``bow_hold``).
        give: at the touchdown of a step along the feet (a sideways one as without: her
            110 N left push was lost) the landed knee's target bends this much more (rad)
            than its angle there, as a critically damped spring over ``give_time``, and the
            other ankle's target is held at its angle there (the rear foot kept on its toes,
            not turned flat: that lifted them off within 8 ms), both eased back to the law's
            over :data:`STEP_GIVE_BACK` ``give_time``s more (0: off; the hips follow as
            without: the law holds the pelvis's pitch whatever the thighs do; opt-in,
            docs/athletics.md "The standing step's landed knee yields").
        give_time: the seconds of ``give``'s bend (in [0.02, 0.5]).
        foresee: with ``across``, the capture point across the feet taken where the COM's
            sideways speed will have carried it (LIPM about the standing foot) this many
            seconds after the swing began, not where it is (0: where it is, and the COM still
            fell on past the landed foot; opt-in, docs/athletics.md "The standing step's
            landed knee yields").
        down_after: from this many seconds into the swing on, the place is the floor under
            where the swing foot was then (the leg aimed straight down there, lengthened to
            reach it) instead of past the capture point (0: off; opt-in: the male back
            handspring's landing steps hung 3-5 cm over the floor, the foot 0.2-0.3 m beside
            its place, until the swing's limit, docs/athletics.md "the step put down").
        hang_still: before the run's first step, a foot left hanging by the standing balance
            is planted (:data:`STANDING_HANG`) once the COM is slower than this (m/s) instead
            of :data:`STANDING_STILL` (0: off; :data:`STANDING_STEP` 0.25: her 85 N right push
            hung a foot for 0.8 s at 0.10 m/s until a step fired; the 16 pushes' limits 2255
            -> 2425 N, none lower; docs/athletics.md "What follows the standing step's first
            touchdown").
        hang_near: with ``hang_still``, that plant also waits until the COM lies within this
            (m, horizontal) of the supporting sole's middle (0: off; opt-in: the forward tuck's
            hung foot put down 9-11 cm off the support kept it on one foot, docs/athletics.md
            "Forward tuck: the hung foot put down near the support").
        pair: after the run's first step, the next starts only once the capture point lies
            more than this (m) past the box of both soles, a lifted one counted, in either
            axis (the COM's sideways speed in it); while it lies within, a foot that hangs is
            planted at once (:attr:`Posture.plant`; 0: off, the box of the soles in contact
            and ``margin``, and the rear foot that rolled off the floor after the first
            touchdown was swung while the COM went on sideways; opt-in, docs/athletics.md
            "The standing step's bow held through the swing").
        bow_hold: during a swing the hip strategy's bow (:attr:`BalanceGains.bow_ease`)
            eases out over this many seconds instead (0: off, the gains' 0.15 s; the pelvis
            pitching back at up to 6 rad/s took the lagging swing thigh up with it and the
            foot 0.2-0.3 m over the floor; on a step along the feet only; docs/athletics.md
            "The standing step's bow held through the swing"; :data:`STANDING_STEP` 1.0).
        knees: at a step's touchdown both knees' targets go this share of the way (in [0, 1])
            from their last ones to their mean, the legs alike (0: off, the last ones: each
            stepped leg's is its swing's, and after the male back handspring's two landing
            steps the legs stood 0.17-0.19 rad apart in the knee, the pelvis rolled 15-20 deg
            and the COM drifted out over the more bent one on both feet; to the posture's
            knees lost more starts; docs/athletics.md "kind (c)").
        hang_plant: on a stepper that is not the standing balance's (the landing's, carried
            on by the balance after it), the posture's plant (:attr:`Posture.plant`) on once
            a foot has hung this many seconds with no swing under way (0: off; in [0, 2] s;
            opt-in: male back handspring starts stood 1-2 s on one foot after the landing,
            then a step's swing never came down; docs/athletics.md "the last falling
            starts").
        plant_settle: when the standing balance plants a hung foot, the posture's stand-up
            (knees, spine, arms, the pelvis's pitch) starts again from where its targets
            are, at rest, and reaches the posture over this many seconds (0: off, it runs
            on over the posture's settle; opt-in: the forward tuck's stand-up bounced the
            hung foot off the floor, docs/athletics.md "Forward tuck: the stand-up
            restarted at the plant").
    """

    margin: float = 0.05
    reach: float = 0.1
    lift: float = 0.3
    seconds: float = 0.25
    across: float = 0.0
    ground: float = 0.0
    give: float = 0.0
    give_time: float = 0.1
    foresee: float = 0.0
    down_after: float = 0.0
    hang_still: float = 0.0
    hang_near: float = 0.0
    pair: float = 0.0
    bow_hold: float = 0.0
    knees: float = 0.0
    hang_plant: float = 0.0
    plant_settle: float = 0.0

    def __post_init__(self) -> None:
        names = ("margin", "reach", "lift", "seconds", "across", "ground", "give", "foresee")
        for name in names:
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise ConfigError(f"step {name} must be a finite number >= 0, got {v!r}")
        if not 0.05 <= self.seconds <= 2.0:
            raise ConfigError(f"step seconds must be in [0.05, 2], got {self.seconds}")
        if self.ground and not 0.5 <= self.ground <= 1.0:
            raise ConfigError(f"step ground must be 0 or in [0.5, 1], got {self.ground}")
        if not self.give <= 1.0:
            raise ConfigError(f"step give must be in [0, 1] rad, got {self.give}")
        g = self.give_time
        if not (isinstance(g, (int, float)) and math.isfinite(g) and 0.02 <= g <= 0.5):
            raise ConfigError(f"step give_time must be in [0.02, 0.5] s, got {g!r}")
        if self.foresee and not (self.across and self.foresee <= 1.0):
            raise ConfigError(f"step foresee must be 0 or in (0, 1] s, with across: {self.foresee}")
        if not (isinstance(self.down_after, (int, float)) and 0.0 <= self.down_after <= 2.0):
            raise ConfigError(f"step down_after must be in [0, 2] s, got {self.down_after!r}")
        ranges = (("hang_still", 1.0, "m/s"), ("hang_near", 0.3, "m"), ("bow_hold", 5.0, "s"),
                  ("pair", 0.3, "m"), ("knees", 1.0, "of the way"), ("hang_plant", 2.0, "s"),
                  ("plant_settle", 5.0, "s"))  # fmt: skip
        for name, hi, unit in ranges:
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and 0.0 <= v <= hi):
                raise ConfigError(f"step {name} must be in [0, {hi:g}] {unit}, got {v!r}")

    @classmethod
    def of(cls, values: Step | Sequence[float] | None) -> Step | None:
        """A step from a parameter list ``[margin, reach, lift, seconds]`` (any leading
        part; the rest default), or ``None`` for an empty one (off)."""
        if values is None or isinstance(values, Step):
            return values
        v = tuple(values)
        if not v:
            return None
        if len(v) > 4:
            raise ConfigError(
                f"step takes at most 4 numbers (margin, reach, lift, seconds), got {v}"
            )
        return cls(*(float(x) for x in v))


@dataclass(frozen=True)
class BalanceGains:
    """COM servo gains (rad/m and rad s/m) and the joint stiffness (units of ``m g L`` N m/rad)
    and damping (``m L sqrt(g L)`` N m s/rad) while balancing."""

    kp: float = 2.0
    kv: float = 0.5
    max_offset: float = 0.35
    #: COM target moved uphill by these times the floor's gradient (m; heading frame, along
    #: and across the feet): sideways, the feet slide downhill first; along them a shift
    #: downhill (< 0) measured better (docs/athletics.md)
    uphill: tuple[float, float] = (0.0, 0.0)
    #: on a sideways slope, the sideways offset's multiples on the ankles' and the hips' roll
    #: (level floor: the thesis's 1 and -0.5), blended in over the first :data:`SIDE_SLOPE`
    #: of gradient: an ankle roll offset tips each foot onto its downhill edge, and a foot on
    #: one edge creeps downhill in MuJoCo's soft contact at half the friction cone
    #: (docs/athletics.md); ``None``: the thesis's everywhere
    side_roll: tuple[float, float] | None = None
    #: hip strategy ``(gain, margin, forward, back)``: the pelvis pitched toward the fall by
    #: ``gain`` rad per metre that the capture point (COM + velocity / omega) lies beyond
    #: ``margin`` m of the COM target along the feet while the COM moves that way (a COM on
    #: its way to a moved target sets nothing off), at most ``forward`` / ``back`` rad, while
    #: both feet are down: once the ankles have the centre of pressure at the toe or heel, the
    #: trunk's rotation moves the hips back against the fall (angular momentum about the COM;
    #: on one foot it cost the female's diagonal push 5 N, docs/athletics.md); ``None``: off
    bow: tuple[float, float, float, float] | None = None
    #: with a foot up the bow eases out over this many seconds (first order) instead of
    #: dropping at once (with a step, the trunk snapping upright as the swing foot lifted
    #: kicked the standing foot off the floor; eased only while a foot swings, the female's
    #: sideways step ended on one foot, docs/athletics.md); ``None``: at once
    bow_ease: float | None = None
    #: arm strategy ``(gain, margin, limit)``: while the capture point lies more than
    #: ``margin`` m behind the COM target and the support centre along the feet, both arms are
    #: raised forward by ``gain`` rad per metre beyond the target's margin, at most ``limit``
    #: rad (their mass goes ahead and their swing turns the body forward, against the fall);
    #: backward only: swung back on a forward fall they cost the male's front-right push 20 N
    #: (docs/athletics.md); ``None``: off
    arms: tuple[float, float, float] | None = None
    #: arm windmilling ``(rate, margin)``: while the capture point lies more than ``margin`` m
    #: beyond the COM target and the support centre along the feet, both arms
    #: circle at ``rate`` rad/s in the sense whose reaction pitches the body against the fall
    #: (back-up-over on a forward fall), and finish the circle they are on once it is back
    #: (their momentum given back when the COM is caught); ``None``: off
    windmill: tuple[float, float] | None = None
    #: sideways arm windmilling ``(rate, margin, lean)``: as ``windmill`` across the feet,
    #: both arms circling about the fore-aft axis (roll) at ``rate`` rad/s in the sense
    #: whose reaction rolls the body against a sideways fall, the circle's plane tipped
    #: ``lean`` rad forward so the arms pass in front of the hips and behind the head (the
    #: body does not collide with itself), only while the arms do not circle fore-aft; opt-in:
    #: the female's sideways push 75 -> 95 N but her front diagonals lost 10-25 N
    #: (docs/athletics.md); ``None``: off
    windmill_side: tuple[float, float, float] | None = None
    #: the sideways COM servo's gains (``kp``, ``kv``) as a multiple of the fore-aft ones
    #: (the leap's crouch on yawed feet drifts sideways: docs/athletics.md)
    side: float = 1.0
    stiffness: tuple[tuple[str, float], ...] = (
        ("waist", 2.0), ("back", 2.0), ("neck", 0.3), ("shoulder", 0.3), ("elbow", 0.15),
        ("wrist", 0.05), ("hip", 3.0), ("knee", 3.0), ("ankle", 3.0),
    )  # fmt: skip
    damping: tuple[tuple[str, float], ...] = (
        ("waist", 0.1), ("back", 0.1), ("hip", 0.15), ("knee", 0.15), ("ankle", 0.2),
    )  # fmt: skip

    def __post_init__(self) -> None:
        for name in ("uphill", "side_roll"):
            v = getattr(self, name)
            if v is not None and (len(v) != 2 or not all(math.isfinite(x) for x in v)):
                raise ConfigError(f"balance {name} must be 2 finite numbers, got {v!r}")
        b = self.bow
        if b is not None and (len(b) != 4 or not all(math.isfinite(x) and x >= 0 for x in b)):
            raise ConfigError(
                f"balance bow must be 4 finite numbers >= 0 (gain rad/m, margin m, forward "
                f"and back limits rad), got {b!r}"
            )
        if self.bow_ease is not None and not (math.isfinite(self.bow_ease) and self.bow_ease > 0):
            raise ConfigError(f"balance bow_ease must be > 0 s, got {self.bow_ease!r}")
        if not (math.isfinite(self.side) and 0.0 < self.side <= 5.0):
            raise ConfigError(
                f"balance side must be in (0, 5] (a multiple of kp, kv), got {self.side!r}"
            )
        w = self.windmill
        if w is not None and (len(w) != 2 or not all(math.isfinite(x) and x >= 0 for x in w)):
            raise ConfigError(
                f"balance windmill must be 2 finite numbers >= 0 (rate rad/s, margin m), got {w!r}"
            )
        ws = self.windmill_side
        if ws is not None and (
            len(ws) != 3
            or not all(math.isfinite(x) and x >= 0 for x in ws[:2])
            or not abs(ws[2]) <= 0.5 * math.pi
        ):
            raise ConfigError(
                f"balance windmill_side must be (rate rad/s >= 0, margin m >= 0, lean rad in "
                f"[-pi/2, pi/2]), got {ws!r}"
            )
        a = self.arms
        if a is not None and (len(a) != 3 or not all(math.isfinite(x) and x >= 0 for x in a)):
            raise ConfigError(
                f"balance arms must be 3 finite numbers >= 0 (gain rad/m, margin m, limit "
                f"rad), got {a!r}"
            )

    def stiffness_array(self) -> F64:
        return per_joint(dict(self.stiffness))

    def damping_array(self) -> F64:
        return per_joint(dict(self.damping))


#: :attr:`Posture.plant`: the ankle pitch offset given way (rad) per metre of a standing
#: sole's tilt past the dead band (m)
PLANT_GAIN = 10.0
PLANT_DEADBAND = 0.015
#: what "settled" means for :class:`Balance` (a perturbed start before a leap): each foot
#: bears this share of the body weight (contact force low-passed over ``tau`` s), the COM
#: moves slower than ``speed`` (m/s, horizontal) within ``offset`` (m) of the balance's COM
#: target, all for ``hold`` s in a row
SETTLED = MappingProxyType({"share": 0.2, "tau": 0.05, "speed": 0.05, "offset": 0.03, "hold": 0.2})
#: :attr:`BalanceGains.windmill` only on a floor less steep than this (tan): on a 33 deg
#: sideways slope the circling arms tipped the female over (docs/athletics.md)
WINDMILL_SLOPE = 0.05
#: sideways gradient (tan of the slope) over which :attr:`BalanceGains.side_roll` comes in
SIDE_SLOPE = 0.2
#: :class:`Step`: the longest step (m, the swing foot's target from the standing foot along
#: the feet), the most the swing leg swings from under its hip (sine, as the landing's
#: ``swing_cap``), the seconds after a step before the next may start
STEP_LONGEST = 0.7
STEP_SWING_CAP = 0.8
STEP_PAUSE = 0.1
#: seconds after a step within which a foot left hanging is brought down beside the other
STEP_CLOSE = 1.0
#: the least sideways distance (m) between the soles' middles a step leaves
STEP_WIDTH = 0.12
#: steps go sideways too (the capture point's way out of the soles' box in both axes, a foot
#: crossing over the other if it must); off: on the male back handspring's first 16 perturbed
#: starts it stepped the landers that stand sideways and lost 1-2 of 5 (docs/athletics.md)
STEP_SIDEWAYS = False
#: how much longer (m) the swing leg reaches than the standing ankle's height, by the end of
#: the swing (without it the foot hovered 2-3 cm over the floor, the servo's sag)
STEP_PRESS = 0.05
#: time constant (s) of the swing hip's target's approach to its aim
STEP_EASE = 0.05
#: the longest the swing leg is made (fraction of the straight leg)
STEP_REACH = 0.97
#: the least seconds the knees take back to the posture's after a step
STEP_SETTLE = 0.2
#: :attr:`Step.give`'s return to the law's targets, in ``give_time``s
STEP_GIVE_BACK = 1.0
BALANCE_GAINS = BalanceGains()
#: standing on its own (the ``balance`` behaviour: pushes and slopes): the COM target moved
#: 0.07 m per unit gradient uphill across the feet and 0.03 m downhill along them (the
#: sideways slope balanced 19.5 -> 23.5-25.5 deg, docs/athletics.md), and on a sideways
#: slope the sideways offset on the hips, not the ankles (23.5-25.5 -> 30-33.5 deg); a hip
#: strategy (``bow``: the male's push forward 120 -> 135 N and back 160 -> 175 N, no direction
#: lower, docs/athletics.md; the back limit 0.35 rad, about a hip's extension; from gain 25 on
#: the bow hops the feet); an arm strategy (``arms``: the push back 175 -> 185 N male, 60 -> 65
#: female, no direction lower); arm windmilling (``windmill``, 8 rad/s: the male's push
#: forward 135 -> 165 N and back 185 -> 200 N, the female's 90 -> 95 and 65 -> 75, the feet
#: kept down, docs/athletics.md); otherwise as :data:`BALANCE_GAINS`
STANDING_GAINS = BalanceGains(uphill=(-0.03, 0.07), side_roll=(0.0, -1.0),
                              bow=(20.0, 0.05, 1.0, 0.35), arms=(40.0, 0.05, 2.0),
                              windmill=(8.0, 0.05))  # fmt: skip
#: the ``balance`` behaviour's opt-in step (``step="on"``; :class:`Stepper`'s ``standing``),
#: with :attr:`BalanceGains.bow_ease` this many seconds, the standing knee bending at most
#: :data:`STANDING_BEND_RATE` (rad/s) for the swing leg's reach; a foot hung before the first
#: step planted under a COM slower than 0.25 m/s (:attr:`Step.hang_still`); on a step along
#: the feet the bow eased out over 1 s during the swing (:attr:`Step.bow_hold`) and the foot
#: aimed at the floor from the hip as it is (:attr:`Step.ground` 0.99): the 16 pushes' limits
#: 2425 -> 2430 N (his forward 170 -> 175), none lower (docs/athletics.md "The standing
#: step's bow held through the swing")
STANDING_STEP = Step(hang_still=0.25, ground=0.99, bow_hold=1.0)
STANDING_BOW_EASE = 0.15
STANDING_BEND_RATE = 1.5
#: the standing step's end: once one foot alone has been down for :data:`STANDING_HANG` s
#: (no step for :data:`STEP_PAUSE`) with the COM slower than :data:`STANDING_STILL` m/s, the
#: posture's :attr:`~Posture.plant` goes on (the COM target the middle of both feet, the
#: hanging foot's leg lengthened): the foot comes down and stays loaded (both feet required,
#: the 16 pushes' limits 2165 -> 2255 N, none lower; a closing swing put the foot down and it
#: lifted again; docs/athletics.md)
STANDING_HANG = 0.2
STANDING_STILL = 0.08


class BalanceLaw:
    """The per-tick balance law on a context (used by :class:`Balance` and by the leap's crouch
    and the landing's recovery). :meth:`set_posture` moves the posture targets smoothly."""

    def __init__(self, ctx: Context, gains: BalanceGains = BALANCE_GAINS) -> None:
        self.ctx = ctx
        self.gains = gains
        self.posture = Posture()
        self.athlete: Athlete = ctx.athlete
        a = self.athlete
        self.heading = 0.0
        self.com_target = np.zeros(3)
        #: the COM offset eased from (set_posture's ease_com), or None, and over how many
        #: seconds (None: the posture's settle)
        self._com0: tuple[float, float] | None = None
        self._com_over: float | None = None
        #: :attr:`BalanceGains.windmill` (index 0, pitch) and ``windmill_side`` (1, roll): the
        #: arms' circle (rad), its sense; the last tick
        self._wind = [0.0, 0.0]
        self._wind_dir = [0.0, 0.0]
        self._t_wind = math.nan
        #: :attr:`BalanceGains.bow_ease`: the bow applied last, its tick
        self._bow_now = 0.0
        self._t_bow = math.nan
        #: a step when the capture point leaves the feet (:class:`Step`), or None
        self.stepper: Stepper | None = None
        #: the pelvis's roll target (rad, heading frame; 0 upright): the landing's roll_ease
        self.roll = 0.0
        #: the share of the COM servo's stance-hip pitch offset kept (1: all; the landing's
        #: held_hip_share after a held absorb, carried to the balance after it)
        self.hip_share = 1.0
        self._knee_standing = float(np.mean(knee_for_length(
            a.thigh, a.shin, STANDING_LEG * (a.thigh + a.shin))[0]))  # fmt: skip

    def set_posture(
        self, posture: Posture, t: float, gains: bool = True, ease_com: bool = False,
        com_over: float | None = None, pitch_from: float | None = None,
    ) -> None:  # fmt: skip
        """Move the knees, spine and arms toward ``posture`` over ``posture.settle`` s;
        ``ease_com``: the COM target's offset too, from the last posture's (a step in it
        steps the COM servo's ankle offsets: a broad jump's 17 cm hopped the body off the
        floor as its crouch began), over ``com_over`` s if given (else ``posture.settle``);
        ``pitch_from``: the pelvis pitch target (rad) to start from, else the pelvis's pitch."""
        self._com0 = self.posture.com_offset if ease_com else None
        self._com_over = com_over
        self.posture = posture
        rig = self.ctx.rig
        if gains:
            rig.set_stiffness(self.gains.stiffness_array())
            rig.set_damping(self.gains.damping_array())
        goal = np.full((NJ, 3), np.nan)
        knees = knee_for_length(self.athlete.thigh, self.athlete.shin,
                                posture.leg * (self.athlete.thigh + self.athlete.shin))  # fmt: skip
        for k in range(2):
            goal[_KNEE[k]] = (knees[0, k], 0.0, 0.0)
        for j in _SPINE + [joint_index("neck")]:
            goal[j] = 0.0
        for s in "lr":
            goal[joint_index(f"{s}_shoulder")] = (posture.arms, 0.0, 0.0)
            goal[joint_index(f"{s}_elbow")] = (0.0, 0.0, 0.0)
            goal[joint_index(f"{s}_wrist")] = 0.0
        moving = [j for j in range(NJ) if not np.isnan(goal[j]).all()]
        rig.move(goal, posture.settle, t, moving)
        # the commanded pitch starts from where the pelvis is (less the new posture's lean)
        self._pitch0 = (self.pelvis_pitch() if pitch_from is None else pitch_from) - self.lean()
        self._t_pitch = t

    def set_com_offset(self, offset: tuple[float, float]) -> None:
        """The COM target's offset from the support centre (m, heading frame) from now on, at
        once (any ease of :meth:`set_posture`'s ``ease_com`` ends)."""
        self.posture = replace(self.posture, com_offset=offset)
        self._com0 = None

    def pelvis_roll(self, heading: float) -> float:
        """Current anatomical roll of the pelvis (rad) in the frame of ``heading``, as
        :func:`hold_pelvis_and_feet` composes it."""
        d = self.ctx.world.data
        q = quat_mul(d.xquat[self.ctx.senses.root], quat_conj(self.athlete.neutral[0]))
        return float(quat_to_euler(quat_mul(quat_conj(quat_from_yaw(heading)), q), EULER_ORDER)[1])

    def pelvis_pitch(self) -> float:
        """Current anatomical pitch of the pelvis (rad, forward > 0)."""
        d = self.ctx.world.data
        q = quat_mul(d.xquat[self.ctx.senses.root], quat_conj(self.athlete.neutral[0]))
        return float(quat_to_euler(q, EULER_ORDER)[0])

    def lean(self) -> float:
        """Forward trunk lean (rad) the posture adds for the knees' bend past standing."""
        if not self.posture.lean:
            return 0.0
        knee = float(np.mean(self.ctx.rig.knee_flexion()))
        return self.posture.lean * max(0.0, knee - self._knee_standing)

    def _eased(self, t: float, over: float | None = None) -> float:
        """How far (0-1, Hermite, as the pitch) the posture set last has come, or an ease of
        ``over`` s begun with it (the pitch keeps its own sum's operation order: the figures
        were measured on it)."""
        if not hasattr(self, "_t_pitch"):
            return 1.0
        span = self.posture.settle if over is None else over
        s = min(max((t - self._t_pitch) / max(span, 1e-9), 0.0), 1.0)
        return s * s * (3 - 2 * s)

    def _pitch_now(self, t: float) -> float:
        if not hasattr(self, "_t_pitch"):
            return self.posture.pitch
        s = min(max((t - self._t_pitch) / max(self.posture.settle, 1e-9), 0.0), 1.0)
        return self._pitch0 + (self.posture.pitch - self._pitch0) * s * s * (3 - 2 * s)

    def pitch_target(self, t: float) -> float:
        """The pelvis pitch target (rad, forward > 0) at ``t``, as :meth:`control` commands it."""
        return self._pitch_now(t) + self.lean()

    def control(self, world: World, t: float) -> None:
        ctx = self.ctx
        s = ctx.sense(t)
        d = world.data
        rig = ctx.rig
        g = self.gains
        h = s.heading()
        self.heading = h
        centre = s.support_center(h, both=self.posture.plant)
        c, sn = math.cos(h), math.sin(h)
        if self.posture.side_both and not self.posture.plant:
            # across the feet the middle of both soles, along them the soles in contact
            across = float((s.support_center(h, both=True) - centre)[:2] @ (-sn, c))
            centre[0] -= sn * across
            centre[1] += c * across
        ox, oy = self.posture.com_offset
        if self._com0 is not None:  # set_posture's ease_com
            w = self._eased(t, self._com_over)
            ox, oy = (
                self._com0[0] + (ox - self._com0[0]) * w,
                self._com0[1] + (oy - self._com0[1]) * w,
            )
        target = centre.copy()
        target[0] += c * ox - sn * oy
        target[1] += sn * ox + c * oy
        ahead = ox  # the target ahead of the support centre, along the feet
        roll = (1.0, -0.5)
        left = oy  # the target left of the support centre
        if any(g.uphill) or g.side_roll is not None:
            n = s.floor_normal
            grad = s.local(-n / max(float(n[2]), 1e-6), h)  # the floor's gradient, heading frame
            up = grad * g.uphill
            target[0] += c * up[0] - sn * up[1]
            target[1] += sn * up[0] + c * up[1]
            ahead += float(up[0])
            left += float(up[1])
            if g.side_roll is not None:
                w = min(abs(float(grad[1])) / SIDE_SLOPE, 1.0)
                roll = (1.0 + w * (g.side_roll[0] - 1.0), -0.5 + w * (g.side_roll[1] + 0.5))
        self.com_target = target
        err = s.local(target - s.com, h)
        vel = s.local(s.com_vel, h)
        delta = g.kp * err - g.kv * vel
        delta[1] *= g.side
        np.clip(delta, -g.max_offset, g.max_offset, out=delta)
        pitch = self.pitch_target(t)
        cp = cp_side = 0.0
        if any(x is not None for x in (g.bow, g.arms, g.windmill, g.windmill_side)):
            omega = math.sqrt(9.81 / max(float(s.com[2] - centre[2]), 0.3))  # LIPM
            cp = float(vel[0]) / omega - float(err[0])  # capture point ahead of the target
            cp_side = float(vel[1]) / omega - float(err[1])  # ... and left of it
        if g.bow is not None and g.bow_ease is not None:
            pitch += self._bow_eased(cp, float(vel[0]), bool(s.foot_contact.all()), t)
        elif g.bow is not None and bool(s.foot_contact.all()):
            pitch += self._bow(cp, float(vel[0]))
        hold_pelvis_and_feet(ctx, d, pitch, h, t, self.roll)
        rig.offset[:] = 0.0
        for k in range(2):
            rig.offset[_ANKLE[k], 0] = -delta[0]
            rig.offset[_ANKLE[k], 1] = roll[0] * delta[1]
            rig.offset[_HIP[k], 0] = 0.5 * delta[0] * self.hip_share
            rig.offset[_HIP[k], 1] = roll[1] * delta[1]
        if g.arms is not None:
            gain, margin, limit = g.arms
            # behind the support centre too: a COM on its way to a target moved ahead is left be
            behind = cp + ahead < -margin
            rig.offset[_SHOULDER, 0] = -min(gain * max(-cp - margin, 0.0), limit) * behind
        if g.windmill is not None or g.windmill_side is not None:
            n = s.floor_normal
            level = math.hypot(float(n[0]), float(n[1])) < WINDMILL_SLOPE * float(n[2])
            dt = 0.0 if math.isnan(self._t_wind) else max(t - self._t_wind, 0.0)
            self._t_wind = t
            if g.windmill is not None:
                rig.offset[_SHOULDER, 0] += self._windmill(0, cp, ahead, dt, level, *g.windmill)
            if g.windmill_side is not None:
                rate, margin, lean = g.windmill_side
                # a fall to the left (+y) is a roll about -x: the arms roll that way too; only
                # while the arms do not circle fore-aft (with both, or on whichever fall ran
                # more across the feet, the front diagonals lost 10-55 N, docs/athletics.md)
                across = -cp_side * (self._wind_dir[0] == 0.0)
                spin = self._windmill(1, across, -left, dt, level, rate, margin)
                rig.offset[_SHOULDER, 1] += spin
                rig.offset[_SHOULDER, 0] -= lean * (self._wind_dir[1] != 0.0)
        lo, hi = ANKLE_LIMITS
        desired = rig.desired(t)
        for k in range(2):
            total = desired[_ANKLE[k], 0] + rig.offset[_ANKLE[k], 0]
            rig.offset[_ANKLE[k], 0] += float(np.clip(total, lo, hi)) - total
        hang = self._plant(s, d, h) if self.posture.plant else None
        self._level_legs(d, desired, hang)
        self.support(s)
        if self.stepper is not None:
            self.stepper.control(self, d, h, t)

    def _windmill(
        self, k: int, cp: float, ahead: float, dt: float, level: bool, rate: float, margin: float
    ) -> float:
        """The arms' circle (rad) about axis ``k`` (0: pitch, :attr:`BalanceGains.windmill`;
        1: roll, ``windmill_side``) for the capture point ``cp`` beyond the COM target in that
        circle's positive sense, the target ``ahead`` of the support centre that way; off the
        level (:data:`WINDMILL_SLOPE`) the arms only finish their circle."""
        # beyond the support centre's margin too: a COM on its way to a moved target is left be
        fwd = cp > margin and cp + ahead > margin
        back = cp < -margin and cp + ahead < -margin
        falling = level and (fwd or back)
        if falling:  # forward: the arms go back and over (pitch > 0), else the other way
            self._wind_dir[k] = 1.0 if cp > 0.0 else -1.0
        sense = self._wind_dir[k]
        nxt = self._wind[k] + sense * rate * dt
        if not falling and sense:  # caught: finish the circle the arms are on
            turn = self._wind[k] / (2.0 * math.pi)
            whole = math.ceil(turn - 1e-9) if sense > 0 else math.floor(turn + 1e-9)
            end = 2.0 * math.pi * whole
            if (nxt - end) * sense >= 0.0:
                nxt, self._wind_dir[k] = end, 0.0
        self._wind[k] = nxt
        return nxt

    def _bow_eased(self, cp: float, vel: float, both: bool, t: float) -> float:
        """:meth:`_bow` on both feet; with a foot up, the last one easing out over
        :attr:`BalanceGains.bow_ease` s (first order) instead of at once."""
        dt = 0.0 if math.isnan(self._t_bow) else max(t - self._t_bow, 0.0)
        self._t_bow = t
        if both:
            self._bow_now = self._bow(cp, vel)
        else:
            tau = self.gains.bow_ease or 0.0
            st = self.stepper
            if st is not None and st.step.bow_hold and st.along():  # Step.bow_hold
                tau = st.step.bow_hold
            self._bow_now *= math.exp(-dt / max(tau, 1e-9))
        return self._bow_now

    def _bow(self, cp: float, vel: float) -> float:
        """:attr:`BalanceGains.bow`'s pitch (rad, forward > 0) for the capture point ``cp``
        ahead of the COM target and the COM's velocity ``vel`` along the feet."""
        gain, margin, forward, back = self.gains.bow  # type: ignore[misc]
        if cp * vel <= 0.0:  # the COM on its way back (or to a moved target)
            return 0.0
        beyond = math.copysign(max(abs(cp) - margin, 0.0), cp)
        return float(np.clip(gain * beyond, -back, forward))

    def _plant(self, s, d, h: float) -> F64:  # type: ignore[no-untyped-def]
        """:attr:`Posture.plant`'s ankle give (on the rig's offsets); returns each foot's
        height to bring down (m; 0 unless it hangs while the other stands)."""
        corners = s.corners
        fwd = s.local(corners, h)[..., 0]
        back = np.where(fwd < fwd.mean(axis=1, keepdims=True), 0.5, -0.5)
        tilt = (back * corners[..., 2]).sum(axis=1)  # heel over toes (m), each foot
        excess = np.sign(tilt) * np.maximum(np.abs(tilt) - PLANT_DEADBAND, 0.0)
        self.ctx.rig.offset[_ANKLE, 0] -= PLANT_GAIN * excess * s.foot_contact
        n = s.floor_normal
        height = ((corners - d.geom_xpos[s.floor]) @ n).min(axis=1)
        return np.where(~s.foot_contact & s.foot_contact[::-1], np.maximum(height, 0.0), 0.0)

    def _level_legs(self, d, desired: F64, hang: F64 | None = None) -> None:  # type: ignore[no-untyped-def]
        """Leg by leg (eq. 7.5 per leg): the leg whose ankle stands over higher floor (uphill
        on a sideways slope) is shortened by the height difference, so the pelvis stays level.
        The floor's height under each ankle, not the ankle's own: a heel or a foot that
        lifts would otherwise shorten its leg and lengthen the other, lifting it further
        (on flat floor that loop lifted a foot and launched the body out of a landing's
        stand-up, docs/athletics.md). ``hang``: each foot's height over the floor to bring
        down (:meth:`_plant`), counted as floor that much lower under it."""
        a = self.athlete
        s = self.ctx.senses
        n = s.floor_normal
        xy = d.xanchor[s.ankle_joints, :2]
        z = -(xy @ n[:2]) / max(float(n[2]), 1e-6)  # the floor plane's height, up to a constant
        if hang is not None:
            z = z - hang
        if self.posture.level_hips:
            # a hip standing higher than the other counts as floor that much higher under it
            z = z + self.posture.level_hips * d.xpos[s.leg_bodies[:2], 2]
        for k in range(2):
            knee = float(desired[_KNEE[k], 0])
            ul, ll = float(a.thigh[k]), float(a.shin[k])
            length = math.sqrt(ul * ul + ll * ll + 2.0 * ul * ll * math.cos(knee))
            level = length + 0.5 * float(z[1 - k] - z[k])
            self.ctx.rig.offset[_KNEE[k], 0] = float(knee_for_length(ul, ll, level)[0]) - knee

    def support(self, s: Senses) -> None:
        """Weight shares of the feet in contact (by where the COM lies between them)."""
        rig = self.ctx.rig
        rig.support[:] = 0.0
        feet = np.flatnonzero(s.foot_contact)
        if feet.size == 0:
            return
        if feet.size == 1:
            rig.support[feet[0]] = 1.0
            return
        a, b = s.foot_point[0, :2], s.foot_point[1, :2]
        ab = b - a
        w = float(np.clip(np.dot(s.com[:2] - a, ab) / max(float(ab @ ab), 1e-9), 0.0, 1.0))
        rig.support[:] = (1.0 - w, w)


class Stepper:
    """:class:`Step` on a :class:`BalanceLaw`'s targets, after its own (one per run: the
    landing's recovery hands it to the balance that follows, ``ctx.handover["stepper"]``, so
    a swing under way goes on). Each step is recorded in ``ctx.handover["steps"]``."""

    def __init__(self, ctx: Context, step: Step, standing: bool = False) -> None:
        self.ctx = ctx
        self.step = step
        #: the standing balance's step (the ``balance`` behaviour's ``step="on"``): across the
        #: feet too, a step along them under its own hip, the standing knee's bend for the
        #: swing leg's reach growing at most :data:`STANDING_BEND_RATE`, and no closing step
        #: (the stance kept as it landed); docs/athletics.md
        self.standing = standing
        self.sideways = STEP_SIDEWAYS or standing
        self._bend = 0.0  # the standing knee's bend so far (standing)
        m = ctx.world.model
        pre = ctx.rig.wc.prefix
        self._hips = [m.joint(f"{pre}{s}_hip").id for s in "lr"]
        self._ankles = [m.joint(f"{pre}{s}_ankle").id for s in "lr"]
        self.foot = -1  # the swinging foot (0 left, 1 right), -1 none
        #: the way out of the support (unit, heading frame); None: a closing step
        self._out: F64 | None = None
        self._t0 = math.nan  # when the swing began
        self._t_end = -math.inf  # when the last step ended
        self._t_last = math.nan  # the last tick of the swing
        self._t_hang = math.inf  # since when one foot alone has been down (standing)
        self._hip = np.zeros(3)  # the swing hip's eased target
        self._close = False  # a step ended: bring the foot it stood on down if it hangs
        self._stood = 0
        self._goal = np.full((NJ, 3), np.nan)
        self._held = np.zeros(2)  # Step.give: the landed knee's, the rear ankle's angle
        self._t_give = -math.inf  # Step.give: the touchdown it is for
        self._thigh = np.zeros(3)  # the swing thigh's pitch, roll, yaw (heading frame)
        self._down: F64 | None = None  # Step.down_after: where the foot goes down (world)
        steps = ctx.handover.setdefault("steps", [])  # shared by the run's steppers
        self.record: list[dict[str, float]] = steps if isinstance(steps, list) else []

    def control(self, bl: BalanceLaw, d, h: float, t: float) -> None:  # type: ignore[no-untyped-def]
        s = self.ctx.senses
        st = self.step
        rig = self.ctx.rig
        com = s.local(s.com, h)[:2]
        vel = s.local(s.com_vel, h)[:2]
        feet = s.local(s.corners.mean(axis=1), h)[:, :2]  # each sole's middle
        floor = float(s.corners[..., 2].min())  # a level floor: the lowest sole corner
        omega = math.sqrt(9.81 / max(float(s.com[2]) - floor, 0.3))  # LIPM, as the bow's
        cp = com + vel / omega
        if self.foot < 0 and self._close and s.foot_contact.any():
            # after a step, the foot it stood on, if left hanging, is brought down beside the
            # stepped one (on the stepped foot alone the COM servo's hip offsets swung the
            # free leg up and over)
            k = self._stood
            self._close = t < self._t_end + STEP_CLOSE
            if self._close and s.foot_contact[1 - k] and not s.foot_contact[k]:
                self.foot, self._out, self._t0, self._close = k, None, t, False
                self.record.append({"t": t, "foot": float(k), "beyond_m": 0.0,
                                    "from_m": float(feet[k, 0] - feet[1 - k, 0])})  # fmt: skip
        if self.foot < 0 and self.standing and not bl.posture.plant:
            self._plant_if_hanging(bl, float(np.hypot(*vel)), t)
        elif self.foot < 0 and st.hang_plant and not bl.posture.plant:
            self._plant_hung(bl, t)
        if self.foot < 0 and t - self._t_give < (1.0 + STEP_GIVE_BACK) * st.give_time:
            self._give(t)
        if self.foot < 0:
            if t < self._t_end + STEP_PAUSE or not s.foot_contact.any():
                return
            # Step.pair: both soles' box after a step along the feet (after a sideways one as
            # without: her 110 N left push was lost)
            along = self._out is not None and self._out[1] == 0.0
            pair = bool(st.pair and self.record and along)
            lo, hi = s.support_extent(h, both=pair)
            # how far the capture point lies outside the soles' box (along the feet only
            # unless sideways), and the way out
            out = np.maximum(cp - hi[:2], 0.0) - np.maximum(lo[:2] - cp, 0.0)
            if not self.sideways:
                out[1] = 0.0
            beyond = float(np.hypot(*out))
            if beyond <= (st.pair if pair else st.margin) or float(vel @ out) <= 0.0:
                if pair and beyond <= st.pair and not s.foot_contact.all():
                    bl.posture = replace(bl.posture, plant=True)  # the hanging foot put down
                return
            # the farther foot swings (on a sideways fall toward the standing foot it crosses
            # over, see below)
            k = int(np.argmax(np.linalg.norm(feet - cp, axis=1)))
            if not s.foot_contact[1 - k]:
                return
            self.foot, self._out, self._t0 = k, out / beyond, t
            self.record.append({"t": t, "foot": float(k), "beyond_m": beyond,
                                "from_m": float(feet[k, 0] - feet[1 - k, 0])})  # fmt: skip
        k = self.foot
        if t == self._t0:  # the hip's eased target starts where the hip is
            self._t_last = t
            self._bend = 0.0
            self._hip[:] = rig.current_angles()[_HIP[k]]
            self._down = None
        u = (t - self._t0) / st.seconds
        if (u >= 0.5 and bool(s.foot_contact[k])) or u >= 3.0:  # down: balance on both feet
            self.record[-1]["to_m"] = float(feet[k, 0] - feet[1 - k, 0])
            self.record[-1]["s"] = t - self._t0
            self._close, self._stood = self._out is not None and not self.standing, 1 - k
            self.foot, self._t_end = -1, t
            if st.give and self._out is not None and self._out[1] == 0.0:  # Step.give
                self._t_give = t
                now = rig.current_angles()
                self._held[:] = now[_KNEE[k], 0] + st.give, now[_ANKLE[1 - k], 0]
            # both knees on from where they are to the posture's, over what is left of its
            # stand-up (at once, the stepped leg's push launched the body), the law's
            # leveling on top
            left = max(float(rig.time_left(t)[_KNEE].max()), STEP_SETTLE)
            goal = rig.goal()[_KNEE, 0]
            if st.knees:  # Step.knees: the legs alike, not each at its swing's last target
                goal += st.knees * (float(goal.mean()) - goal)
            rig.move(rig.current_angles(), 0.0, t, _KNEE)
            self._goal[_KNEE, 0] = goal
            rig.move(self._goal, left, t, _KNEE)
            return
        hip = d.xanchor[self._hips[k]]
        at = s.local(hip, h)[:2]
        stand = feet[1 - k]
        under = self._out is None  # the place across the feet under its own hip
        # Step.ground on the standing balance's steps along the feet only (her 110 N left
        # push's shorter sideways swings took 4-6 steps and lost it)
        ground = 0.0 if self.standing and not self.along() else st.ground
        if self._out is None:  # closing: beside the other, under its own hip
            want = np.array([stand[0], at[1]])
        else:  # past the capture point
            want = cp + st.reach * self._out
            want[0] = np.clip(want[0], stand[0] - STEP_LONGEST, stand[0] + STEP_LONGEST)
            # the feet kept STEP_WIDTH apart sideways, on whichever side the place lies
            apart = want[1] - stand[1]
            want[1] = stand[1] + math.copysign(max(abs(apart), STEP_WIDTH), apart)
            if not self.sideways or (self.standing and self._out[1] == 0.0):
                want[1] = at[1]
                under = True
        if st.across and under:  # the COM falls toward the swing side over the single support
            side = 1.0 if at[1] >= stand[1] else -1.0
            lat = cp[1] - stand[1]
            if st.foresee:  # the capture point diverges from the standing foot
                lat *= math.exp(omega * max(st.foresee - (t - self._t0), 0.0))
            past = max(side * (at[1] - stand[1]), side * lat + st.across)
            want[1] = stand[1] + side * past
        if st.down_after and t - self._t0 >= st.down_after:  # put down under where it is
            if self._down is None:
                self._down = s.corners[k].mean(axis=0)
            want = s.local(self._down, h)[:2]
        # the leg as long as it takes to put the sole on the floor at the place (the stance
        # ankle's height over the floor below the hip), its knee lifted over the swing
        down = float(hip[2]) - float(d.xanchor[self._ankles[1 - k], 2])
        down += STEP_PRESS * min(max(2.0 * u - 1.0, 0.0), 1.0)  # pressed down as it ends
        ahead, aside = (float(x) for x in want - at)
        a = self.ctx.athlete
        ul, ll = float(a.thigh[k]), float(a.shin[k])
        reach = STEP_REACH * (ul + ll)
        # the standing knee bends as far as it takes the swing leg to reach the place
        low = max(down - math.sqrt(max(reach * reach - ahead * ahead - aside * aside, 0.01)), 0.0)
        if low > 0.0:
            j = 1 - k
            stand_leg = float(np.linalg.norm(d.xanchor[self._hips[j]] - d.xanchor[self._ankles[j]]))
            bend = float(knee_for_length(a.thigh[j], a.shin[j], stand_leg - low)[0])
            bend -= float(rig.desired(t)[_KNEE[j], 0])
            if self.standing:  # from straight, at once it pulled the standing foot up
                bend = min(bend, self._bend + STANDING_BEND_RATE * max(t - self._t_last, 0.0))
                self._bend = max(bend, 0.0)
            rig.offset[_KNEE[j], 0] = max(bend, float(rig.offset[_KNEE[j], 0]))
            if not ground or u < 0.5:  # aimed from the hip as low as that bend will put it
                down -= low
        if ground and u >= 0.5:  # then on the floor within this reach from the hip as it is
            reach = ground * (ul + ll)
            far = math.sqrt(max(reach * reach - down * down, 0.0))
            pull = min(far / max(math.hypot(ahead, aside), 1e-9), 1.0)
            ahead, aside = ahead * pull, aside * pull
        length = min(math.sqrt(ahead * ahead + aside * aside + max(down, 0.2) ** 2), reach)
        swing = math.asin(float(np.clip(ahead / length, -STEP_SWING_CAP, STEP_SWING_CAP)))
        knee, geom = (float(x) for x in knee_for_length(ul, ll, length))
        knee += st.lift * math.sin(math.pi * min(max(u, 0.0), 1.0))
        # the leg aimed in the world at the place, whatever the pelvis's orientation (as the
        # landing's reach); the COM servo's offsets off it, its weight on the other foot
        self._thigh[0] = -swing + geom
        self._thigh[1] = math.asin(float(np.clip(aside / length, -0.5, 0.5)))
        aim = hips_for_thighs(self.ctx, d, self._thigh[None], h)[0]
        # the hip eased toward its aim (first order): a jump in its target kicked the pelvis
        # back and the standing foot off the floor
        ease = min(max(t - self._t_last, 0.0) / STEP_EASE, 1.0) if STEP_EASE > 0 else 1.0
        self._t_last = t
        self._hip += ease * (aim - self._hip)
        self._goal[_HIP[k]] = self._hip
        self._goal[_KNEE[k], 0] = knee
        rig.move(self._goal, 0.0, t, (_HIP[k], _KNEE[k]))
        rig.offset[_HIP[k]] = 0.0
        rig.offset[_ANKLE[k]] = 0.0
        rig.offset[_KNEE[k]] = 0.0
        rig.support[k] = 0.0
        rig.support[1 - k] = 1.0

    def along(self) -> bool:
        """A swing under way along the feet (not a sideways one, nor a closing one)."""
        return self.foot >= 0 and self._out is not None and self._out[1] == 0.0

    def _give(self, t: float) -> None:
        """:attr:`Step.give`: the landed knee's and the rear ankle's targets after a
        touchdown, in place of the law's."""
        rig = self.ctx.rig
        x = (t - self._t_give) / self.step.give_time
        spring = 1.0 - (1.0 + 4.0 * x) * math.exp(-4.0 * x)  # critically damped, 0.91 at x = 1
        joints = [_KNEE[1 - self._stood], _ANKLE[self._stood]]
        held = self._held - (self.step.give * (1.0 - spring), 0.0)
        law = rig.desired(t)[joints, 0] + rig.offset[joints, 0]
        w = min((1.0 + STEP_GIVE_BACK - x) / STEP_GIVE_BACK, 1.0)  # then the law's, linearly
        rig.offset[joints, 0] += w * (held - law)

    def _hung_since(self, t: float) -> float:
        """Since when one foot alone has been down (inf while both or neither are)."""
        if int(self.ctx.senses.foot_contact.sum()) != 1:
            self._t_hang = math.inf
        else:
            self._t_hang = min(self._t_hang, t)
        return self._t_hang

    def _plant_hung(self, bl: BalanceLaw, t: float) -> None:
        """:attr:`Step.hang_plant`: the posture's plant on once a foot has hung that long."""
        if t >= max(self._hung_since(t) + self.step.hang_plant, self._t_end + STEP_PAUSE):
            bl.posture = replace(bl.posture, plant=True)

    def _plant_if_hanging(self, bl: BalanceLaw, speed: float, t: float) -> None:
        """:data:`STANDING_HANG`: the posture's plant on once a foot has hung long enough
        over a COM slower than :data:`STANDING_STILL` (standing still on one foot is no rest)."""
        hang = self._hung_since(t)
        first = bool(self.step.hang_still and not self.record)
        still = self.step.hang_still if first else STANDING_STILL
        if t >= max(hang + STANDING_HANG, self._t_end + STEP_PAUSE) and speed < still:
            if first and self.step.hang_near:
                s = self.ctx.senses
                if float(np.hypot(*(s.com[:2] - s.support_center()[:2]))) >= self.step.hang_near:
                    return  # Step.hang_near: the COM still far off the standing sole
            bl.posture = replace(bl.posture, plant=True)
            if self.step.plant_settle:  # the stand-up again from rest, from here
                bl.set_posture(replace(bl.posture, settle=self.step.plant_settle), t,
                               gains=False, pitch_from=bl.pitch_target(t))  # fmt: skip


def hips_for_thighs(  # type: ignore[no-untyped-def]
    ctx: Context, d, thighs: np.ndarray, heading: float, ahead: np.ndarray | None = None
) -> np.ndarray:
    """``(2, 3)`` hip angles that give the thighs the world ``thighs`` ``(2, 3)`` (anatomical
    pitch, roll, yaw in the heading frame) from where the pelvis is now, in all three axes,
    or turned on by the world rotation vector ``ahead`` (the landing's ``twist_aim``)."""
    pelvis = quat_mul(d.xquat[ctx.senses.root], quat_conj(ctx.athlete.neutral[0]))
    if ahead is not None:
        pelvis = quat_mul(quat_exp(ahead), pelvis)
    want = quat_mul(quat_from_yaw(heading)[None], quat_from_euler(thighs, EULER_ORDER))
    eul = quat_to_euler(quat_mul(quat_conj(pelvis)[None], want), EULER_ORDER)
    eul[:, 2] = 0.0  # the hips' yaw targets stay 0, as elsewhere
    return eul


def hold_pelvis_and_feet(  # type: ignore[no-untyped-def]
    ctx: Context, d, pitch: float, heading: float, t: float, roll: float = 0.0
) -> None:
    """Set the hips' targets so the pelvis has ``pitch`` (forward > 0) and ``roll`` (upright
    by default, at ``heading``) given where the thighs are, and the ankles' so the feet lie
    flat on the floor given where the shins are (the thesis's eqs. 7.3-7.4 and "the hips keep
    the pelvis vertical"). Yaw targets stay 0."""
    a = ctx.athlete
    rot = d.xquat[ctx.senses.leg_bodies]  # thighs, shins, feet (world)
    anat = quat_mul(rot, quat_conj(a.neutral[_LEG_NEUTRAL]))
    pelvis = quat_mul(quat_from_yaw(heading), quat_from_euler([pitch, roll, 0.0], EULER_ORDER))
    flat = _flat_feet(anat[4:6], ctx.senses.floor_normal)
    hips = quat_mul(quat_conj(pelvis)[None], anat[0:2])
    ankles = quat_mul(quat_conj(anat[2:4]), flat)
    eul = quat_to_euler(np.concatenate([hips, ankles]), EULER_ORDER)  # (4, 3) pitch, roll, yaw
    goal = np.full((NJ, 3), np.nan)
    for k in range(2):
        goal[_HIP[k]] = (eul[k, 0], eul[k, 1], 0.0)
        goal[_ANKLE[k]] = (eul[2 + k, 0], eul[2 + k, 1], 0.0)
    ctx.rig.move(goal, 0.0, t, _HIP + _ANKLE)


_LEG_NEUTRAL = [
    SIM_BODY_INDEX[b] for b in ("l_thigh", "r_thigh", "l_shin", "r_shin", "l_foot", "r_foot")
]


def _flat_feet(foot_now: F64, normal: F64) -> F64:
    """Each foot's anatomical frame turned so its sole lies flat on a floor of ``normal``,
    keeping its heading (MuJoCo's small-vector routines: this runs every tick)."""
    out = np.empty_like(foot_now)
    x = np.empty(3)
    mat = np.empty(9)
    for k in range(2):
        mujoco.mju_rotVecQuat(x, _X, foot_now[k])
        x -= normal * float(x @ normal)
        x /= max(float(np.linalg.norm(x)), 1e-9)
        y = np.array([normal[1] * x[2] - normal[2] * x[1], normal[2] * x[0] - normal[0] * x[2],
                      normal[0] * x[1] - normal[1] * x[0]])  # fmt: skip
        mat.reshape(3, 3)[:] = np.column_stack([x, y, normal])
        mujoco.mju_mat2Quat(out[k], mat)
    return out


_X = np.array([1.0, 0.0, 0.0])


def settled(ctx: Context, bl: BalanceLaw, share: float | None = None) -> Event:
    """Fires once the body stands settled on both feet under ``bl`` (:data:`SETTLED`; each
    foot bearing ``share`` of the weight instead of its share if given)."""
    need = SETTLED["share"] if share is None else share
    load = np.zeros(2)  # each foot's contact force, low-passed
    clock = np.array([-1.0, math.nan])  # the last tick, and since when it has been settled
    weight = ctx.senses.mass * float(np.linalg.norm(ctx.world.model.opt.gravity))

    def event(_w: World, t: float, _t_in: float) -> bool:
        s = ctx.sense(t)
        k = min(max(t - clock[0], 0.0) / SETTLED["tau"], 1.0) if clock[0] >= 0 else 1.0
        clock[0] = t
        load[:] += k * (s.foot_force - load)
        h = s.heading()
        ok = (bool(s.foot_contact.all()) and float(load.min()) >= need * weight
              and float(np.hypot(*s.com_vel[:2])) < SETTLED["speed"]
              and float(np.hypot(*s.local(bl.com_target - s.com, h))) < SETTLED["offset"])  # fmt: skip
        if not ok:
            clock[1] = math.nan
            return False
        if math.isnan(clock[1]):
            clock[1] = t
        return bool(t - clock[1] >= SETTLED["hold"] - 1e-9)

    return event


class Balance(Basis):
    """The balance basis controller: settle into ``posture`` and hold it, for ``seconds`` (then
    hand over) or forever (``None``). With ``settle_within`` it hands over once
    :func:`settled` (the posture's COM target reached, still, on both feet); a body not
    settled within that many seconds stays in the state ``unsettled`` (the sequence never
    goes on) and the time is in the hand-over dict (``"unsettled_s"``): a failure.
    ``settle_share``: the weight each foot must bear to count as settled (default
    :data:`SETTLED`'s). ``step``: a step when the capture point leaves the feet
    (:class:`Step`; None: off, unless a landing before it handed over its own);
    ``standing_step``: the standing balance's kind of step (:class:`Stepper`)."""

    name = "balance"
    initial = "hold"

    def __init__(
        self,
        posture: Posture | None = None,
        seconds: float | None = None,
        gains: BalanceGains = BALANCE_GAINS,
        until: Event | None = None,
        settle_within: float | None = None,
        settle_share: float | None = None,
        step: Step | None = None,
        standing_step: bool = False,
    ) -> None:
        self.posture = posture or Posture()
        self.step = step
        self.standing_step = standing_step
        if seconds is not None and not (math.isfinite(seconds) and seconds >= 0):
            raise ConfigError(f"balance seconds must be >= 0, got {seconds!r}")
        if settle_within is not None and not (math.isfinite(settle_within) and settle_within > 0):
            raise ConfigError(f"balance settle_within must be > 0 s, got {settle_within!r}")
        if settle_share is not None and not (
            math.isfinite(settle_share) and 0.0 < settle_share <= 0.5
        ):
            raise ConfigError(
                f"balance settle_share must be in (0, 0.5] of the weight per foot, got {settle_share!r}"
            )
        self.settle_share = settle_share
        self.seconds = seconds
        self.settle_within = settle_within
        self.gains = gains
        self.until = until
        self.law: BalanceLaw | None = None

    def states(self, ctx: Context) -> list[State]:
        bl = BalanceLaw(ctx, self.gains)
        self.law = bl
        if self.step is not None:
            bl.stepper = Stepper(ctx, self.step, self.standing_step)

        def enter(world: World, t: float) -> None:
            del world
            prev = ctx.handover.get("posture")
            if isinstance(prev, Posture):
                bl.posture = prev
            stepper = ctx.handover.get("stepper")
            if bl.stepper is None and isinstance(stepper, Stepper):  # the landing's step goes on
                bl.stepper = stepper
            # a landing's last pitch target, carried on (LandingParams.carry_pitch)
            pitch = ctx.handover.pop("pitch", None)
            bl.set_posture(self.posture, t, pitch_from=pitch if isinstance(pitch, float) else None)
            # a landing's share of the hip offset after a held absorb (held_hip_share)
            share = ctx.handover.pop("hip_share", None)
            if isinstance(share, float):
                bl.hip_share = share

        exits: list[tuple[Event, str]] = []
        if self.until is not None:
            exits.append((self.until, NEXT))
        if self.seconds is not None:
            exits.append((after(self.seconds), NEXT))
        hold = law(bl.control, ctx.control_every)
        if self.settle_within is None:
            return [State("hold", hold, enter, tuple(exits))]

        def timed_out(world: World, t: float) -> None:
            del world
            ctx.handover["unsettled_s"] = t

        exits += [
            (settled(ctx, bl, self.settle_share), NEXT),
            (after(self.settle_within), "unsettled"),
        ]
        return [State("hold", hold, enter, tuple(exits)), State("unsettled", hold, timed_out)]
