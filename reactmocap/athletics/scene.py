"""The athletic scene: a World for one athlete (athletics contact settings), its standing pose,
an optional backpack (mass added to the chest) and a floor that tilts into a slope."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Literal

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.balance import STANDING_LEG, knee_for_length
from reactmocap.athletics.bodies import Athlete
from reactmocap.athletics.rig import joint_index
from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.rotations import quat_conj, quat_from_euler, quat_from_yaw, quat_mul, quat_rotate
from reactmocap.sim.bodies import SIM_BODIES
from reactmocap.sim.world import World, WorldConfig

__all__ = [
    "ATHLETICS_WORLD",
    "BACKPACK_OFFSET",
    "CONTACT_MODELS",
    "DEFAULT_CONTACT",
    "SOLE_TORSION",
    "ContactModel",
    "Slope",
    "add_backpack",
    "athletics_world",
    "contact_model",
    "shins_off_floor",
    "stand_angles",
]

F64 = NDArray[np.float64]
#: the athletics world: MuJoCo's own contact time constant (20 ms) instead of the tracking
#: worlds' 10 ms. Why: a flat-footed landing on a 10 ms contact rebounds (a 3 m/s touchdown
#: bounced the body back up at 0.8 m/s), where a foot's heel pad and sole give a little; the
#: thesis's ground was springs and dampers too (section 3.1.1)
ATHLETICS_WORLD = WorldConfig(contact_solref=(0.02, 1.0))


@dataclass(frozen=True)
class ContactModel:
    """An athletics contact model: MuJoCo's friction cone for every contact (``"pyramidal"``,
    its default, approximates Coulomb's circular cone by a pyramid; ``"elliptic"`` is the
    exact cone, same coefficient) and the sole boxes' torsional friction (m; 0: none,
    ``condim`` 3 as every other geom)."""

    cone: Literal["pyramidal", "elliptic"]
    sole_torsion: float = 0.0


#: a sole corner contact's torsional friction (m). MuJoCo's torsional coefficient is a length:
#: the largest torque about the contact normal is it times the normal force. A disc of radius
#: a under even pressure resists up to (2/3) mu a N; a corner contact standing for a heel or
#: forefoot pad of a ~3 cm radius at the sliding coefficient 1.0 gives 0.02 m
SOLE_TORSION = 0.02
#: the athletics contact models by name (:func:`athletics_world`, ``run(..., contact=)``,
#: ``run_maneuver(..., contact=)``, the CLI's and the benchmark's ``--contact``). Only the
#: default's figures are the measured tables' (docs/athletics.md, "The elliptic cone, opt-in")
CONTACT_MODELS: Mapping[str, ContactModel] = MappingProxyType({
    "pyramidal": ContactModel("pyramidal"),
    "elliptic": ContactModel("elliptic"),
    "elliptic+torsion": ContactModel("elliptic", SOLE_TORSION),
})  # fmt: skip
DEFAULT_CONTACT = "pyramidal"


def contact_model(name: str) -> ContactModel:
    """The contact model ``name`` (:data:`CONTACT_MODELS`)."""
    try:
        return CONTACT_MODELS[name]
    except (KeyError, TypeError):
        raise UnknownKeyError(
            f"unknown athletics contact model {name!r}; valid models are {list(CONTACT_MODELS)}"
        ) from None


#: where a backpack's mass sits relative to the chest's centre of mass (m, chest frame of the
#: neutral pose: 0.15 m behind the back)
BACKPACK_OFFSET = (-0.15, 0.0, 0.0)


def stand_angles(athlete: Athlete, leg: float = STANDING_LEG) -> F64:
    """``(15, 3)`` anatomical angles of standing with hip-to-ankle length ``leg`` (fraction of
    the straight leg): knees bent by the law of cosines, hips and ankles so the pelvis and
    feet are level."""
    angles = np.zeros((15, 3))
    kh = knee_for_length(athlete.thigh, athlete.shin, leg * (athlete.thigh + athlete.shin))
    for k, side in enumerate("lr"):
        angles[joint_index(f"{side}_knee"), 0] = kh[0, k]
        angles[joint_index(f"{side}_hip"), 0] = kh[1, k]
        angles[joint_index(f"{side}_ankle"), 0] = -(kh[0, k] + kh[1, k])
    return angles


def add_backpack(world: World, athlete: Athlete, mass: float, character: int = 0) -> None:
    """Add ``mass`` kg to the chest, :data:`BACKPACK_OFFSET` behind its centre of mass (a point
    mass, combined by the parallel-axis theorem), and refresh MuJoCo's derived constants."""
    if not (math.isfinite(mass) and mass >= 0):
        raise ConfigError(f"backpack mass must be >= 0 kg, got {mass!r}")
    if mass == 0:
        return
    m = world.model
    body = world.characters[character].body_id("chest")
    m0 = float(m.body_mass[body])
    c0 = m.body_ipos[body].copy()
    flat = np.zeros(9)
    mujoco.mju_quat2Mat(flat, m.body_iquat[body])
    rot = flat.reshape(3, 3)
    chest = SIM_BODIES.index("chest")
    p = c0 + quat_rotate(quat_conj(athlete.neutral[chest]), np.asarray(BACKPACK_OFFSET))
    c = (m0 * c0 + mass * p) / (m0 + mass)

    def shift(mm: float, x: F64) -> F64:
        return mm * (float(x @ x) * np.eye(3) - np.outer(x, x))

    inertia = rot @ np.diag(m.body_inertia[body]) @ rot.T + shift(m0, c0 - c) + shift(mass, p - c)
    evals, evecs = np.linalg.eigh(inertia)
    if np.linalg.det(evecs) < 0:
        evecs[:, 0] *= -1
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, evecs.reshape(-1))
    m.body_mass[body] = m0 + mass
    m.body_ipos[body] = c
    m.body_inertia[body] = evals
    m.body_iquat[body] = q
    mujoco.mj_setConst(m, world.data)


