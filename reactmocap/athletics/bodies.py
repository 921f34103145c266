"""The athletes' bodies: the thesis's male and female (Appendix A listings) as ordinary
:class:`~reactmocap.sim.character.Character` objects, any mapped mocap skeleton, and the
anatomical frames the controllers set joint angles in (zero = standing upright facing +X, arms
down). Why a Character rather than the listing's own MuJoCo model: ``docs/athletics.md``."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.library.anthropometry import SEXES, listing_body_part
from reactmocap.library.bodyparts import BodyPartMap, map_body_parts
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import BVHLayout, Skeleton
from reactmocap.rotations import (
    EulerQuats,
    quat_conj,
    quat_from_euler,
    quat_from_yaw,
    quat_mul,
    quat_mul_rows,
    quat_mul_table,
    quat_normalize,
    quat_rotate,
    quat_to_euler,
)
from reactmocap.sim.bodies import BALL_JOINTS, SIM_BODIES, SIM_PARENTS
from reactmocap.sim.character import Character, SegmentInertia, build_character
from reactmocap.sim.reference_bodies import inertia_matrix, reference_listing

__all__ = [
    "BODIES",
    "EULER_ORDER",
    "Athlete",
    "athlete",
    "athlete_of",
    "joint_points",
    "segment_inertials",
    "thesis_character",
    "thesis_skeleton",
]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)
#: the thesis bodies by name; anything else given as a body is a BVH file
BODIES: tuple[str, ...] = SEXES
#: anatomical joint angles are intrinsic Euler angles in this order: pitch (about +Y, the
#: flexion axis of hips, knees, ankles and spine), then roll (+X), then yaw (+Z)
EULER_ORDER = "YXZ"

# (joint, parent joint, listing body whose inboard joint it is, or a point rule)
_JOINTS: tuple[tuple[str, str | None, str], ...] = (
    ("Hips", None, "hips"),
    ("Spine", "Hips", "CHEST3"),
    ("Chest", "Spine", "CHEST1"),
    ("Neck", "Chest", "HEAD"),
    ("Head", "Neck", "head"),
    ("LeftShoulder", "Chest", "CHESTL"),
    ("LeftArm", "LeftShoulder", "UARML"),
    ("LeftForeArm", "LeftArm", "LARML"),
    ("LeftHand", "LeftForeArm", "HANDL"),
    ("RightShoulder", "Chest", "CHESTR"),
    ("RightArm", "RightShoulder", "UARMR"),
    ("RightForeArm", "RightArm", "LARMR"),
    ("RightHand", "RightForeArm", "HANDR"),
    ("LeftUpLeg", "Hips", "ULEGL"),
    ("LeftLeg", "LeftUpLeg", "LLEGL"),
    ("LeftFoot", "LeftLeg", "FOOTL"),
    ("LeftToeBase", "LeftFoot", "TOEL"),
    ("RightUpLeg", "Hips", "ULEGR"),
    ("RightLeg", "RightUpLeg", "LLEGR"),
    ("RightFoot", "RightLeg", "FOOTR"),
    ("RightToeBase", "RightFoot", "TOER"),
)
_PARTS = {
    "pelvis": "Hips", "waist": "Spine", "chest": "Chest", "neck": "Neck", "head": "Head",
    "l_upper_arm": "LeftArm", "l_forearm": "LeftForeArm", "l_hand": "LeftHand",
    "r_upper_arm": "RightArm", "r_forearm": "RightForeArm", "r_hand": "RightHand",
    "l_thigh": "LeftUpLeg", "l_shin": "LeftLeg", "l_foot": "LeftFoot", "l_toe": "LeftToeBase",
    "r_thigh": "RightUpLeg", "r_shin": "RightLeg", "r_foot": "RightFoot", "r_toe": "RightToeBase",
}  # fmt: skip


def joint_points(sex: str) -> dict[str, F64]:
    """World position (reference pose) of every listing joint, keyed by its body's name."""
    return {
        b.name: np.add(b.com, b.body_to_joint)
        for b in reference_listing(sex)
        if b.parent is not None
    }


