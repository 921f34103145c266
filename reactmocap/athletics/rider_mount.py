"""The rider on the bicycle (Hodgins et al. 1995, "Bicycling"): the bicycle fitted to the body
(:func:`fit_bicycle`) and the mount (:class:`RiderMount`): the pelvis pivots on the saddle, hands
and feet tied to the grips and pedals by two-sided spring-dampers (MuJoCo soft ``connect``
equalities: toe-clips and a fixed gear, so a leg can pull up); the rider's world settings
(:data:`RIDER_WORLD`). The control laws: :mod:`reactmocap.athletics.rider`."""

from __future__ import annotations

import math
from dataclasses import replace

import mujoco
import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from reactmocap.athletics.bicycle import Bicycle, BicycleParams, Fit
from reactmocap.athletics.bodies import Athlete
from reactmocap.athletics.rider_kinematics import SIT_OFFSET, Posture, trunk_pose
from reactmocap.errors import ConfigError
from reactmocap.rotations import quat_conj, quat_rotate
from reactmocap.sim.bodies import SIM_BODY_INDEX
from reactmocap.sim.world import World, WorldConfig

__all__ = [
    "FOOT_SPRING",
    "HAND_SPRING",
    "RIDER_WORLD",
    "SEAT_SPRING",
    "RiderMount",
    "ball_offset",
    "fit_bicycle",
    "hand_offset",
]

F64 = NDArray[np.float64]
#: the rider's world: 2 ms steps (the mounts are 10-20 ms spring-dampers, the wheels 4 ms
#: contacts), the athletics contact time constant for the body, also between riders (the
#: strike-stiff 2 ms of the response worlds needs 1 ms steps)
RIDER_WORLD = WorldConfig(
    timestep=0.002, contact_solref=(0.02, 1.0), body_contact_solref=(0.02, 1.0)
)
#: mount spring-dampers (time constant s, damping ratio): saddle, hands, feet
SEAT_SPRING = (0.01, 1.0)
HAND_SPRING = (0.02, 1.0)
FOOT_SPRING = (0.02, 1.0)


def fit_bicycle(params: BicycleParams, athlete: Athlete, *, knee_at_bottom: float = 0.45,
                posture: Posture | None = None, elbow: float = math.radians(30.0),
                arm_drop: float = math.radians(60.0),
                seat_angle: float = math.radians(73.0)) -> BicycleParams:  # fmt: skip
    """The bicycle fitted to the athlete in ``posture``: the saddle up the seat tube
    (``seat_angle`` from horizontal through the bottom bracket) until the knee bends
    ``knee_at_bottom`` rad with the pedal at the bottom, and the grips where the hands reach
    with ``elbow`` rad of elbow bend, the arms ``arm_drop`` rad below horizontal."""
    dt = params.drivetrain
    if dt is None:
        raise ConfigError("a rider needs a bicycle with a drivetrain")
    pose = posture or Posture()
    _, bases, sit = trunk_pose(athlete, pose)
    thigh, shin = float(athlete.thigh.mean()), float(athlete.shin.mean())
    leg = math.sqrt(thigh**2 + shin**2 + 2 * thigh * shin * math.cos(knee_at_bottom))
    ball = ball_offset(athlete)
    reach = math.hypot(leg + abs(float(ball[2])) * 0.5, float(ball[0]))  # hip to ball of foot
    bb = np.array([dt.bottom_bracket[0], 0.0, dt.bottom_bracket[1]])
    pedal = bb - [0.0, 0.0, dt.crank_length]
    up = np.array([-math.cos(seat_angle), 0.0, math.sin(seat_angle)])
    hip = 0.5 * (bases[2] + bases[3]) - sit  # from the sit point
    gap = lambda s: float(np.linalg.norm(bb + s * up + hip - pedal)) - reach  # noqa: E731
    along = float(brentq(gap, 0.0, 2.0))
    seat = bb + along * up
    shoulder = seat - sit + bases[0]
    v1 = quat_rotate(
        athlete.neutral[SIM_BODY_INDEX["l_upper_arm"]],
        athlete.character.body_pos[SIM_BODY_INDEX["l_forearm"]],
    )
    v2 = quat_rotate(
        athlete.neutral[SIM_BODY_INDEX["l_forearm"]],
        athlete.character.body_pos[SIM_BODY_INDEX["l_hand"]],
    )
    v2 = v2 + quat_rotate(athlete.neutral[SIM_BODY_INDEX["l_hand"]], hand_offset(athlete))
    l1, l2 = float(np.linalg.norm(v1)), float(np.linalg.norm(v2))
    arm = math.sqrt(l1**2 + l2**2 + 2 * l1 * l2 * math.cos(elbow))
    half = params.fit.grip_offset if params.fit else 0.25
    lateral = half - float(shoulder[1])
    flat = math.sqrt(max(arm**2 - lateral**2, 0.01))
    grips = shoulder + flat * np.array([math.cos(arm_drop), 0.0, -math.sin(arm_drop)])
    fit = Fit(seat=(float(seat[0]), float(seat[2])), grips=(float(grips[0]), float(grips[2])),
              grip_offset=half)  # fmt: skip
    return replace(params, fit=fit)


