"""Tumbling (thesis ch. 5): the body position of a somersault and the tumbling basis controller.

The leap makes the angular momentum; in the air the tumbling controller takes the body into a
layout, pike or tuck by predetermined hip, spine and knee angles (:data:`POSITIONS`), which
speeds the rotation up as the moment of inertia about the somersault axis falls (Fig. 5.2/5.3),
and opens out for the landing when the rotation still to go matches what the open body will
turn through before the feet reach the floor: the remaining rotation is predicted from the
whole-body angular momentum about the COM (``mj_subtreeVel``) and the composite inertia of the
landing pose about the COM (:func:`somersault_inertia`), and the time to touchdown from the
COM's ballistic path. The landing controller does the opening (it untucks and places the legs,
as in the thesis's section 8.4)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import Athlete
from reactmocap.athletics.machine import NEXT, Basis, Context, law
from reactmocap.athletics.rig import joint_index, per_joint
from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.sim.bodies import BALL_JOINTS, SIM_BODIES
from reactmocap.sim.controllers.machine import Event, State, after
from reactmocap.sim.world import World

__all__ = [
    "POSITIONS",
    "TUMBLE_STIFFNESS",
    "Tumble",
    "TumbleParams",
    "composite_inertia",
    "position_angles",
    "time_to_height",
    "somersault_inertia",
]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)
_SHOULDERS = [joint_index(f"{s}_shoulder") for s in "lr"]

#: the predetermined joint angles of each somersault position (anatomical ``[pitch, roll,
#: yaw]``, rad; both sides alike, shoulder roll mirrored): layout: straight, arms out to the
#: sides (the thesis's listing pose); pike: flexed at the hips and spine, arms reaching down
#: the legs; tuck: hips, knees and spine flexed, hands on the shins
_POSITIONS: dict[str, dict[str, tuple[float, float, float]]] = {
    "layout": {"shoulder": (0.0, 1.5708, 0.0)},
    "pike": {"hip": (-2.2, 0.0, 0.0), "waist": (0.6, 0.0, 0.0), "back": (0.6, 0.0, 0.0),
             "neck": (0.3, 0.0, 0.0), "shoulder": (-0.9, 0.0, 0.0)},
    "tuck": {"hip": (-2.2, 0.0, 0.0), "knee": (2.3, 0.0, 0.0), "waist": (0.6, 0.0, 0.0),
             "back": (0.6, 0.0, 0.0), "neck": (0.3, 0.0, 0.0), "shoulder": (-0.9, 0.0, 0.0),
             "elbow": (1.2, 0.0, 0.0)},
}  # fmt: skip
POSITIONS: Mapping[str, Mapping[str, tuple[float, float, float]]] = MappingProxyType(
    {k: MappingProxyType(v) for k, v in _POSITIONS.items()}
)
#: joint stiffness in the air while tumbling (units of m g L N m/rad): the hips and knees
#: must pull the legs in against the spin
TUMBLE_STIFFNESS = {
    "waist": 2.0, "back": 2.0, "neck": 0.3, "shoulder": 0.4, "elbow": 0.15, "wrist": 0.05,
    "hip": 2.0, "knee": 1.0, "ankle": 0.3,
}  # fmt: skip


def position_angles(position: str) -> F64:
    """``(15, 3)`` anatomical angles of somersault ``position`` (``layout``, ``pike``,
    ``tuck``); unknown names list the valid ones."""
    try:
        spec = POSITIONS[position]
    except KeyError:
        raise UnknownKeyError(
            f"unknown somersault position {position!r}; valid positions are {sorted(POSITIONS)}"
        ) from None
    out = np.zeros((NJ, 3))
    for key, (pitch, roll, yaw) in spec.items():
        for side, sign in (("l_", 1.0), ("r_", -1.0)):
            name = f"{side}{key}"
            if name in BALL_JOINTS:
                out[joint_index(name)] = (pitch, sign * roll, sign * yaw)
        if key in BALL_JOINTS:
            out[joint_index(key)] = (pitch, roll, yaw)
    return out


def composite_inertia(
    model: mujoco.MjModel, data: mujoco.MjData, bodies: NDArray
) -> tuple[F64, F64]:
    """Whole-body ``(3, 3)`` inertia (kg m^2, world axes) of ``bodies`` about their joint
    centre of mass, and that COM, from the current kinematics (``mj_kinematics`` has run):
    each body's principal inertia turned into the world plus the parallel-axis term."""
    mass = model.body_mass[bodies]
    pos = data.xipos[bodies]
    com = (mass[:, None] * pos).sum(axis=0) / mass.sum()
    rot = data.ximat[bodies].reshape(-1, 3, 3)
    inertia = np.einsum("nij,nj,nkj->ik", rot, model.body_inertia[bodies], rot)
    d = pos - com
    inertia += np.einsum("n,nij->ij", mass,
                         np.einsum("n,ij->nij", (d * d).sum(axis=1), np.eye(3))
                         - np.einsum("ni,nj->nij", d, d))  # fmt: skip
    return inertia, com


