"""The back handspring's hand support (thesis 8.3): the basis controller between the leap and the
landing. From lift-off the body arches back with the arms thrown over the head; when the hands
touch the floor (MuJoCo contacts of the hand bodies) the arms become stiff struts that give a
little at the elbows, and after ``push_after`` seconds they push: the elbows straighten and
the shoulders close (the arms swing from over the head toward the front) while the hips, trunk
and knees snap down (flex), turning the legs over toward the floor; the body leaves the hands
for a second, short flight, and the controller hands over to the landing once the hands are
off the floor (or a foot touches). As in the thesis, the hands are not
controlled by feedback: the push comes a set time after contact.

The hand contacts are expected, so they are not a fall: :func:`handspring_report` judges
``fell`` on every contact but the hands' during this phase (``ctx.handover["handspring"]``),
and adds the time the hands were on the floor during it."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from reactmocap.athletics.behaviours import LANDED_AFTER
from reactmocap.athletics.machine import NEXT, Basis, Context, law
from reactmocap.athletics.report import FALL_HEIGHT, standing_balanced
from reactmocap.athletics.rig import joint_index, per_joint
from reactmocap.athletics.tumble import TUMBLE_STIFFNESS, composite_inertia, time_to_height
from reactmocap.errors import ConfigError
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.controllers.machine import State, after
from reactmocap.sim.world import World

__all__ = ["HANDS", "Handspring", "HandspringParams", "handspring_report"]

NJ = len(BALL_JOINTS)
#: the bodies whose floor contacts are the handspring's support
HANDS = frozenset({"l_hand", "r_hand"})
#: joint stiffness while the hands carry the body (m g L N m/rad): arms as struts
SUPPORT_STIFFNESS = {**TUMBLE_STIFFNESS, "shoulder": 3.0, "elbow": 3.0, "wrist": 1.0,
                     "waist": 3.0, "back": 3.0, "hip": 3.0}  # fmt: skip
#: the largest shoulder pitch offset (rad) the hands' twist feedback may make (twist_gain)
TWIST_LIMIT = 0.5


@dataclass(frozen=True)
class HandspringParams:
    """The hand support's parameters (radians, seconds).

    Args:
        arms: shoulder pitch in the air (arms thrown over the head; < 0 raises them).
        arch: waist and back pitch in the air (< 0 arches back).
        neck: neck pitch in the air (< 0: the head back, looking for the floor).
        hips: hip pitch in the air (> 0 extends the legs behind the trunk).
        knees: knee flexion in the air.
        entry: seconds the joints take to reach that shape.
        give: elbow flexion (rad) the arms take on contact, over ``push_after`` (0: straight
            struts); the push straightens them again.
        push_after: seconds after the hands touch that the push and snap-down start.
        push: shoulder pitch the push closes the shoulders to (> ``arms``: the arms swing
            from over the head toward the front).
        snap_hips: hip pitch of the snap-down (< 0 flexes, bringing the legs over).
        snap_trunk: waist and back pitch of the snap-down (> 0 flexes).
        snap_knees: knee flexion of the snap-down (the legs reach the floor bent, to absorb).
        snap: seconds the push and snap-down take.
        max_seconds: hand over to the landing after this long at the latest.
        aim: the rotation (rad, backward < 0) at which the hands should meet the floor; 0:
            off (the knees held at ``knees``). Otherwise the knees steer it in the air: the
            rotation at contact is predicted each tick from the whole-body angular momentum
            over the current pose's inertia and the COM's ballistic time to ``aim_height``,
            and the knees flex about ``knees`` by ``aim_gain`` rad per rad that the
            prediction falls short of ``aim`` (straighten as it runs past; more flexion:
            less inertia, faster turning), clipped to [0, ``aim_knees``]. Why: the leap's take-off speed varies with the start and the
            hands then meet the floor early or late, where the push makes too little or
            far too much spin.
        aim_gain: knee flexion (rad) per rad of predicted rotation short of ``aim``.
        aim_height: the COM height at hand contact the prediction falls to, as a fraction of
            the standing COM height.
        aim_knees: the most knee flexion the aim may ask for (rad).
        twist_gain: while the hands are on the floor, the shoulders' pitch is moved apart
            (one arm pushes on toward the front, the other back) by this many rad per unit of
            the whole-body vertical angular momentum (in m L^2 rad/s), at most
            :data:`TWIST_LIMIT` each way: the hands' floor forces along the travel then make a
            vertical moment against the twist (the hands are the only thing that can change
            it once in the air); 0: off (as before).
        twist_above: the twist feedback acts only in a run whose hands meet the floor with
            more than this vertical momentum (kg m^2/s, either way): a small one is no harm,
            and the split disturbs the push.
    """

    arms: float = -2.9
    arch: float = -0.3
    neck: float = -0.4
    hips: float = 0.2
    knees: float = 0.0
    entry: float = 0.2
    give: float = 0.0
    push_after: float = 0.05
    push: float = -3.1
    snap_hips: float = -0.8
    snap_trunk: float = 0.2
    snap_knees: float = 0.0
    snap: float = 0.15
    max_seconds: float = 2.0
    aim: float = 0.0
    aim_gain: float = 4.0
    aim_height: float = 1.03
    aim_knees: float = 0.9
    twist_gain: float = 0.0
    twist_above: float = 0.0

    def __post_init__(self) -> None:
        for name, v in vars(self).items():
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ConfigError(f"handspring {name} must be a finite number, got {v!r}")
        if self.entry <= 0 or self.snap <= 0 or self.max_seconds <= 0 or self.push_after < 0:
            raise ConfigError(
                "handspring entry, snap and max_seconds must be > 0 and push_after >= 0"
            )
        if not -2.0 * math.pi <= self.aim <= 0.0:
            raise ConfigError(
                f"handspring aim must be in [-2 pi, 0] rad (backward < 0; 0: off), got {self.aim}"
            )
        if not (0.0 <= self.twist_gain <= 100.0 and self.twist_above >= 0.0):
            raise ConfigError(
                f"handspring twist_gain must be in [0, 100] and twist_above >= 0, got "
                f"{self.twist_gain}, {self.twist_above}"
            )
        if self.aim_gain < 0 or not 0.3 <= self.aim_height <= 2.0 or not 0 < self.aim_knees <= 2.0:
            raise ConfigError(
                f"handspring aim_gain must be >= 0, aim_height in [0.3, 2] (of the standing "
                f"COM) and aim_knees in (0, 2] rad, got {self.aim_gain}, {self.aim_height}, "
                f"{self.aim_knees}"
            )


class Handspring(Basis):
    """The hand-support basis controller: ``reach`` (arched, arms over the head, until the
    hands touch), ``support`` (arms as struts, then push and snap down); exits to the next
    basis controller once the hands are off the floor again, or a foot touches."""

    name = "handspring"
    initial = "reach"

    def __init__(self, params: HandspringParams | None = None) -> None:
        self.params = params or HandspringParams()

    def states(self, ctx: Context) -> list[State]:
        p = self.params
        rig = ctx.rig
        every = ctx.control_every
        dt = every * float(ctx.world.model.opt.timestep)
        memo: dict[str, Any] = {}
        # what the report needs, shared through the hand-over dict
        rec: dict[str, Any] = {"contact_s": 0.0, "first": None, "last": None, "push": None,
                               "others": set()}  # fmt: skip
        ctx.handover["handspring"] = rec

        def pose(arms: float, trunk: float, hips: float, knees: float, neck: float) -> np.ndarray:
            goal = np.full((NJ, 3), np.nan)
            for s in "lr":
                goal[joint_index(f"{s}_shoulder")] = (arms, 0.0, 0.0)
                goal[joint_index(f"{s}_elbow")] = 0.0
                goal[joint_index(f"{s}_hip")] = (hips, 0.0, 0.0)
                goal[joint_index(f"{s}_knee")] = (knees, 0.0, 0.0)
            for j in ("waist", "back"):
                goal[joint_index(j)] = (trunk, 0.0, 0.0)
            goal[joint_index("neck")] = (neck, 0.0, 0.0)
            return goal

        def watch(t: float) -> bool:
            """Record the contacts (once per tick); True while a hand touches the floor."""
            s = ctx.sense(t)
            if memo.get("seen") == t:
                return bool(HANDS.intersection(s.other_contact))
            memo["seen"] = t
            hands = HANDS.intersection(s.other_contact)
            rec["others"].update(set(s.other_contact) - HANDS)
            if hands:
                rec["contact_s"] += dt
                if rec["first"] is None:
                    rec["first"] = t
                rec["last"] = t
            return bool(hands)

        knees = [joint_index(f"{s}_knee") for s in "lr"]
        bend = np.full((NJ, 3), np.nan)
        bend[knees] = 0.0
        bodies = np.asarray(ctx.world.characters[ctx.character].body_ids)

        def aim(world: World, t: float) -> None:
            """The knees steer the rotation at hand contact (``aim``; as the tumble's opening,
            the rotation to come is the momentum over the current inertia times the fall)."""
            s = ctx.sense(t)
            axis = memo["axis"]
            momentum = float(world.data.subtree_angmom[s.root] @ axis)
            inertia = float(axis @ composite_inertia(world.model, world.data, bodies)[0] @ axis)
            fall = time_to_height(ctx, p.aim_height * (ctx.standing_com or float(s.com[2])))
            predicted = ctx.rotation + momentum / inertia * fall
            knee = float(np.clip(p.knees + p.aim_gain * (predicted - p.aim), 0.0, p.aim_knees))
            rec["aim_knees"] = knee
            bend[knees, 0] = knee
            rig.move(bend, 0.0, t, knees)

        def reach_enter(world: World, t: float) -> None:
            del world
            # the somersault axis the aim measures about: the start's left-right axis
            h = ctx.heading0 if ctx.heading0 is not None else ctx.sense(t).heading()
            memo["axis"] = np.array([-math.sin(h), math.cos(h), 0.0])
            rig.set_stiffness(per_joint(TUMBLE_STIFFNESS))
            rig.support[:] = 0.0
            rig.offset[:] = 0.0
            moving = list(range(NJ))
            rig.move(pose(p.arms, p.arch, p.hips, p.knees, p.neck), p.entry, t, moving)

        def support_enter(world: World, t: float) -> None:
            # (the momentum read only with the feedback on: off, the run is as before)
            memo["twist"] = p.twist_gain > 0 and (
                abs(float(world.data.subtree_angmom[ctx.sense(t).root][2])) > p.twist_above
            )
            memo["contact"] = t
            memo["pushed"] = False
            rig.set_stiffness(per_joint(SUPPORT_STIFFNESS))
            if p.give > 0:  # the arms give a little on impact, then push
                goal = np.full((NJ, 3), np.nan)
                for s in "lr":
                    goal[joint_index(f"{s}_elbow")] = (p.give, 0.0, 0.0)
                rig.move(
                    goal, max(p.push_after, 0.02), t, [joint_index(f"{s}_elbow") for s in "lr"]
                )

        shoulders = [joint_index(f"{s}_shoulder") for s in "lr"]
        apart = np.array([1.0, -1.0])  # left and right shoulders' share of the twist offset
        unit = ctx.athlete.mass * ctx.athlete.leg_length**2

        def support(world: World, t: float) -> None:
            hands = watch(t)
            if memo["twist"]:
                # the vertical momentum against a fore-aft split of the hands' push
                lz = float(world.data.subtree_angmom[ctx.sense(t).root][2]) if hands else 0.0
                off = float(np.clip(p.twist_gain * lz / unit, -TWIST_LIMIT, TWIST_LIMIT))
                rig.offset[shoulders, 0] = off * apart
            if not memo["pushed"] and t - memo["contact"] >= p.push_after:
                memo["pushed"] = True
                rec["push"] = t
                goal = pose(p.push, p.snap_trunk, p.snap_hips, p.snap_knees, 0.0)
                rig.move(goal, p.snap, t, list(range(NJ)))

        def hands_on(_w: World, t: float, _t_in: float) -> bool:
            return watch(t)

        def released(_w: World, t: float, t_in: float) -> bool:
            s = ctx.sense(t)
            off = not HANDS.intersection(s.other_contact) and t - t_in > p.snap
            return bool(off or s.foot_contact.any())

        def feet(_w: World, t: float, _t_in: float) -> bool:
            return bool(ctx.sense(t).foot_contact.any())

        return [
            State("reach", law(aim if p.aim else lambda w, t: None, every), reach_enter,
                  ((hands_on, "support"), (feet, NEXT), (after(p.max_seconds), NEXT))),
            State("support", law(support, every), support_enter,
                  ((released, NEXT), (after(p.max_seconds), NEXT))),
        ]  # fmt: skip


def handspring_report(
    ctx: Context, log: dict[str, np.ndarray], standing_pelvis: float
) -> dict[str, Any]:
    """``fell`` and the hand support's figures for a run with a :class:`Handspring` phase: a
    fall is any contact but the feet's outside the hand support, any but the hands' during it
    (``handspring_other_contacts``), or the pelvis below :data:`FALL_HEIGHT` of standing once
    the hands have left the floor (during the support the pelvis is low by design); ``landed``:
    the feet touched after the hands and the athlete stood balanced and still
    ``LANDED_AFTER`` s later, with no fall."""
    rec = ctx.handover.get("handspring")
    if not isinstance(rec, dict):
        raise ConfigError("handspring_report needs a run with a handspring phase")
    state = log["state"]
    during = np.array([str(s).startswith("handspring") for s in state], dtype=bool)
    others = log["others"].astype(bool)
    bad = bool(rec["others"]) or bool((others & ~during).any())
    first, last = rec["first"], rec["last"]
    t = log["t"]
    after_hands = t > (last if last is not None else np.inf)
    low = bool((log["pelvis"][after_hands] < FALL_HEIGHT * standing_pelvis).any())
    td = ctx.touchdown_time
    end = float(t[-1]) if t.size else 0.0
    fell = bad or low
    landed = (td is not None and not fell and last is not None and td > last
              and end >= td + LANDED_AFTER - 1e-6 and standing_balanced(ctx))  # fmt: skip
    i = min(int(np.searchsorted(t, first)), t.size - 1) if first is not None else None
    return {
        "rotation_at_hands_deg": math.degrees(float(log["rotation"][i])) if i is not None else None,
        "hands_contact_s": float(rec["contact_s"]),
        "hands_first_contact_s": first,
        "hands_last_contact_s": last,
        "handspring_push_s": rec["push"],
        "handspring_other_contacts": sorted(rec["others"]),
        # the knees' flexion the aim (HandspringParams.aim) last asked for in the air
        "handspring_aim_knees": rec.get("aim_knees"),
        "fell": fell,
        "landed": bool(landed),
    }