def thesis_skeleton(sex: str) -> tuple[Skeleton, BodyPartMap]:
    """A BVH skeleton of the thesis body at the listing's joint locations (reference pose: all
    rotations identity, Z up, facing +X), with its body-part map. The root sits between the
    hip joints; the head joint at the head's centre of mass; end sites at the top of the head,
    the finger tips and the toe tips (from the listing's segment extents)."""
    if sex not in BODIES:
        raise UnknownKeyError(f"unknown thesis body {sex!r}; valid bodies: {list(BODIES)}")
    pts = joint_points(sex)
    listing = {b.name: b for b in reference_listing(sex)}
    pts["hips"] = 0.5 * (pts["ULEGL"] + pts["ULEGR"])
    pts["head"] = np.asarray(listing["HEAD"].com)
    names = [j for j, _, _ in _JOINTS]
    parents = [-1 if p is None else names.index(p) for _, p, _ in _JOINTS]
    world = np.array([pts[src] for _, _, src in _JOINTS])
    offsets = np.array([world[k] - (world[p] if p >= 0 else 0.0) for k, p in enumerate(parents)])
    offsets[0] = 0.0
    height = {"male": 1.84, "female": 1.60}[sex]  # Tables 3.3/3.4 captions
    ends: dict[int, tuple[float, float, float]] = {
        names.index("Head"): (0.0, 0.0, height - float(world[names.index("Head"), 2])),
    }
    for side, s in (("Left", 1.0), ("Right", -1.0)):
        hand = names.index(f"{side}Hand")
        ends[hand] = (0.0, s * 0.18 * height / 1.84, 0.0)
        toe = names.index(f"{side}ToeBase")
        ends[toe] = (0.06 * height / 1.84, 0.0, 0.0)
    rot = ("Zrotation", "Xrotation", "Yrotation")
    chans = (("Xposition", "Yposition", "Zposition", *rot),) + (rot,) * (len(names) - 1)
    skel = Skeleton(tuple(names), np.array(parents), offsets, BVHLayout(chans, "m", "y", ends))
    parts = BodyPartMap(skel, {p: names.index(j) for p, j in _PARTS.items()})
    return skel, parts


def segment_inertials(sex: str) -> dict[str, SegmentInertia]:
    """Listing bodies merged into the 16 sim bodies (toes into feet, spine segments and clavicle
    bodies into waist and chest) with the parallel-axis theorem, world frame."""
    groups: dict[str, list] = {b: [] for b in SIM_BODIES}
    for body in reference_listing(sex):
        groups[listing_body_part(sex, body.name)].append(body)
    out = {}
    for part, bodies in groups.items():
        mass = sum(b.mass for b in bodies)
        com = sum(b.mass * np.asarray(b.com) for b in bodies) / mass
        inertia = np.zeros((3, 3))
        for b in bodies:
            d = np.asarray(b.com) - com
            inertia += inertia_matrix(b) + b.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
        c = (float(com[0]), float(com[1]), float(com[2]))
        rows = tuple((float(r[0]), float(r[1]), float(r[2])) for r in inertia)
        out[part] = SegmentInertia(float(mass), c, rows)
    return out


def thesis_character(sex: str) -> Character:
    """The thesis's ``"male"`` (97.84 kg) or ``"female"`` (53.30 kg) body as a 16-body
    Character: joints where the listing has them, every segment's mass and inertia from the
    listing (merged segments by the parallel-axis theorem), collision geometry from
    :func:`~reactmocap.sim.character.build_character` on the body's proportions."""
    skel, parts = thesis_skeleton(sex)
    pts = joint_points(sex)
    root = 0.5 * (pts["ULEGL"] + pts["ULEGR"])
    ref = Motion(skel, 30.0, root[None], np.tile([1.0, 0.0, 0.0, 0.0], (1, skel.num_joints, 1)))
    return build_character(skel, parts, reference=ref, inertials=segment_inertials(sex))


# ---------------------------------------------------------------------------------- athlete
#: the direction each sim body's defining axis takes in the neutral pose (anatomical frame):
#: trunk and head up, limbs down; feet: their sole normal up
_NEUTRAL_DIRECTION = {
    "pelvis": (0, 0, 1), "waist": (0, 0, 1), "chest": (0, 0, 1), "head": (0, 0, 1),
    "upper_arm": (0, 0, -1), "forearm": (0, 0, -1), "hand": (0, 0, -1),
    "thigh": (0, 0, -1), "shin": (0, 0, -1), "foot": (0, 0, 1),
}  # fmt: skip
#: a reference body whose axis is within this angle of neutral keeps its reference rotation
#: (the thesis bodies are neutral as modelled; a mocap T-pose's arms are 90 degrees off)
NEUTRAL_TOLERANCE = math.radians(30.0)


def _min_rotation(u: F64, v: F64) -> F64:
    """Shortest-arc quaternion taking unit ``u`` to unit ``v``."""
    w = 1.0 + float(u @ v)
    if w < 1e-9:  # opposite: any perpendicular axis
        axis = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
        return quat_normalize(np.r_[0.0, axis])
    return quat_normalize(np.r_[w, np.cross(u, v)])