def somersault_inertia(athlete: Athlete, angles: F64 | str) -> float:
    """Moment of inertia (kg m^2) about the somersault axis (the body's left-right axis
    through its COM) of ``athlete`` in anatomical ``angles`` ``(15, 3)`` or a named
    :data:`POSITIONS` entry, measured on its MuJoCo model (Fig. 5.2)."""
    a = position_angles(angles) if isinstance(angles, str) else np.asarray(angles, dtype=np.float64)
    model = athlete.character.model
    data = mujoco.MjData(model)
    data.qpos[:] = athlete.standing_qpos(a)
    mujoco.mj_kinematics(model, data)
    bodies = np.array([model.body(b).id for b in SIM_BODIES])
    inertia, _ = composite_inertia(model, data, bodies)
    return float(inertia[1, 1])


#: the landing pose the prediction assumes (the landing controller's reach: knees 0.6 rad,
#: hips flexed to put the feet under the COM, arms forward)
LANDING_POSE: Mapping[str, tuple[float, float, float]] = MappingProxyType({
    "hip": (-0.45, 0.0, 0.0), "knee": (0.6, 0.0, 0.0), "ankle": (-0.15, 0.0, 0.0),
    "shoulder": (-0.6, 0.0, 0.0),
})  # fmt: skip


@dataclass(frozen=True)
class TumbleParams:
    """The tumbling controller's parameters.

    Args:
        position: ``layout``, ``pike`` or ``tuck`` (:data:`POSITIONS`).
        turns: somersaults to turn (> 0; the direction follows the angular momentum).
        entry: seconds the joints take to reach the position (Hermite).
        lead: rotation (rad) before the predicted total at which to open (the opening takes
            time, during which the body still turns faster than open); with ``open_inertia``
            below the position's, a negative lead opens once the prediction is that far
            short of the turn (the landing turns the rest).
        touchdown_height: COM height (fraction of the standing COM height) at which the
            feet are predicted to touch.
        latest: open, however far the rotation has got, once the feet are predicted to
            touch within this many seconds (a short somersault still lands feet first).
        open_at: open at this many seconds in the air instead of predicting (the thesis's
            timed transition); None predicts.
        max_seconds: open at the latest after this long.
        arm_tilt: the tilt-twist arm throw (rad, section 5.2): both shoulders turn by this
            much about the body's front-back axis once the position is reached (one arm up
            over the head, the other down and across); the body tilts the other way out of
            the somersault plane and starts to twist. 0: no throw.
        arm_throw: seconds the throw takes.
        twist: twists (turns, >= 0, in half turns) to stop the tilt twist at; 0: the throw
            (if any) is held. Each tick after the throw the twist still to come while the
            asymmetry is undone is predicted as the twist rate now (the pelvis's angular
            velocity about the pelvis-to-head line) times ``arm_throw / 2`` (the tilt, and
            with it the rate, falls to zero over the undo); once the twist so far plus that
            reaches the goal the asymmetry is undone: at a whole turn the arms go back to the
            position (the body's front-back axis is where it was at the throw, so turning
            the arms back takes the tilt out), at an odd half turn they go on by another
            ``arm_tilt`` (the front-back axis is reversed, so the same turn of the trunk
            needs the opposite arm motion).
        target_height: the COM height (m) the prediction aims at instead (a dive: the water
            surface); None: ``touchdown_height`` of the standing COM.
        open_inertia: the opened body's inertia about the somersault axis (kg m^2) the
            prediction uses; None: the landing pose's (:data:`LANDING_POSE`). When it is
            below the position's own (the layout), the prediction falls through the flight
            and the tumble opens once it has come down to ``turns`` (+ ``lead``) instead.
        open_delay: seconds of the time to touchdown that the prediction leaves out: the
            opened body is taken to turn at ``L / open_inertia`` over the rest only, ``L /
            open_inertia * max(t - open_delay, 0)``; 0: over all of it. Why: the layout's
            reach pikes deeper the longer it has, so its turn grows by about 19 rad per
            second of reach against a mean rate of 6 rad/s (perturbed back layouts); a rate
            over the whole time made the opening follow the take-off's small momentum and
            height errors the wrong way and scattered the touchdown over -287..-319 deg
            (docs/athletics.md).
        extend: fraction (0-1) of the way from the position to the landing pose that the
            hips and knees extend before the opening (thesis 8.5.1: in the forward somersault
            they extend slightly in the air before the landing controller takes over, so the
            legs are under the body at touchdown); 0: none.
        extend_lead: rotation (rad) before the opening at which that extension starts.
        hip: the position's hip flexion (rad, anatomical pitch, -2.6..0) instead of its own;
            None keeps it. The pike's own -2.2 makes the somersault axis the piked body's
            intermediate principal axis (male 2.07 < 5.94 < 6.10 kg m^2), about which the
            rotation is unstable: a little cartwheel or twist momentum from the take-off grows
            into a tilt and a twist (the tuck's is its largest axis). At -2.0 it is the largest
            (6.28 against 6.00).
    """

    position: str = "tuck"
    turns: float = 1.0
    entry: float = 0.2
    lead: float = 0.0
    touchdown_height: float = 0.9
    latest: float = 0.12
    open_at: float | None = None
    max_seconds: float = 3.0
    arm_tilt: float = 0.0
    arm_throw: float = 0.15
    twist: float = 0.0
    target_height: float | None = None
    open_inertia: float | None = None
    extend: float = 0.0
    extend_lead: float = 0.5
    hip: float | None = None
    open_delay: float = 0.0

    def __post_init__(self) -> None:
        position_angles(self.position)  # an unknown position lists the valid ones
        for name in ("turns", "entry", "lead", "touchdown_height", "latest", "max_seconds",
                     "arm_tilt", "arm_throw", "twist", "extend", "extend_lead"):  # fmt: skip
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ConfigError(f"tumble {name} must be a finite number, got {v!r}")
        if self.turns <= 0 or self.entry <= 0 or self.max_seconds <= 0 or self.arm_throw <= 0:
            raise ConfigError("tumble turns, entry, arm_throw and max_seconds must be > 0")
        if self.twist < 0 or not float(2.0 * self.twist).is_integer():
            raise ConfigError(f"tumble twist must be >= 0 in half turns, got {self.twist!r}")
        if self.twist and not self.arm_tilt:
            raise ConfigError("tumble twist needs an arm throw (arm_tilt != 0) to twist with")
        if not 0.0 <= self.extend <= 1.0:
            raise ConfigError(f"tumble extend must be in [0, 1], got {self.extend!r}")
        if self.open_at is not None and not (math.isfinite(self.open_at) and self.open_at >= 0):
            raise ConfigError(f"tumble open_at must be >= 0 s, got {self.open_at!r}")
        if self.target_height is not None and not math.isfinite(self.target_height):
            raise ConfigError(f"tumble target_height must be finite, got {self.target_height!r}")
        if self.open_inertia is not None and not (
            math.isfinite(self.open_inertia) and self.open_inertia > 0
        ):
            raise ConfigError(f"tumble open_inertia must be > 0, got {self.open_inertia!r}")
        if not (isinstance(self.open_delay, (int, float)) and 0.0 <= self.open_delay < 5.0):
            raise ConfigError(f"tumble open_delay must be in [0, 5) s, got {self.open_delay!r}")
        if self.hip is not None and not (math.isfinite(self.hip) and -2.6 <= self.hip <= 0.0):
            raise ConfigError(f"tumble hip must be in [-2.6, 0] rad, got {self.hip!r}")