class Slope:
    """A floor that tilts, as a controller: over ``ramp`` seconds from level to ``angle`` rad,
    rising toward heading ``direction`` (rad; 0: the athlete faces uphill), about a line
    through ``pivot``. The floor is a plane, so turning its geom is the whole change."""

    def __init__(
        self, world: World, angle: float, direction: float = 0.0, ramp: float = 1.5,
        pivot: F64 | None = None, control_every: int = 8,
    ) -> None:  # fmt: skip
        if not (math.isfinite(angle) and math.isfinite(direction) and ramp >= 0):
            raise ConfigError("slope angle and direction must be finite, ramp >= 0")
        self.world = world
        self.angle = float(angle)
        self.direction = float(direction)
        self.ramp = float(ramp)
        self.pivot = np.zeros(3) if pivot is None else np.asarray(pivot, dtype=np.float64)
        self.control_every = control_every
        self.floor = int(world.model.geom("floor").id)
        self._scratch: mujoco.MjData | None = None

    def tilt(self, angle: float) -> None:
        """Turn the floor to ``angle`` now."""
        # rising toward the direction: a rotation by -angle about the horizontal axis
        # perpendicular to it (pitch in the frame turned to the direction)
        yaw = quat_from_yaw(self.direction)
        q = quat_mul(yaw, quat_mul(quat_from_euler([-angle, 0.0, 0.0], "YXZ"),
                                   quat_from_yaw(-self.direction)))  # fmt: skip
        m, d = self.world.model, self.world.data
        m.geom_quat[self.floor] = q
        m.geom_pos[self.floor] = self.pivot
        # MuJoCo places the world body's geoms in mj_setConst (at qpos0, in the data it is
        # given): run it on a scratch copy, then copy the floor's new pose over
        scratch = mujoco.MjData(m) if self._scratch is None else self._scratch
        self._scratch = scratch
        mujoco.mj_setConst(m, scratch)
        d.geom_xmat[self.floor] = scratch.geom_xmat[self.floor]
        d.geom_xpos[self.floor] = scratch.geom_xpos[self.floor]

    def reset(self, world: World) -> None:
        del world
        self.tilt(0.0 if self.ramp > 0 else self.angle)

    def control(self, world: World, t: float) -> None:
        del world
        if self.ramp > 0 and t <= self.ramp + 1e-9:
            s = min(t / self.ramp, 1.0)
            self.tilt(self.angle * s * s * (3.0 - 2.0 * s))


def shins_off_floor(world: World, character: int = 0) -> None:
    """The shins of ``character`` collide with nothing (see :func:`athletics_world`)."""
    m = world.model
    for side in "lr":
        body = world.characters[character].body_id(f"{side}_shin")
        geoms = np.flatnonzero(m.geom_bodyid == body)
        m.geom_contype[geoms] = 0
        m.geom_conaffinity[geoms] = 0


def athletics_world(
    athlete: Athlete, *, backpack: float = 0.0, contact: str = DEFAULT_CONTACT
) -> World:
    """A World holding ``athlete`` standing on level ground (:data:`ATHLETICS_WORLD`, its
    contacts as the :data:`CONTACT_MODELS` entry ``contact``). The shins do not collide with
    the floor: their capsules end at the ankle joint, a loaded sole sinks a little into the
    soft contact, and a shin touching the floor under a flat foot is a rigid stop that threw
    landing athletes back into the air (a real shin is well clear)."""
    model = contact_model(contact)
    world = World(athlete.character, replace(ATHLETICS_WORLD, cone=model.cone))
    if model.sole_torsion > 0:
        # condim 4 on the soles: a contact takes the larger condim and coefficients of its
        # two geoms, so the floor's contacts with the soles get the torsion
        soles = world.characters[0].sole_ids
        world.model.geom_condim[soles] = 4
        world.model.geom_friction[soles, 1] = model.sole_torsion
    shins_off_floor(world)
    add_backpack(world, athlete, backpack)
    world.set_pose(0, athlete.standing_qpos(stand_angles(athlete), clearance=0.0005))
    return world
