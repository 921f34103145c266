"""The handspring vault (Hodgins et al. 1995, "Vaulting and Balancing"): a gymnast runs onto a
springboard, springs onto a vaulting horse with her hands, turns a layout somersault over
it and lands on the far side. Six states: hurdle step (the flight before the board), board
contact (the board springs; at its deepest the knees extend and add energy), first flight
(the shoulders aim the hands at the horse, eq. 12), horse contact (arms straight, no
shoulder or wrist torque), second flight (layout, feet a little apart) and landing (the
athletics landing and balance controllers). The body is the thesis female scaled to the mean
gymnast of Table 1 (47.96 kg, 1.55 m); the board is a plate on a spring and damper; the
horse is of the women's competition height of Takei's data (1.20 m). :data:`TABLE1` holds
Table 1 of the paper (human data of Takei 1990, 24 gymnasts); :func:`table1` measures the
same rows on a simulated vault. Design and figures: ``docs/athletics.md``."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.balance import Balance
from reactmocap.athletics.bodies import Athlete, athlete
from reactmocap.athletics.land import Landing, LandingParams
from reactmocap.athletics.machine import NEXT, Basis, Context
from reactmocap.athletics.rig import joint_index, per_joint
from reactmocap.athletics.scene import ATHLETICS_WORLD, shins_off_floor
from reactmocap.athletics.sequencer import Sequencer
from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_conj, quat_mul, quat_rotate
from reactmocap.sim.bodies import BALL_JOINTS, SIM_BODIES
from reactmocap.sim.controllers.base import FunctionController
from reactmocap.sim.controllers.machine import State, after
from reactmocap.sim.rollout import RolloutResult, rollout
from reactmocap.sim.world import World

__all__ = [
    "BOARD",
    "HORSE",
    "TABLE1",
    "Table1Row",
    "VaultParams",
    "VaultResult",
    "table1",
    "vault",
    "vault_athlete",
    "vault_plot",
    "vault_world",
]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)


# ---------------------------------------------------------------------------------- Table 1
@dataclass(frozen=True)
class Table1Row:
    """One row of Table 1: its key in reports, what it measures, the unit, the human mean,
    minimum and maximum over 24 gymnasts (Takei 1990), and Hodgins et al.'s simulation."""

    key: str
    label: str
    unit: str
    mean: float
    low: float
    high: float
    hodgins: float


#: Table 1 of Hodgins, Wooten, Brogan & O'Brien 1995, "Animating Human Athletics"
#: (SIGGRAPH 95): velocities, contact times and forces of 24 elite female gymnasts at the
#: 1987 Pan American Games (Takei, Int. J. Sport Biomechanics 6:29-55, 1990) and the
#: authors' simulated vault. Transcribed from ``../shared/seeds/000_49afa289a704f6ef.txt``.
TABLE1: tuple[Table1Row, ...] = (
    Table1Row("mass_kg", "mass", "kg", 47.96, 35.5, 64.0, 64.3),
    Table1Row("height_m", "height", "m", 1.55, 1.39, 1.66, 1.64),
    Table1Row("board_contact_s", "board contact", "s", 0.137, 0.11, 0.15, 0.105),
    Table1Row("first_flight_s", "first flight", "s", 0.235, 0.14, 0.30, 0.156),
    Table1Row("horse_contact_s", "horse contact", "s", 0.245, 0.19, 0.30, 0.265),
    Table1Row("second_flight_s", "second flight", "s", 0.639, 0.50, 0.78, 0.632),
    Table1Row("board_touchdown_vx_m_s", "horizontal velocity, board touchdown", "m/s", 6.75, 5.92, 7.25, 6.75),
    Table1Row("board_liftoff_vx_m_s", "horizontal velocity, board lift-off", "m/s", 4.61, 3.97, 5.26, 4.01),
    Table1Row("horse_touchdown_vx_m_s", "horizontal velocity, horse touchdown", "m/s", 4.61, 3.97, 5.26, 4.01),
    Table1Row("horse_liftoff_vx_m_s", "horizontal velocity, horse lift-off", "m/s", 3.11, 2.48, 3.83, 2.83),
    Table1Row("board_touchdown_vz_m_s", "vertical velocity, board touchdown", "m/s", -1.15, -1.54, -0.71, -1.13),
    Table1Row("board_liftoff_vz_m_s", "vertical velocity, board lift-off", "m/s", 3.34, 2.98, 3.87, 3.81),
    Table1Row("horse_touchdown_vz_m_s", "vertical velocity, horse touchdown", "m/s", 1.26, 0.74, 2.39, 2.13),
    Table1Row("horse_liftoff_vz_m_s", "vertical velocity, horse lift-off", "m/s", 1.46, 0.56, 2.47, 1.10),
    Table1Row("board_force_n", "average vertical force, board contact", "N", 2175.0, 1396.0, 2792.0, 5075.0),
    Table1Row("horse_force_n", "average vertical force, horse contact", "N", 521.0, 309.0, 752.0, 957.0),
)  # fmt: skip
TABLE1_KEYS = tuple(r.key for r in TABLE1)
#: the Table 1 mean gymnast the vault's body is scaled to
GYMNAST_MASS = 47.96
GYMNAST_HEIGHT = 1.55