class Tumble(Basis):
    """The tumbling basis controller: from lift-off, into ``params.position``; hands over
    (:data:`NEXT`, to the landing) when the predicted rotation at touchdown of a body opened
    now reaches ``params.turns`` somersaults (or on touchdown, or at ``open_at``)."""

    name = "tumble"
    initial = "tumble"

    def __init__(self, params: TumbleParams | None = None) -> None:
        self.params = params or TumbleParams()

    def states(self, ctx: Context) -> list[State]:
        p = self.params
        every = ctx.control_every
        rig = ctx.rig
        goal = position_angles(p.position)
        if p.hip is not None:
            goal[[joint_index(f"{side}_hip") for side in "lr"], 0] = p.hip
        landing = np.zeros((NJ, 3))
        for key, val in LANDING_POSE.items():
            for side in "lr":
                landing[joint_index(f"{side}_{key}")] = val
        i_open = p.open_inertia or somersault_inertia(ctx.athlete, landing)
        # a position that turns slower than the opened body (the layout): the prediction falls
        # as the flight goes on, so it opens once the prediction has come down to the turn
        slower = somersault_inertia(ctx.athlete, goal) > i_open
        legs = [joint_index(f"{side}_{j}") for side in "lr" for j in ("hip", "knee")]
        extended = np.full((NJ, 3), np.nan)
        extended[legs] = goal[legs] + p.extend * (landing[legs] - goal[legs])
        memo: dict[str, float] = {}
        bodies = np.asarray(ctx.world.characters[ctx.character].body_ids)

        def enter(world: World, t: float) -> None:
            del world
            rig.set_stiffness(per_joint(TUMBLE_STIFFNESS))
            rig.set_damping(per_joint({}))
            rig.support[:] = 0.0
            rig.support_scale = 1.0
            rig.support_dir = None
            rig.offset[:] = 0.0
            rig.move(goal, p.entry, t)
            memo["predicted"] = ctx.rotation
            memo["t_td"] = math.inf
            memo["t0"] = t
            memo.pop("thrown", None)
            memo.pop("extended", None)
            memo.pop("undone", None)
            memo["twist0"] = ctx.twist
            memo["tick"] = t

        def control(world: World, t: float) -> None:
            if p.arm_tilt and "thrown" not in memo and t - memo["t0"] >= p.entry:
                memo["thrown"] = t  # the tilt twist: both arms turn the same way
                throw = np.full((NJ, 3), np.nan)
                for side in _SHOULDERS:
                    throw[side] = goal[side] + (0.0, p.arm_tilt, 0.0)
                rig.move(throw, p.arm_throw, t, _SHOULDERS)
            twist_rate = (ctx.twist - memo["twist0"]) / max(t - memo["tick"], 1e-9)
            memo["twist0"], memo["tick"] = ctx.twist, t
            if (p.twist and "undone" not in memo and "thrown" in memo
                    and t - memo["thrown"] >= p.arm_throw):  # fmt: skip
                # the twist still to come while the tilt is taken out: about half the
                # rate now over the undo
                coming = abs(ctx.twist + twist_rate * 0.5 * p.arm_throw)
                if coming >= 2.0 * math.pi * p.twist:
                    memo["undone"] = t
                    ctx.handover["tumble_twist_undone"] = t
                    half = not float(p.twist).is_integer()
                    back = np.full((NJ, 3), np.nan)
                    for side in _SHOULDERS:
                        back[side] = goal[side] + (0.0, 2.0 * p.arm_tilt if half else 0.0, 0.0)
                    rig.move(back, p.arm_throw, t, _SHOULDERS)
            # the rotation the body would still turn, opened now, before its feet touch:
            # the angular momentum about the somersault axis over the open body's inertia,
            # times the time the COM takes to fall to its touchdown height
            s = ctx.sense(t)
            h = ctx.heading0 if ctx.heading0 is not None else s.heading()
            axis = np.array([-math.sin(h), math.cos(h), 0.0])
            momentum = float(world.data.subtree_angmom[s.root] @ axis)
            aim = p.target_height
            if aim is None:
                aim = p.touchdown_height * (ctx.standing_com or float(s.com[2]))
            memo["t_td"] = time_to_height(ctx, aim)
            turning = max(memo["t_td"] - p.open_delay, 0.0)
            memo["predicted"] = ctx.rotation + momentum / i_open * turning
            want = 2.0 * math.pi * p.turns - p.lead - p.extend_lead
            if (p.extend and "extended" not in memo and t - memo["t0"] > p.entry
                    and abs(memo["predicted"]) >= want):  # fmt: skip
                memo["extended"] = t  # hips and knees part-way open before the landing
                rig.move(extended, p.entry, t, legs)
            # the whole body's angular velocity about the axis (Fig. 5.3): L over the inertia
            # of the pose it is in now
            inertia = float(axis @ composite_inertia(world.model, world.data, bodies)[0] @ axis)
            low = float(ctx.handover.get("tumble_min_inertia", math.inf))  # type: ignore[arg-type]
            if inertia < low:
                ctx.handover["tumble_min_inertia"] = inertia
            rate = abs(momentum) / inertia
            peak = float(ctx.handover.get("tumble_peak_rate", 0.0))  # type: ignore[arg-type]
            ctx.handover["tumble_peak_rate"] = max(peak, rate)

        def opened(world: World, t: float, t_in: float) -> bool:
            del world
            if p.open_at is not None:
                return t_in >= p.open_at
            if t_in <= p.entry:
                return False
            if p.twist and ("undone" not in memo or t < memo["undone"] + p.arm_throw):
                return False  # a twist is opened out of only once it is stopped
            want = 2.0 * math.pi * p.turns
            if slower:
                return abs(memo["predicted"]) <= want + p.lead or memo["t_td"] <= p.latest
            return abs(memo["predicted"]) >= want - p.lead or memo["t_td"] <= p.latest

        exits: list[tuple[Event, str]] = [(opened, NEXT), (after(p.max_seconds), NEXT)]
        return [State("tumble", law(control, every), enter, tuple(exits))]


def time_to_height(ctx: Context, height: float) -> float:
    """Seconds until the COM, on its ballistic path, falls to ``height`` m (0 if below)."""
    s = ctx.senses
    g = float(np.linalg.norm(ctx.world.model.opt.gravity))
    z, vz = float(s.com[2]), float(s.com_vel[2])
    disc = vz * vz + 2.0 * g * max(z - height, 0.0)
    return max((vz + math.sqrt(disc)) / g, 0.0)
