"""The handspring vault's set-up: the springboard and the horse (:data:`BOARD`, :data:`HORSE`,
a MuJoCo scene), the gymnast's body (:func:`vault_athlete`), the vault's parameters
(:class:`VaultParams`) and the starting state in the hurdle step (:func:`vault_start`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from types import MappingProxyType

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import Athlete
from reactmocap.athletics.scene import ATHLETICS_WORLD, shins_off_floor
from reactmocap.athletics.tumble import position_angles
from reactmocap.athletics.vault_table1 import GYMNAST_HEIGHT, GYMNAST_MASS
from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.sim.bodies import BALL_JOINT_INDEX, BALL_JOINTS
from reactmocap.sim.world import World

__all__ = [
    "ALL_ROWS_VALUES",
    "BOARD",
    "HORSE",
    "Apparatus",
    "VaultParams",
    "vault_athlete",
    "vault_start",
    "vault_world",
]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)


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
        start_pitch: the body's pitch at the start (rad, < 0 leaning back: the board
            touchdown's lean).
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
        arm_spring: > 0 makes the horse contact active, unlike the paper: shoulders and
            elbows become a spring of this stiffness (units of m g L) that first yields
            (``yield_shoulder``, ``yield_elbow``) for ``yield_s`` seconds, then blocks (the
            elbows straighten and the shoulders drive to ``block_shoulder`` over ``block_s``
            seconds); 0: the paper's passive strut (``horse_push``).
        arm_damping: the shoulders' and elbows' damping on the horse with ``arm_spring``
            (units of m L sqrt(g L) N m s/rad).
        yield_shoulder: the yield's shoulder pitch, from the angle at the hands' touchdown
            (rad; > 0 lowers the arms toward the body).
        yield_elbow: the yield's elbow flexion (rad, within [0, 2.5]).
        yield_s: seconds from the hands' touchdown to the block.
        block_shoulder: shoulder pitch the block drives to (rad; -pi: the arms in line with
            the trunk, overhead).
        block_s: seconds the block's move takes.
        layout2: seconds the second flight holds the layout after the hands leave the horse
            (the legs clear it) before the tumbling controller takes the body into
            ``position2``.
        position2: the second flight's somersault position (a :data:`POSITIONS` name of
            the tumbling controller): the smaller inertia turns the somersault faster.
        turns2: the rotation (somersaults, counted from the start) the tumbling controller
            opens for: it opens when the rotation predicted at touchdown reaches it.
        touchdown_com: the COM height at touchdown (fraction of the standing COM's) the
            opening's prediction aims at.
        land_knee, land_lead, land_delta, land_damping, land_knee_stiffness, land_restore,
            land_lean: the landing controller's ``knee``, ``lead``, ``delta``, ``damping``,
            ``knee_stiffness``, ``restore`` and ``lean``
            (:class:`~reactmocap.athletics.land.LandingParams`): the vault lands faster than
            a broad jump (about 3.7 m/s forward, 4 m/s down).
        stand_leg, stand_settle: the posture the balance controller stands her up into after
            the landing (:class:`~reactmocap.athletics.balance.Posture` ``leg``, the
            hip-to-ankle length as a fraction of the leg: knees a little bent, and
            ``settle``, the seconds it takes).
        mat_solref: contact time constant of the floor (s): a landing mat, softer than the
            ground (the paper: "reducing the stiffness of the ground").
        mat_damping: the mat contact's damping ratio (1: critical; more: the mat gives back
            less of the landing's energy, as a foam mat does).
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
    start_pitch: float = -0.1
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
    arm_spring: float = 0.0
    arm_damping: float = 0.0
    yield_shoulder: float = 0.0
    yield_elbow: float = 0.0
    yield_s: float = 0.05
    block_shoulder: float = -math.pi
    block_s: float = 0.1
    mat_solref: float = 0.022
    mat_damping: float = 1.0
    layout2: float = 0.065
    position2: str = "tuck"
    turns2: float = 0.966
    touchdown_com: float = 0.987
    land_knee: float = 0.311
    land_lead: float = 0.719
    land_delta: float = -0.107
    land_damping: float = 1.2
    land_knee_stiffness: float = 0.0
    land_restore: float = 0.3
    land_lean: float = 0.396
    stand_leg: float = 0.9
    stand_settle: float = 0.5

    def __post_init__(self) -> None:
        position_angles(self.position2)  # an unknown position lists the valid ones
        for f in fields(self):
            if f.name == "position2":
                continue
            v = getattr(self, f.name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ConfigError(f"vault parameter {f.name} must be a finite number, got {v!r}")
        for name in ("board_stiffness", "board_mass", "horse_distance", "approach_vx",
                     "mat_solref", "mat_damping", "turns2", "touchdown_com", "stand_settle"):  # fmt: skip
            if getattr(self, name) <= 0:
                raise ConfigError(f"vault parameter {name} must be > 0")
        for name in ("arm_spring", "arm_damping", "yield_s"):
            if getattr(self, name) < 0:
                raise ConfigError(
                    f"vault parameter {name} must be >= 0, got {getattr(self, name)!r}"
                )
        if self.block_s <= 0:
            raise ConfigError(f"vault parameter block_s must be > 0, got {self.block_s!r}")
        if not 0.0 <= self.yield_elbow <= 2.5:
            raise ConfigError(
                f"vault yield_elbow must be within [0, 2.5], got {self.yield_elbow!r}"
            )
        if not 0.3 <= self.stand_leg <= 1.0:
            raise ConfigError(f"vault stand_leg must be within [0.3, 1.0], got {self.stand_leg!r}")


#: values (``benchmarks/bench_athletics_running.py --tune-vault``, 2026-12-03) with which all
#: 16 of Table 1's rows are inside the human range and she lands: the active horse contact
#: (``arm_spring``), the board's push and the first flight, the landing re-tuned to them. On a
#: knife edge (the values rounded to 4 decimals, or most of them 2% off, take rows out) and
#: the forearms are on the horse for most of its contact: not the defaults (docs/athletics.md)
ALL_ROWS_VALUES: Mapping[str, float] = MappingProxyType({
    "approach_vz": -1.0237069174124969, "start_pitch": -0.10401579943275072,
    "start_x": -0.4018796829822193, "knee_stiffness": 4.0, "arms_push": -2.663556754331671,
    "board_damping": 219.30899944727597, "horse_distance": 2.0,
    "hand_target": -0.06741257932476542, "pike": -0.06141596648741468,
    "arms_flight2": -2.301986610458221, "arm_spring": 0.380138511216428,
    "yield_elbow": 0.9198492858771935, "yield_shoulder": -0.42919125734542,
    "yield_s": 0.05349259921243724, "block_s": 0.09861381079791331,
    "layout2": 0.12467991821705547, "turns2": 0.9208621025158331,
    "touchdown_com": 1.077305515576973, "land_knee": 0.30772556096344716,
    "land_lead": 0.6886171097716345, "land_damping": 2.0048780349731286,
    "land_restore": 0.4160575211727438, "land_lean": 0.5340825334579754,
    "mat_solref": 0.015310018855889135, "stand_leg": 0.8450928873959748,
    "stand_settle": 0.25929139325180595,
})  # fmt: skip


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
            athlete_of,
            joint_points,
            segment_inertials,
            thesis_skeleton,
        )
        from reactmocap.library.bodyparts import BodyPartMap
        from reactmocap.library.skeleton import Skeleton
        from reactmocap.sim.character import SegmentInertia, build_character

        skel, parts = thesis_skeleton("female")
        s = height / 1.60  # the thesis female's height (Table 3.4)
        inert = segment_inertials("female")
        r = mass / sum(v.mass for v in inert.values())
        layout = replace(skel.layout, end_sites={j: tuple(float(x) * s for x in v)  # type: ignore[misc]
                                                 for j, v in skel.layout.end_sites.items()})  # fmt: skip
        scaled = Skeleton(skel.names, skel.parents, skel.offsets * s, layout)
        parts_s = BodyPartMap(scaled, dict(parts.joints))
        pts = joint_points("female")
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
        m.geom_solref[m.geom("floor").id] = (self.params.mat_solref, self.params.mat_damping)


def vault_world(ath: Athlete, params: VaultParams) -> World:
    """A World with the athlete and the vault's apparatus (:class:`_Apparatus`)."""
    return World(ath.character, ATHLETICS_WORLD, scene=_Apparatus(params))