@dataclass(eq=False)
class Athlete:
    """A character with the anatomical frames the athletic controllers use.

    Anatomical joint angles ``(15, 3)`` (``[pitch, roll, yaw]`` per ball joint in
    ``BALL_JOINTS`` order, radians, :data:`EULER_ORDER`) are rotations of each body relative to
    its parent in frames aligned with the world when the athlete stands upright facing +X.
    Signs (right-handed, Y to the left): hip pitch < 0 flexes the thigh forward, knee pitch > 0
    bends the knee, ankle pitch > 0 points the toes down, shoulder pitch < 0 raises the arm
    forward, spine pitch > 0 bends the trunk forward.

    Attributes:
        name: ``"male"``, ``"female"`` or the clip's name.
        character: the Character.
        neutral: ``(16, 4)`` world rotation of each body in the neutral pose.
        thigh, shin: ``(2,)`` hip-knee and knee-ankle lengths (m), left and right.
        hip_width: distance between the hip joints (m).
    """

    name: str
    character: Character
    neutral: F64
    thigh: F64
    shin: F64
    hip_width: float

    def __post_init__(self) -> None:
        n = self.neutral
        parent = n[SIM_PARENTS[1:]]
        bq = self.character.body_quat[1:]
        #: q_joint = joint_left * r * joint_right (r the anatomical rotation; see joint_quats)
        self.joint_left = quat_mul(quat_conj(bq), quat_conj(parent))
        self.joint_right = n[1:]
        self._right_table = quat_mul_table(np.array(self.joint_right))  # for joint_quats
        # joint_quats' buffers for the (15, 3) angles of the control ticks
        nj = len(self.joint_right)
        self._euler = EulerQuats(EULER_ORDER, nj)
        self._euler_shape = (nj, 3)
        self._products = np.empty((nj, 4, 4))
        self._table = np.empty((nj, 4, 4))

    @property
    def mass(self) -> float:
        return self.character.total_mass

    @property
    def leg_length(self) -> float:
        """Mean hip-to-ankle length with straight knees (m)."""
        return float(np.mean(self.thigh + self.shin))

    def joint_quats(self, angles: F64) -> F64:
        """``(15, 4)`` MuJoCo ball-joint quaternions of anatomical angles ``(15, 3)``."""
        if (isinstance(angles, np.ndarray) and angles.dtype == np.float64
                and angles.shape == self._euler_shape):  # fmt: skip
            # the same products into buffers (the control ticks: a fifth of the cost)
            work = self._products
            r = quat_mul_rows(self._euler(angles), self._right_table, work)
            return quat_mul_rows(self.joint_left, quat_mul_table(r, self._table), work)
        r = quat_mul_rows(quat_from_euler(angles, EULER_ORDER), self._right_table)
        return quat_mul_rows(self.joint_left, quat_mul_table(r))  # quat_mul's values, faster

    def joint_angles(self, quats: F64) -> F64:
        """Inverse of :meth:`joint_quats`."""
        r = quat_mul(
            quat_conj(self.joint_left), quat_mul(np.asarray(quats), quat_conj(self.joint_right))
        )
        return quat_to_euler(quat_normalize(r), EULER_ORDER)

    def root_quat(self, pitch: float = 0.0, yaw: float = 0.0) -> F64:
        """Pelvis world rotation for an anatomical pelvis pitch (forward > 0) and heading."""
        r = quat_mul(quat_from_yaw(yaw), quat_from_euler([pitch, 0.0, 0.0], EULER_ORDER))
        return quat_mul(r, self.neutral[0])

    def standing_qpos(self, angles: F64, pitch: float = 0.0, clearance: float = 0.0) -> F64:
        """``(67,)`` qpos of a pose with the lowest sole corner ``clearance`` m above z = 0 and
        the feet's midpoint over the origin."""
        model = self.character.model
        data = mujoco.MjData(model)
        q = np.zeros(model.nq)
        q[3:7] = self.root_quat(pitch)
        q[7:] = self.joint_quats(angles).reshape(-1)
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        corners = _box_corners(model, data, _sole_geoms(self.character))
        q[0] -= float(corners[..., 0].mean())
        q[1] -= float(corners[..., 1].mean())
        q[2] += clearance - float(corners[..., 2].min())
        return q

    def com_of(self, qpos: F64) -> F64:
        """World centre of mass ``(3,)`` of the whole body at ``qpos`` (a setup-time query:
        it makes its own MjData)."""
        model = self.character.model
        data = mujoco.MjData(model)
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        return data.subtree_com[1].copy()


def _sole_geoms(character: Character) -> NDArray[np.int64]:
    """Geom ids (in the character's own model) of the left and right sole boxes."""
    model = character.model
    names = {g.body: f"{g.body}_{k}" for k, g in enumerate(character.geoms)
             if g.kind == "box" and not g.patch}  # fmt: skip
    return np.array([model.geom(names[f]).id for f in ("l_foot", "r_foot")], dtype=np.int64)