# ---------------------------------------------------------------------------------- apparatus
@dataclass(frozen=True)
class Apparatus:
    """A box's size (full extents x, y, z, m) and the position of its centre at rest."""

    size: tuple[float, float, float]
    centre: tuple[float, float, float]

    @property
    def top(self) -> float:
        return self.centre[2] + 0.5 * self.size[2]


#: the springboard's moving plate: 1.2 m long, 0.6 m wide, its top 0.20 m up at rest
BOARD = Apparatus((1.2, 0.6, 0.06), (0.0, 0.0, 0.17))
#: the horse, set sideways as for women's vault: 1.60 m long across the run, 0.35 m deep,
#: its top 1.20 m up (Takei's 1987 competition height for women); centre x from the board's
#: centre is VaultParams.horse_distance
HORSE = Apparatus((0.35, 1.60, 1.20), (0.0, 0.0, 0.60))


@dataclass(frozen=True)
class VaultParams:
    """The vault's physical set-up and the gymnast's control parameters (SI units, radians).

    Args:
        board_stiffness: the springboard's spring (N/m); board_damping: its damper (N s/m).
        board_mass: the moving plate's mass (kg).
        horse_distance: from the board's centre to the horse's centre along the run (m).
        approach_vx, approach_vz: the COM's velocity at the start of the hurdle step's last
            instant (the paper: 6.75 m/s forward; Table 1's board touchdown vertical -1.15).
        start_clearance: height of the soles over the board at the start (m).
        start_x: the COM's position along the run at the start, from the board's centre (m).
        block: hip flexion at board touchdown (rad; the feet ahead: "blocking").
        knee_touchdown: knee flexion at board touchdown (rad).
        knee_stiffness: knee and hip stiffness on the board (units of m g L).
        push_stiffness: stiffness of the extension at the board's deepest (units of m g L).
        push_hip: hip flexion the extension drives to (rad; < 0 brings the trunk forward).
        arms_push: shoulder pitch the arms swing to during the extension (rad).
        approach_spin: forward angular velocity of the body at the start (rad/s), estimated
            like the paper's other initial conditions.
        arms_flight2: shoulder pitch in the second flight (rad).
        pike2: hip flexion in the second flight (rad; a pike turns the somersault faster).
        arms_board: shoulder pitch the arms swing to on the board (rad, < 0 forward/up).
        hand_target: where on the horse's top the hands aim, from its centre along the run (m).
        pike: hip flexion held in the first flight (rad).
        flight_stiffness: trunk and leg stiffness in the flights (units of m g L).
        horse_push: shoulder extension stiffness while on the horse (units of m g L; the
            paper's "no torque at the shoulder" is 0).
        landing_height: the COM height (m) below which the second flight hands over to the
            landing controller.
        mat_solref: contact time constant of the floor (s): a landing mat, softer than the
            ground (the paper: "reducing the stiffness of the ground").
    """

    board_stiffness: float = 36849.0
    board_damping: float = 242.8
    board_mass: float = 5.0
    horse_distance: float = 1.621
    approach_vx: float = 6.75
    approach_vz: float = -1.10
    start_clearance: float = 0.02
    start_x: float = -0.3523
    block: float = -0.6745
    knee_touchdown: float = 0.2449
    knee_stiffness: float = 12.0
    push_stiffness: float = 20.0
    push_hip: float = -0.1641
    arms_push: float = -2.468
    approach_spin: float = 0.0
    pike2: float = 0.0
    arms_flight2: float = -2.388
    arms_board: float = -2.65
    hand_target: float = -0.05048
    pike: float = -0.06506
    flight_stiffness: float = 4.145
    horse_push: float = 0.0
    landing_height: float = 1.039
    mat_solref: float = 0.03

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ConfigError(f"vault parameter {f.name} must be a finite number, got {v!r}")
        for name in ("board_stiffness", "board_mass", "horse_distance", "approach_vx",
                     "mat_solref"):  # fmt: skip
            if getattr(self, name) <= 0:
                raise ConfigError(f"vault parameter {name} must be > 0")


# ---------------------------------------------------------------------------------- the body
_ATHLETE: dict[tuple[float, float], Athlete] = {}