def vault_start(ath: Athlete, p: VaultParams) -> tuple[F64, F64]:
    """qpos and qvel of the gymnast in the hurdle step's flight just before the board: the
    feet ahead (blocking), the knees a little bent, the arms raised, the soles
    ``start_clearance`` over the board's top."""
    angles = np.zeros((NJ, 3))
    for s in "lr":
        angles[BALL_JOINT_INDEX[f"{s}_hip"]] = (p.block, 0.0, 0.0)
        angles[BALL_JOINT_INDEX[f"{s}_knee"]] = (p.knee_touchdown, 0.0, 0.0)
        angles[BALL_JOINT_INDEX[f"{s}_ankle"]] = (-0.2, 0.0, 0.0)
        angles[BALL_JOINT_INDEX[f"{s}_shoulder"]] = (p.arms_board, 0.0, 0.0)
    q = ath.standing_qpos(angles, pitch=p.start_pitch, clearance=p.start_clearance + BOARD.top)
    com = ath.com_of(q)
    q[0] += p.start_x - com[0]
    v = np.zeros(6 + 3 * NJ)
    v[0] = p.approach_vx
    v[2] = p.approach_vz
    # the forward rotation the hurdle step brings (body frame of the free joint)
    rot = np.empty(9)
    mujoco.mju_quat2Mat(rot, q[3:7])
    v[3:6] = rot.reshape(3, 3).T @ np.array([0.0, p.approach_spin, 0.0])
    return q, v