def _box_corners(model: mujoco.MjModel, data: mujoco.MjData, geoms: NDArray[np.int64]) -> F64:
    signs = np.array([[x, y, -1.0] for x in (-1, 1) for y in (-1, 1)])
    half = model.geom_size[geoms]
    rot = data.geom_xmat[geoms].reshape(-1, 3, 3)
    local = signs[None] * half[:, None]
    return np.einsum("gij,gkj->gki", rot, local) + data.geom_xpos[geoms][:, None]


def _neutral_frames(character: Character, yaw: float) -> F64:
    """World rotation of every body in the neutral pose (see :class:`Athlete`)."""
    model = character.model
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0
    data.qpos[3:7] = quat_from_yaw(-yaw)
    mujoco.mj_kinematics(model, data)
    ids = [model.body(b).id for b in SIM_BODIES]
    rot = data.xquat[ids].copy()
    pos = data.xpos[ids]
    out = np.empty_like(rot)
    for i, b in enumerate(SIM_BODIES):
        kind = b[2:] if b[:2] in ("l_", "r_") else b
        want = np.asarray(_NEUTRAL_DIRECTION[kind], dtype=np.float64)
        if kind == "foot":
            sole = _sole_geoms(character)[0 if b == "l_foot" else 1]
            axis = data.geom_xmat[sole].reshape(3, 3)[:, 2]
        else:
            child = [k for k in range(len(SIM_BODIES)) if SIM_PARENTS[k] == i]
            tip = pos[child].mean(axis=0) if child else None
            if kind == "pelvis":  # pelvis: from the hips' midpoint up to the waist joint
                tip = pos[SIM_BODIES.index("waist")]
                base = 0.5 * (pos[SIM_BODIES.index("l_thigh")] + pos[SIM_BODIES.index("r_thigh")])
            else:
                base = pos[i]
            if tip is None:  # head, hands: along the body's main geom
                g = [k for k in range(model.ngeom) if model.geom_bodyid[k] == ids[i]]
                tip = data.geom_xpos[g].mean(axis=0)
            axis = tip - base
        axis = axis / np.linalg.norm(axis)
        if math.acos(float(np.clip(axis @ want, -1.0, 1.0))) > NEUTRAL_TOLERANCE:
            out[i] = quat_mul(_min_rotation(axis, want), rot[i])
        else:
            out[i] = rot[i]
    return out


def _athlete(name: str, character: Character) -> Athlete:
    p = character.body_pos
    idx = {b: i for i, b in enumerate(SIM_BODIES)}
    thigh = np.array([np.linalg.norm(p[idx[f"{s}_shin"]]) for s in "lr"])
    shin = np.array([np.linalg.norm(p[idx[f"{s}_foot"]]) for s in "lr"])
    hips = np.linalg.norm(p[idx["l_thigh"]] - p[idx["r_thigh"]])
    yaw = _reference_heading(character)
    return Athlete(name, character, _neutral_frames(character, yaw), thigh, shin, float(hips))


def _reference_heading(character: Character) -> float:
    """Heading of the reference pose from the hip axis (as ``library.placement.heading``)."""
    p = character.body_pos
    rot = character.body_quat[0]
    left = quat_rotate(rot, p[SIM_BODIES.index("l_thigh")] - p[SIM_BODIES.index("r_thigh")])
    return float(np.arctan2(-left[0], left[1]))


def athlete_of(character: Character, name: str = "character") -> Athlete:
    """The athlete (anatomical frames, leg lengths) of an already built Character."""
    return _athlete(name, character)


_CACHE: dict[str, Athlete] = {}


def athlete(body: str | Path | Motion) -> Athlete:
    """The athlete for ``body``: ``"male"`` or ``"female"`` (the thesis bodies), a BVH file or
    a Motion of any mapped skeleton (built on the skeleton's rest pose; 75 kg, the project's
    mass fractions)."""
    if isinstance(body, Motion):
        return _mocap_athlete(body.name or "clip", body.skeleton)
    key = str(body)
    if key in BODIES:
        if key not in _CACHE:
            _CACHE[key] = _athlete(key, thesis_character(key))
        return _CACHE[key]
    path = Path(key)
    if path.suffix.lower() != ".bvh":
        raise UnknownKeyError(
            f"unknown body {key!r}; valid bodies are {list(BODIES)} or a BVH file (CLIP.bvh)"
        )
    if not path.is_file():
        raise ConfigError(f"body file {key!r} does not exist")
    from reactmocap.library.bvh import read_bvh

    clip = read_bvh(path)
    return _mocap_athlete(path.stem, clip.skeleton)


def _mocap_athlete(name: str, skeleton: Skeleton) -> Athlete:
    """A mocap skeleton's athlete, built on its rest pose (a BVH rest pose stands with the legs
    straight down and the feet forward; a clip's frames are in a stance of their own)."""
    return _athlete(name, build_character(skeleton, map_body_parts(skeleton)))