def vault_athlete(height: float = GYMNAST_HEIGHT, mass: float = GYMNAST_MASS) -> Athlete:
    """The thesis female body scaled to ``height`` m and ``mass`` kg (Table 1's mean gymnast
    by default): lengths by the height ratio, segment masses by the mass ratio, inertias by
    both (mass times length squared); the thesis female's proportions are kept."""
    if not (math.isfinite(height) and math.isfinite(mass) and height > 0 and mass > 0):
        raise ConfigError(f"height and mass must be > 0, got {height!r}, {mass!r}")
    key = (round(height, 4), round(mass, 4))
    if key not in _ATHLETE:
        from reactmocap.athletics.bodies import (
            _inertials,
            _joint_points,
            athlete_of,
            thesis_skeleton,
        )
        from reactmocap.library.bodyparts import BodyPartMap
        from reactmocap.library.skeleton import Skeleton
        from reactmocap.sim.character import SegmentInertia, build_character

        skel, parts = thesis_skeleton("female")
        s = height / 1.60  # the thesis female's height (Table 3.4)
        inert = _inertials("female")
        r = mass / sum(v.mass for v in inert.values())
        layout = replace(skel.layout, end_sites={j: tuple(float(x) * s for x in v)  # type: ignore[misc]
                                                 for j, v in skel.layout.end_sites.items()})  # fmt: skip
        scaled = Skeleton(skel.names, skel.parents, skel.offsets * s, layout)
        parts_s = BodyPartMap(scaled, dict(parts.joints))
        pts = _joint_points("female")
        root = 0.5 * (pts["ULEGL"] + pts["ULEGR"]) * s
        ref = Motion(
            scaled, 30.0, root[None], np.tile([1.0, 0.0, 0.0, 0.0], (1, scaled.num_joints, 1))
        )
        inertials = {}
        for k, v in inert.items():
            com = np.asarray(v.com, dtype=np.float64) * s
            inertia = np.asarray(v.inertia, dtype=np.float64) * r * s * s
            inertials[k] = SegmentInertia(
                v.mass * r,
                (float(com[0]), float(com[1]), float(com[2])),
                tuple((float(a), float(b), float(c)) for a, b, c in inertia),
            )
        ch = build_character(scaled, parts_s, reference=ref, inertials=inertials)
        _ATHLETE[key] = athlete_of(ch, "female")
    return _ATHLETE[key]


@dataclass(frozen=True)
class _Apparatus:
    """The vault's :class:`~reactmocap.sim.world.Scene`: the springboard (a plate on a vertical
    slide joint with the board's stiffness and damping, resting with its top at its height) and
    the horse; the floor is the landing mat."""

    params: VaultParams

    def build(self, spec: mujoco.MjSpec) -> None:
        p = self.params
        plate = spec.worldbody.add_body(name="board", pos=list(BOARD.centre))
        j = plate.add_joint(name="board_spring", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 0, 1])
        j.stiffness = [p.board_stiffness, 0.0, 0.0]
        j.damping = [p.board_damping, 0.0, 0.0]
        j.range = [-0.15, 0.05]
        j.limited = 1
        # the spring's rest position lifts the plate by its own weight: it rests at its height
        j.springref = p.board_mass * 9.81 / p.board_stiffness
        g = plate.add_geom(name="board_plate", type=mujoco.mjtGeom.mjGEOM_BOX,
                           size=[0.5 * x for x in BOARD.size], rgba=[0.75, 0.55, 0.35, 1.0])  # fmt: skip
        g.mass = p.board_mass
        horse = spec.worldbody.add_body(
            name="horse", pos=[p.horse_distance, HORSE.centre[1], HORSE.centre[2]]
        )
        horse.add_geom(name="horse_box", type=mujoco.mjtGeom.mjGEOM_BOX,
                       size=[0.5 * x for x in HORSE.size], rgba=[0.45, 0.3, 0.2, 1.0])  # fmt: skip

    def configure(self, world: World) -> None:
        # the shins do not touch the floor (as in the athletics world); the mat is softer
        m = world.model
        shins_off_floor(world)
        # the apparatus is as soft as the floor (the values were found with it so) and, like
        # the floor, dominates the solref of its contacts with the gymnast
        for name in ("board_plate", "horse_box"):
            g = m.geom(name).id
            m.geom_solref[g] = world.config.contact_solref
            m.geom_solmix[g] = 1e9
        m.geom_solref[m.geom("floor").id] = (self.params.mat_solref, 1.0)


def vault_world(ath: Athlete, params: VaultParams) -> World:
    """A World with the athlete and the vault's apparatus (:class:`_Apparatus`)."""
    return World(ath.character, ATHLETICS_WORLD, scene=_Apparatus(params))


# ---------------------------------------------------------------------------------- control
_J = {name: joint_index(name) for name in BALL_JOINTS}
_LEGS = [_J[f"{s}_{j}"] for s in "lr" for j in ("hip", "knee", "ankle")]
_ARMS = [_J[f"{s}_{j}"] for s in "lr" for j in ("shoulder", "elbow", "wrist")]


@dataclass
class VaultLog:
    """Per tick: time, COM, COM velocity, vertical force from the board and from the horse
    on the gymnast (N), whether the feet touch the board, the hands the horse, anything the
    floor, and the lowest point of the body over the horse's top (m)."""

    rows: list[tuple] = field(default_factory=list)

    def arrays(self) -> dict[str, NDArray]:
        names = ("t", "com", "com_vel", "board_force", "horse_force", "on_board", "on_horse",
                 "on_floor", "over_horse_clearance", "pitch")  # fmt: skip
        if not self.rows:
            return {n: np.zeros(0) for n in names}
        return {n: np.array(c) for n, c in zip(names, zip(*self.rows))}