def ball_offset(athlete: Athlete, side: str = "l") -> F64:
    """The ball of the foot (the foot's patch geom) in that foot's frame."""
    m = athlete.character.model
    return m.geom_pos[m.geom(f"{side}_foot_ball").id].copy()


def hand_offset(athlete: Athlete, side: str = "l") -> F64:
    """The grip point (the hand's capsule centre) in that hand's frame."""
    m = athlete.character.model
    geoms = np.flatnonzero(m.geom_bodyid == m.body(f"{side}_hand").id)
    return m.geom_pos[geoms[0]].copy()


class RiderMount:
    """A :class:`~reactmocap.athletics.cycling_scene.ScenePart`: sites on the rider (sit bones,
    grip points, balls of the feet) and on the bicycle (saddle, grips, pedals) tied by soft
    ``connect`` equalities: two at the saddle (a pivot about the saddle's lateral axis), one
    per hand and foot. Also stops the rider's shins and feet colliding with the floor (a loaded
    pedal sits 10 cm up: a foot brushing the ground in a lean would trip the simulation)."""

    def __init__(self, athlete: Athlete, bicycle: Bicycle, prefix: str) -> None:
        fit = bicycle.params.fit
        dt = bicycle.params.drivetrain
        if fit is None or dt is None:
            raise ConfigError("a rider's bicycle needs a fit and a drivetrain (fit_bicycle)")
        self.athlete, self.bicycle, self.prefix = athlete, bicycle, prefix

    def build(self, spec: mujoco.MjSpec) -> None:
        pre, bp, ath = self.prefix, self.bicycle.prefix, self.athlete
        p = self.bicycle.params
        fit = p.fit
        assert fit is not None
        neutral = ath.neutral
        rr = p.rear.radius
        pelvis = spec.body(pre + "pelvis")
        # compiled beside its bicycle (the characters' reference poses all stand at the origin:
        # many riders there would touch each other)
        pl = self.bicycle.placement
        pelvis.pos = [pelvis.pos[0] + pl.x, pelvis.pos[1] + pl.y, pelvis.pos[2]]
        frame = spec.body(bp + "frame")
        fork = spec.body(bp + "fork")
        head = p.steer_foot + p.steer_axis * (p.front.radius / p.steer_axis[2])
        sx, sz = fit.seat
        for side, sign in (("l", 1.0), ("r", -1.0)):
            off = np.array([SIT_OFFSET[0], sign * SIT_OFFSET[1], SIT_OFFSET[2]])
            local = quat_rotate(quat_conj(neutral[0]), off)
            pelvis.add_site(name=f"{pre}{side}_sit", pos=local.tolist())
            frame.add_site(name=f"{bp}{side}_seat", pos=[sx, sign * SIT_OFFSET[1], sz - rr])
            spec.add_equality(type=mujoco.mjtEq.mjEQ_CONNECT, objtype=mujoco.mjtObj.mjOBJ_SITE,
                              name1=f"{pre}{side}_sit", name2=f"{bp}{side}_seat",
                              solref=list(SEAT_SPRING))  # fmt: skip
            hand = spec.body(f"{pre}{side}_hand")
            hand.add_site(name=f"{pre}{side}_grip", pos=hand_offset(ath, side).tolist())
            gx, gz = fit.grips
            fork.add_site(name=f"{bp}{side}_grip",
                          pos=[gx - head[0], sign * fit.grip_offset, gz - head[2]])  # fmt: skip
            spec.add_equality(type=mujoco.mjtEq.mjEQ_CONNECT, objtype=mujoco.mjtObj.mjOBJ_SITE,
                              name1=f"{pre}{side}_grip", name2=f"{bp}{side}_grip",
                              solref=list(HAND_SPRING))  # fmt: skip
            foot = spec.body(f"{pre}{side}_foot")
            foot.add_site(name=f"{pre}{side}_ball", pos=ball_offset(ath, side).tolist())
            pedal = "left_pedal" if side == "l" else "right_pedal"
            spec.add_equality(type=mujoco.mjtEq.mjEQ_CONNECT, objtype=mujoco.mjtObj.mjOBJ_SITE,
                              name1=f"{pre}{side}_ball", name2=f"{bp}{pedal}",
                              solref=list(FOOT_SPRING))  # fmt: skip

    def bind(self, world: World) -> None:
        m = world.model
        pre, bp = self.prefix, self.bicycle.prefix
        self.world = world
        self.sites = {
            name: int(m.site(n).id)
            for name, n in (("l_grip", f"{bp}l_grip"), ("r_grip", f"{bp}r_grip"),
                            ("l_pedal", f"{bp}left_pedal"), ("r_pedal", f"{bp}right_pedal"),
                            ("l_ball", f"{pre}l_ball"), ("r_ball", f"{pre}r_ball"),
                            ("l_seat", f"{bp}l_seat"), ("r_seat", f"{bp}r_seat"),
                            ("l_sit", f"{pre}l_sit"), ("r_sit", f"{pre}r_sit"))
        }  # fmt: skip
        for part in ("l_shin", "r_shin", "l_foot", "r_foot"):
            geoms = np.flatnonzero(m.geom_bodyid == m.body(pre + part).id)
            m.geom_contype[geoms] = 0
            m.geom_conaffinity[geoms] = 0