class Vault(Basis):
    """The vault's first five states as a basis controller; hands over to the landing."""

    name = "vault"
    initial = "hurdle"

    def __init__(self, params: VaultParams, log: VaultLog) -> None:
        self.p = params
        self.log = log

    def states(self, ctx: Context) -> list[State]:
        p = self.p
        world = ctx.world
        m = world.model
        wc = ctx.rig.wc
        rig = ctx.rig
        every = ctx.control_every
        board_geom = int(m.geom("board_plate").id)
        horse_geom = int(m.geom("horse_box").id)
        floor = int(m.geom("floor").id)
        board_dof = int(m.jnt_dofadr[m.joint("board_spring").id])
        own = world.geom_character == ctx.character
        part = world.geom_body
        feet = {SIM_BODIES.index(b) for b in ("l_foot", "r_foot")}
        hands = {SIM_BODIES.index(b) for b in ("l_hand", "r_hand", "l_forearm", "r_forearm")}
        f6 = np.zeros(6)
        seen = {"board": 0, "horse": 0, "deepest": False}
        # the geoms that must stay above the horse's top while over it: all but the arms'
        check = np.flatnonzero(own & ~np.isin(part, list(hands)))
        is_box = m.geom_type == int(mujoco.mjtGeom.mjGEOM_BOX)
        is_capsule = m.geom_type == int(mujoco.mjtGeom.mjGEOM_CAPSULE)
        chest = int(wc.body_ids[SIM_BODIES.index("chest")])
        sh_j = [m.joint(wc.prefix + f"{s}_shoulder").id for s in "lr"]
        horse_top = HORSE.top
        hx0 = p.horse_distance - 0.5 * HORSE.size[0]
        hx1 = p.horse_distance + 0.5 * HORSE.size[0]

        def sense(t: float) -> tuple[bool, bool, bool]:
            """Contacts with the board (feet), the horse (hands) and the floor; logs a row."""
            d = world.data
            fb = fh = 0.0
            on_b = on_h = on_f = False
            for i in range(d.ncon):
                g1, g2 = int(d.contact.geom[i, 0]), int(d.contact.geom[i, 1])
                other = g2 if own[g1] else g1 if own[g2] else -1
                mine = g1 if own[g1] else g2
                if other < 0 or other not in (board_geom, horse_geom, floor):
                    continue
                mujoco.mj_contactForce(m, d, i, f6)
                fz = abs(float((d.contact.frame[i].reshape(3, 3).T @ f6[:3])[2]))
                if other == board_geom:
                    fb += fz
                    on_b |= int(part[mine]) in feet
                elif other == horse_geom:
                    fh += fz
                    on_h |= int(part[mine]) in hands
                else:
                    on_f = True
            s = ctx.sense(t)
            # the body's lowest point while over the horse (only the hands may touch)
            xs = d.geom_xpos[check, 0]
            over = (xs > hx0) & (xs < hx1)
            clear = math.inf
            if over.any():
                g = check[over]
                rz = np.abs(d.geom_xmat[g].reshape(-1, 3, 3)[:, 2, :])  # |R[z, j]|
                size = m.geom_size[g]
                # each geom's lowest point: a box's corners, a capsule's end cap, a sphere
                low = np.where(is_box[g], (rz * size).sum(axis=1),
                               np.where(is_capsule[g], rz[:, 2] * size[:, 1] + size[:, 0],
                                        size[:, 0]))  # fmt: skip
                clear = float((d.geom_xpos[g, 2] - low).min()) - horse_top
            pitch = _body_pitch(d, chest, ctx.athlete)
            self.log.rows.append((t, s.com.copy(), s.com_vel.copy(), fb, fh, on_b, on_h, on_f,
                                  clear, pitch))  # fmt: skip
            return on_b, on_h, on_f

        def pose(goal: dict[int, tuple[float, float, float]], dur: float, t: float) -> None:
            g = np.full((NJ, 3), np.nan)
            for j, v in goal.items():
                g[j] = v
            rig.move(g, dur, t, list(goal))

        def stiff(values: dict[str, float]) -> None:
            rig.set_stiffness(per_joint(values))

        flight = {"waist": p.flight_stiffness, "back": p.flight_stiffness, "neck": 0.3,
                  "shoulder": 1.0, "elbow": 0.5, "wrist": 0.1, "hip": p.flight_stiffness,
                  "knee": p.flight_stiffness, "ankle": 0.5}  # fmt: skip

        # -------------------------------------------------------------- hurdle
        def hurdle_enter(_w: World, t: float) -> None:
            stiff(flight | {"hip": p.knee_stiffness, "knee": p.knee_stiffness, "ankle": 2.0})
            rig.support[:] = 0.0
            goal = {_J[f"{s}_hip"]: (p.block, 0.0, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_knee"]: (p.knee_touchdown, 0.0, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_ankle"]: (-0.2, 0.0, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_shoulder"]: (p.arms_board, 0.0, 0.0) for s in "lr"}
            pose(goal, 0.1, t)

        def hurdle(_w: World, t: float) -> None:
            sense(t)

        def on_board(_w: World, _t: float, _ti: float) -> bool:
            return bool(self.log.rows and self.log.rows[-1][5])

        # -------------------------------------------------------------- board contact
        def board_enter(_w: World, t: float) -> None:
            seen["deepest"] = False
            seen["board"] = 0

        def board(w: World, t: float) -> None:
            on_b, _, _ = sense(t)
            seen["board"] = 0 if on_b else seen["board"] + 1
            # at the board's deepest (the plate stops going down) the legs extend
            if not seen["deepest"] and w.data.qvel[board_dof] >= 0.0 and _ti_since(t) > 0.01:
                seen["deepest"] = True
                stiff(flight | {"hip": p.push_stiffness, "knee": p.push_stiffness,
                                "ankle": p.push_stiffness})  # fmt: skip
                goal = {_J[f"{s}_knee"]: (0.0, 0.0, 0.0) for s in "lr"}
                goal |= {_J[f"{s}_hip"]: (p.push_hip, 0.0, 0.0) for s in "lr"}
                goal |= {_J[f"{s}_ankle"]: (0.3, 0.0, 0.0) for s in "lr"}
                goal |= {_J[f"{s}_shoulder"]: (p.arms_push, 0.0, 0.0) for s in "lr"}
                pose(goal, 0.05, t)

        t_in = {"board": 0.0}

        def _ti_since(t: float) -> float:
            return t - t_in["board"]

        def board_enter2(w: World, t: float) -> None:
            t_in["board"] = t
            board_enter(w, t)

        def left_board(_w: World, _t: float, t_in_state: float) -> bool:
            return t_in_state > 0.02 and seen["board"] >= 2

        # -------------------------------------------------------------- first flight
        def flight1_enter(_w: World, t: float) -> None:
            stiff(flight)
            goal = {_J[f"{s}_{j}"]: (0.0, 0.0, 0.0) for s in "lr" for j in ("knee", "elbow")}
            goal |= {_J[f"{s}_hip"]: (-p.pike, 0.0, 0.0) for s in "lr"}
            goal |= {_J[j]: (0.0, 0.0, 0.0) for j in ("waist", "back")}
            pose(goal, 0.1, t)

        def flight1(w: World, t: float) -> None:
            sense(t)
            # eq. 12: each arm points from its shoulder at the hands' place on the horse
            d = w.data
            target = np.array([p.horse_distance + p.hand_target, 0.0, horse_top])
            goal = {}
            chest_anat = quat_mul(
                d.xquat[chest], quat_conj(ctx.athlete.neutral[SIM_BODIES.index("chest")])
            )
            for k, s in enumerate("lr"):
                sh = d.xanchor[sh_j[k]].copy()
                aim = np.array([target[0], sh[1], target[2]]) - sh
                u = quat_rotate(quat_conj(chest_anat), aim / max(np.linalg.norm(aim), 1e-9))
                goal[_J[f"{s}_shoulder"]] = (float(math.atan2(-u[0], -u[2])), 0.0, 0.0)
                goal[_J[f"{s}_wrist"]] = (-0.3, 0.0, 0.0)
            pose(goal, 0.0, t)

        def on_horse(_w: World, _t: float, _ti: float) -> bool:
            return bool(self.log.rows and self.log.rows[-1][6])

        # -------------------------------------------------------------- horse contact
        def horse_enter(_w: World, t: float) -> None:
            seen["horse"] = 0
            values = flight | {"shoulder": p.horse_push, "wrist": 0.0, "elbow": 3.0}
            stiff(values)
            goal = {_J[f"{s}_elbow"]: (0.0, 0.0, 0.0) for s in "lr"}
            if p.horse_push > 0:
                goal |= {_J[f"{s}_shoulder"]: (-math.pi, 0.0, 0.0) for s in "lr"}
            pose(goal, 0.05, t)

        def horse(_w: World, t: float) -> None:
            _, on_h, _ = sense(t)
            seen["horse"] = 0 if on_h else seen["horse"] + 1

        def left_horse(_w: World, _t: float, t_in_state: float) -> bool:
            return t_in_state > 0.02 and seen["horse"] >= 2

        # -------------------------------------------------------------- second flight
        def flight2_enter(_w: World, t: float) -> None:
            stiff(flight)
            goal = {_J[f"{s}_hip"]: (-p.pike2, 0.08 if s == "l" else -0.08, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_knee"]: (0.0, 0.0, 0.0) for s in "lr"}
            goal |= {_J[j]: (0.0, 0.0, 0.0) for j in ("waist", "back")}
            goal |= {_J[f"{s}_shoulder"]: (p.arms_flight2, 0.0, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_wrist"]: (0.0, 0.0, 0.0) for s in "lr"}
            pose(goal, 0.15, t)

        def flight2(_w: World, t: float) -> None:
            sense(t)

        def landing_near(w: World, t: float, t_in_state: float) -> bool:
            s = ctx.senses
            return (
                t_in_state > 0.1 and float(s.com_vel[2]) < 0 and float(s.com[2]) < p.landing_height
            )

        def logged(fn: Callable[[World, float], None]) -> FunctionController:
            return FunctionController(fn, every)

        def after_landing(w: World, t: float) -> None:
            sense(t)

        self.after_landing = after_landing
        return [
            State("hurdle", logged(hurdle), hurdle_enter, ((on_board, "board"),)),
            State("board", logged(board), board_enter2,
                  ((left_board, "flight1"), (after(0.4), "flight1"))),
            State("flight1", logged(flight1), flight1_enter,
                  ((on_horse, "horse"), (after(1.0), "flight2"))),
            State("horse", logged(horse), horse_enter,
                  ((left_horse, "flight2"), (after(0.6), "flight2"))),
            State("flight2", logged(flight2), flight2_enter,
                  ((landing_near, NEXT), (after(2.0), NEXT))),
        ]  # fmt: skip


def _body_pitch(d: mujoco.MjData, chest: int, ath: Athlete) -> float:
    """The chest's anatomical pitch about the run's lateral axis (rad, forward > 0; a full
    somersault is 2 pi), unwrapped by the caller."""
    q = quat_mul(d.xquat[chest], quat_conj(ath.neutral[SIM_BODIES.index("chest")]))
    up = quat_rotate(q, np.array([0.0, 0.0, 1.0]))
    return float(math.atan2(up[0], up[2]))


class _Logger:
    """Keeps logging the vault's rows through the landing (a controller after the sequencer)."""

    def __init__(self, vault: Vault, seq: Sequencer) -> None:
        self.vault = vault
        self.seq = seq
        self.control_every = seq.control_every

    def reset(self, world: World) -> None:
        del world

    def control(self, world: World, t: float) -> None:
        if not self.seq.state.startswith("vault."):
            self.vault.after_landing(world, t)


# ---------------------------------------------------------------------------------- a vault
@dataclass
class VaultResult:
    motion: Motion
    report: dict[str, Any]
    rollout: RolloutResult
    log: dict[str, NDArray]
    transitions: list[tuple[float, str, str]]
    world: World
    params: VaultParams

    def report_json(self) -> str:
        from reactmocap.athletics.behaviours import _clean

        return json.dumps(_clean(self.report), indent=2) + "\n"

    def scene_video(self, path: str | Path, fps: float = 30.0) -> Path:
        """The vault as recorded, rendered with the board and horse (MuJoCo)."""
        return render_world_video(self.rollout, path, fps=fps)


def render_world_video(res: RolloutResult, path: str | Path, fps: float = 30.0,
                       size: tuple[int, int] = (512, 384)) -> Path:  # fmt: skip
    """A rollout's recorded states rendered in its own world (its apparatus included), the
    camera following character 0 from the side. Raises RenderUnavailable without GL."""

    from reactmocap.response.plots import write_video
    from reactmocap.response.render import offscreen_renderer

    world = res.world
    m = world.model
    d = mujoco.MjData(m)
    _times, qpos = res.frames()
    step = max(1, round(res.fps[0] / fps))
    qpos = qpos[::step]
    width, height = size
    renderer = offscreen_renderer(m, size)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.distance, cam.elevation, cam.azimuth = 5.0, -10.0, 90.0
    frames = np.empty((len(qpos), height, width, 3), dtype=np.uint8)
    root = world.characters[0].qpos_adr
    try:
        for i, q in enumerate(qpos):
            d.qpos[:] = q
            mujoco.mj_kinematics(m, d)
            cam.lookat[:] = (q[root], q[root + 1], 1.0)
            renderer.update_scene(d, camera=cam)
            frames[i] = renderer.render()
    finally:
        renderer.close()
    return Path(write_video(frames, path, fps))


def vault_start(ath: Athlete, p: VaultParams) -> tuple[F64, F64]:
    """qpos and qvel of the gymnast in the hurdle step's flight just before the board: the
    feet ahead (blocking), the knees a little bent, the arms raised, the soles
    ``start_clearance`` over the board's top."""
    angles = np.zeros((NJ, 3))
    for s in "lr":
        angles[_J[f"{s}_hip"]] = (p.block, 0.0, 0.0)
        angles[_J[f"{s}_knee"]] = (p.knee_touchdown, 0.0, 0.0)
        angles[_J[f"{s}_ankle"]] = (-0.2, 0.0, 0.0)
        angles[_J[f"{s}_shoulder"]] = (p.arms_board, 0.0, 0.0)
    q = ath.standing_qpos(angles, pitch=-0.1, clearance=p.start_clearance + BOARD.top)
    com = _com_of(ath, q)
    q[0] += p.start_x - com[0]
    v = np.zeros(6 + 3 * NJ)
    v[0] = p.approach_vx
    v[2] = p.approach_vz
    # the forward rotation the hurdle step brings (body frame of the free joint)
    rot = np.empty(9)
    mujoco.mju_quat2Mat(rot, q[3:7])
    v[3:6] = rot.reshape(3, 3).T @ np.array([0.0, p.approach_spin, 0.0])
    return q, v


def _com_of(ath: Athlete, q: F64) -> F64:
    m = ath.character.model
    d = mujoco.MjData(m)
    d.qpos[:] = q
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    return d.subtree_com[1].copy()


#: seconds the gymnast must stay up after landing for ``landed``
LANDED_AFTER = 1.0
#: physics steps per control tick (4 ms; the board contact lasts about 0.14 s)
CONTROL_EVERY = 8


def vault(
    *,
    body: str = "female",
    params: VaultParams | None = None,
    seconds: float | None = None,
    fps: float = 60.0,
    on_tick: Callable[[float], None] | None = None,
) -> VaultResult:
    """Simulate the handspring vault and measure Table 1 on it (:func:`table1`). ``body`` is
    ``"female"`` (the thesis female scaled to Table 1's mean gymnast) or ``"male"`` (the
    thesis male as is)."""
    p = params or VaultParams()
    if body == "female":
        ath = vault_athlete()
    elif body == "male":
        ath = athlete("male")
    else:
        raise ConfigError(f"unknown vault body {body!r}; valid bodies are ['female', 'male']")
    if seconds is not None and not (math.isfinite(seconds) and seconds > 0):
        raise ConfigError(f"seconds must be > 0, got {seconds!r}")
    duration = 2.2 + LANDED_AFTER if seconds is None else float(seconds)
    world = vault_world(ath, p)
    q, v = vault_start(ath, p)
    world.set_pose(0, q, v)
    ctx = Context.make(world, ath, control_every=CONTROL_EVERY)
    log = VaultLog()
    basis = Vault(p, log)
    seq = Sequencer(ctx, [basis, Landing(LandingParams()), Balance()])
    logger = _Logger(basis, seq)
    tick = None if on_tick is None else (lambda t: on_tick(min(t / duration, 1.0)))
    try:
        res = rollout(world, duration, controllers=[seq, logger], record_fps=fps,
                      on_unstable="stop", on_tick=tick, tick_every=400)  # fmt: skip
    finally:
        ctx.rig.release()
    arrays = log.arrays()
    trans = [(tr.time, tr.source, tr.target) for tr in seq.transitions]
    report = _report(ath, p, arrays, trans, res, ctx)
    motion = res.motion(0, name=f"vault_{ath.name}")
    return VaultResult(motion, report, res, arrays, trans, world, p)


def table1(log: dict[str, NDArray], transitions: list[tuple[float, str, str]],
           mass: float, height: float) -> dict[str, float | None]:  # fmt: skip
    """Table 1's rows measured on a vault's log: contact times are from the first to the last
    tick of contact (the feet on the board, the hands on the horse), flight times between
    them and to the feet's first floor contact, velocities those of the COM at the contacts'
    first and last ticks, average forces the mean vertical contact force over the contact."""
    t = log["t"]
    out: dict[str, float | None] = {k: None for k in TABLE1_KEYS}
    out["mass_kg"] = mass
    out["height_m"] = height
    if t.size == 0:
        return out

    def span(flag: NDArray, after: float = -1.0) -> tuple[int, int] | None:
        idx = np.flatnonzero(flag & (t > after))
        if idx.size == 0:
            return None
        start = int(idx[0])
        # the first uninterrupted contact (a tick's gap is a bounce of the contact)
        stop = start
        for i in idx[1:]:
            if i - stop > 3:
                break
            stop = int(i)
        return start, stop

    board = span(log["on_board"].astype(bool))
    horse = span(log["on_horse"].astype(bool), t[board[1]] if board else -1.0)
    floor = span(log["on_floor"].astype(bool), t[horse[1]] if horse else -1.0)
    vel = log["com_vel"]
    for name, contact in (("board", board), ("horse", horse)):
        if contact:
            a, b = contact
            out[f"{name}_contact_s"] = float(t[b] - t[a])
            for event, i in (("touchdown", a), ("liftoff", b)):
                out[f"{name}_{event}_vx_m_s"] = float(vel[i, 0])
                out[f"{name}_{event}_vz_m_s"] = float(vel[i, 2])
            out[f"{name}_force_n"] = float(np.mean(log[f"{name}_force"][a : b + 1]))
    if horse:
        if board:
            out["first_flight_s"] = float(t[horse[0]] - t[board[1]])
    if floor and horse:
        out["second_flight_s"] = float(t[floor[0]] - t[horse[1]])
    del transitions
    return out


def _report(ath: Athlete, p: VaultParams, log: dict[str, NDArray],
            trans: list[tuple[float, str, str]], res: RolloutResult, ctx: Context) -> dict[str, Any]:  # fmt: skip
    height = GYMNAST_HEIGHT if ath.name == "female" else 1.84
    rows = table1(log, trans, ath.mass, height)
    inside = {}
    close = {}
    for r in TABLE1:
        v = rows[r.key]
        inside[r.key] = v is not None and r.low <= v <= r.high
        if r.unit == "m/s":
            close[r.key] = v is not None and abs(v - r.mean) <= 0.1 * abs(r.mean)
    clear = log["over_horse_clearance"]
    finite = clear[np.isfinite(clear)]
    cleared = bool(
        rows["horse_contact_s"] is not None and (finite.size == 0 or finite.min() > -0.01)
    )
    pitch = np.unwrap(log["pitch"]) if log["pitch"].size else np.zeros(0)
    rotation = float(np.degrees(pitch[-1] - pitch[0])) if pitch.size else 0.0
    td_i = int(np.flatnonzero(log["on_floor"].astype(bool))[0]) if log["on_floor"].any() else -1
    rotation_td = float(np.degrees(pitch[td_i] - pitch[0])) if pitch.size else 0.0
    t = log["t"]
    floor = log["on_floor"].astype(bool)
    td = float(t[np.flatnonzero(floor)[0]]) if floor.any() else None
    arr = ctx.log.arrays()
    pelvis = arr["pelvis"]
    others = arr["others"]
    at = arr["t"]
    standing = float(ath.standing_qpos(np.zeros((NJ, 3)))[2])
    after_td = at >= (td if td is not None else np.inf)
    upright = after_td & (at <= (td or 0) + LANDED_AFTER)
    feet_first = td is not None and not others[at <= td + 0.02].any()
    stayed = bool(upright.any() and not others[upright].any()
                  and pelvis[upright].min() > 0.45 * standing)  # fmt: skip
    landed = bool(feet_first and stayed and res.seconds >= (td or 0) + LANDED_AFTER - 1e-6)
    report: dict[str, Any] = {
        "behaviour": "vault", "body": ath.name, "mass_kg": round(ath.mass, 2),
        "table1": rows,
        "table1_inside": int(sum(inside.values())),
        "table1_outside": [k for k, ok in inside.items() if not ok],
        "velocities_within_10pct": int(sum(close.values())),
        "cleared": cleared,
        "min_clearance_over_horse_m": float(finite.min()) if finite.size else None,
        "landed": landed,
        "touchdown_s": td,
        "rotation_deg": rotation,
        "rotation_at_touchdown_deg": rotation_td,
        "board_stiffness_n_m": p.board_stiffness,
        "board_damping_n_s_m": p.board_damping,
        "horse_height_m": HORSE.top,
        "states": [[round(a, 3), b, c] for a, b, c in trans],
        "simulated_s": round(res.seconds, 3), "wall_s": round(res.wall_s, 3),
        "realtime_factor": round(res.seconds / max(res.wall_s, 1e-9), 2), "status": res.status,
    }  # fmt: skip
    if res.status != "ok":
        report["reason"] = res.reason
    notes = []
    if not cleared:
        notes.append("the gymnast did not clear the horse (a body below its top while over it)")
    if not landed:
        notes.append("the gymnast did not land on her feet and stay up for 1 s")
    if report["table1_inside"] < len(TABLE1):
        notes.append(f"Table 1 rows outside the human range: {report['table1_outside']}")
    report["notes"] = notes
    return report


def vault_plot(result: VaultResult, path: str | Path) -> Path:
    """COM path with the apparatus, and Table 1: ours against the human range and mean."""
    from reactmocap.io import save_png
    from reactmocap.response.plots import _pyplot

    plt = _pyplot()
    log = result.log
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 4.5), dpi=100)
    a1.plot(log["com"][:, 0], log["com"][:, 2], "k-", lw=1.2, label="COM")
    b = BOARD
    a1.add_patch(plt.Rectangle((b.centre[0] - b.size[0] / 2, 0), b.size[0], b.top,
                               color="tan", alpha=0.6))  # fmt: skip
    hx = result.params.horse_distance
    a1.add_patch(plt.Rectangle((hx - HORSE.size[0] / 2, 0), HORSE.size[0], HORSE.top,
                               color="saddlebrown", alpha=0.6))  # fmt: skip
    a1.set_aspect("equal", adjustable="datalim")
    a1.set_xlabel("x (m)")
    a1.set_ylabel("z (m)")
    a1.set_title("handspring vault: COM path")
    rows = result.report["table1"]
    for i, r in enumerate(TABLE1):
        lo, hi = (r.low - r.mean) / abs(r.mean), (r.high - r.mean) / abs(r.mean)
        a2.plot([lo, hi], [i, i], color="0.6", lw=4)
        a2.plot(0, i, "k|")
        v = rows[r.key]
        if v is not None:
            ok = r.low <= v <= r.high
            a2.plot((v - r.mean) / abs(r.mean), i, "o", color="C2" if ok else "C3")
        a2.plot((r.hodgins - r.mean) / abs(r.mean), i, "x", color="C0")
    a2.set_yticks(range(len(TABLE1)))
    a2.set_yticklabels([r.label for r in TABLE1], fontsize=7)
    a2.set_xlabel("relative to the human mean (grey: human range; o ours, x Hodgins 1995)")
    a2.set_xlim(-1.5, 2.5)
    a2.invert_yaxis()
    a2.set_title(f"Table 1: {result.report['table1_inside']}/16 rows inside the human range")
    fig.tight_layout()
    return save_png(fig, path)
