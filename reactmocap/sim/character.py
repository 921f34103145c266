"""The physics character: a 51-DOF MuJoCo body (free pelvis, 15 ball joints) built from any mapped
Skeleton, and the exact mapping between Motion frames and MuJoCo state: every body's frame is
the global frame of one skeleton joint in a reference pose, so joints that are not simulated are
folded in-between rotations and :meth:`Character.check_fk` can diagnose any disagreement.
Geometry follows human proportions scaled by leg length; segment masses follow
:data:`reactmocap.library.anthropometry.MASS_FRACTIONS`. Details: ``docs/design.md``."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import SimulationError, UnknownKeyError
from reactmocap.library.anthropometry import MASS_FRACTIONS, PART_DENSITY
from reactmocap.library.bodyparts import BodyPartMap, map_body_parts
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import Skeleton
from reactmocap.rotations import (
    quat_canonical,
    quat_conj,
    quat_from_matrix,
    quat_log,
    quat_mul,
    quat_normalize,
    quat_rotate,
)

__all__ = [
    "BALL_JOINTS",
    "BALL_PATCH_HALF_SIZE",
    "BODY_ALIASES",
    "SIM_BODIES",
    "PATCH_GEOM_GROUP",
    "Character",
    "build_character",
    "qvel_from_qpos",
]

F64 = NDArray[np.float64]
MassModel = Literal["table", "geometry"]

# (body = part, parent body, ball joint name); preorder, which is MuJoCo's body/joint order.
_TREE: tuple[tuple[str, str | None, str | None], ...] = (
    ("pelvis", None, None),
    ("waist", "pelvis", "waist"),
    ("chest", "waist", "back"),
    ("head", "chest", "neck"),
    ("l_upper_arm", "chest", "l_shoulder"),
    ("l_forearm", "l_upper_arm", "l_elbow"),
    ("l_hand", "l_forearm", "l_wrist"),
    ("r_upper_arm", "chest", "r_shoulder"),
    ("r_forearm", "r_upper_arm", "r_elbow"),
    ("r_hand", "r_forearm", "r_wrist"),
    ("l_thigh", "pelvis", "l_hip"),
    ("l_shin", "l_thigh", "l_knee"),
    ("l_foot", "l_shin", "l_ankle"),
    ("r_thigh", "pelvis", "r_hip"),
    ("r_shin", "r_thigh", "r_knee"),
    ("r_foot", "r_shin", "r_ankle"),
)
SIM_BODIES: tuple[str, ...] = tuple(b for b, _, _ in _TREE)
BALL_JOINTS: tuple[str, ...] = tuple(j for _, _, j in _TREE if j is not None)
BODY_ALIASES: Mapping[str, str] = {"abdomen": "waist", "thorax": "chest", "neck": "head"}
_PARENT = np.array([-1 if p is None else SIM_BODIES.index(p) for _, p, _ in _TREE])
#: parent body index of each of SIM_BODIES (-1 for the pelvis)
SIM_PARENTS = _PARENT

#: cone half-angle (rad) of each ball joint around its reference-pose rotation. MuJoCo ball
#: limits are cones, so these are coarse: they stop wild twists after hard impacts, they do not
#: model anatomy (a knee cone also allows hyperextension).
JOINT_RANGE: Mapping[str, float] = {
    "waist": 1.0, "back": 1.0, "neck": 1.3, "shoulder": 2.9, "elbow": 2.7, "wrist": 1.7,
    "hip": 2.4, "knee": 2.7, "ankle": 1.3,
}  # fmt: skip

# Human proportions (fractions of a 0.85 m hip-to-ankle leg, i.e. a 1.75 m adult).
_LEG_REF = 0.85
_RADIUS = {
    "pelvis": 0.095, "waist": 0.09, "chest": 0.105, "neck": 0.05, "head": 0.1,
    "upper_arm": 0.045, "forearm": 0.037, "hand": 0.03, "thigh": 0.075, "shin": 0.05,
}  # fmt: skip
_FOOT = {"heel": 0.06, "toe": 0.05, "half_width": 0.04, "half_height": 0.025}
_HAND_LEN = 0.10
#: half-size (m) of the ball-of-foot contact patch each foot carries switched off: a tracking
#: controller turns it on, and the foot box off, while the actor pivots on that foot (a box's
#: corners hold a yaw torque of mu N times half its width; a pivoting forefoot holds little)
BALL_PATCH_HALF_SIZE = 0.005
#: MuJoCo geom group of the patch: hidden by the default visualisation (groups 0-2)
PATCH_GEOM_GROUP = 3


def _kind(part: str) -> str:
    return part[2:] if part[:2] in ("l_", "r_") else part


def _target_fractions() -> dict[str, float]:
    """Mass fraction per sim body (the one table, over the bodies the character has)."""
    total = sum(MASS_FRACTIONS[b] for b in SIM_BODIES)
    return {b: MASS_FRACTIONS[b] / total for b in SIM_BODIES}


def _unit(v: F64) -> F64:
    n = float(np.linalg.norm(v))
    if n < 1e-9:
        raise SimulationError("degenerate geometry: zero-length axis while building the character")
    return v / n


def _perp(v: F64) -> F64:
    a = np.array([1.0, 0.0, 0.0]) if abs(v[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    return np.cross(v, a)


def qvel_from_qpos(q: F64, fps: float) -> F64:
    """``(T, 51)`` MuJoCo ``qvel`` of a ``(T, 67)`` qpos path sampled at ``fps`` (central
    differences, one-sided at the ends): root linear velocity in the world, root and ball
    angular velocities in their local frames, as ``mj_differentiatePos`` defines them."""
    q = np.asarray(q, dtype=np.float64)
    n = q.shape[0]
    if n < 2:
        return np.zeros((n, 6 + 3 * len(BALL_JOINTS)))
    lo = np.r_[0, np.arange(n - 1)]
    hi = np.r_[np.arange(1, n), n - 1]
    return _differentiate(q[lo], q[hi], (hi - lo) / fps)


def _differentiate(qa: F64, qb: F64, span: F64) -> F64:
    """qvel taking qpos rows ``qa`` to ``qb`` in ``span`` seconds each."""
    n = qa.shape[0]
    lin = (qb[:, :3] - qa[:, :3]) / span[:, None]
    rel = quat_mul(quat_conj(qa[:, 3:].reshape(n, -1, 4)), qb[:, 3:].reshape(n, -1, 4))
    ang = quat_log(rel) / span[:, None, None]
    return np.concatenate([lin, ang.reshape(n, -1)], axis=1)


@dataclass(frozen=True)
class _Geom:
    body: str
    kind: Literal["capsule", "sphere", "box"]
    size: tuple[float, ...]
    fromto: tuple[float, ...] | None = None  # capsule, body-local
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    #: a massless, hidden contact geom (see :data:`BALL_PATCH_HALF_SIZE`); compiled colliding
    #: (MuJoCo leaves geoms that cannot collide at compile time out of the body's collision
    #: tree for good), and switched off by the World
    patch: bool = False


@dataclass(eq=False)
class Character:
    """A built character: its MuJoCo spec, the skeleton mapping and the reference pose.

    Attributes:
        skeleton: the source skeleton (outputs are written on it).
        parts: body-part map of ``skeleton``.
        anchors: ``(16,)`` skeleton joint index whose frame each sim body carries.
        body_pos, body_quat: ``(16, 3)``, ``(16, 4)`` rest transform of each body relative to its
            parent body (the pelvis: relative to the world).
        ref_rotations, ref_translations, ref_root: the reference pose the frames were taken from
            (its non-simulated joints are the defaults when writing a Motion back).
        total_mass: kg.
    """

    skeleton: Skeleton
    parts: BodyPartMap
    anchors: NDArray[np.int64]
    body_pos: F64
    body_quat: F64
    ref_rotations: F64
    ref_translations: F64
    ref_root: F64
    total_mass: float
    mass_model: MassModel
    joint_limits: bool
    geoms: tuple[_Geom, ...]
    density_scale: dict[str, float]
    _model: mujoco.MjModel | None = field(default=None, repr=False)

    # ------------------------------------------------------------------ model
    def make_spec(self) -> mujoco.MjSpec:
        """A fresh MjSpec of this character alone (bodies, joints, geoms; no floor, no options)."""
        spec = mujoco.MjSpec()
        spec.compiler.degree = False
        dens = PART_DENSITY
        bodies: dict[str, mujoco.MjsBody] = {}
        for i, (name, parent, joint) in enumerate(_TREE):
            parent_body = spec.worldbody if parent is None else bodies[parent]
            body = parent_body.add_body(name=name, pos=self.body_pos[i], quat=self.body_quat[i])
            bodies[name] = body
            if joint is None:
                body.add_freejoint(name="root")
            else:
                j = body.add_joint(name=joint, type=mujoco.mjtJoint.mjJNT_BALL)
                if self.joint_limits:
                    j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
                    j.range = [0.0, JOINT_RANGE[_kind(joint)]]
        for k, g in enumerate(self.geoms):
            body = bodies[g.body]
            rho = dens[_kind(g.body)] * self.density_scale[g.body]
            size = list(g.size) + [0.0] * (3 - len(g.size))
            if g.kind == "capsule":
                body.add_geom(
                    name=f"{g.body}_{k}",
                    type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                    size=size,
                    fromto=list(g.fromto or ()),
                    density=rho,
                )
            elif g.patch:
                body.add_geom(
                    name=f"{g.body}_ball",
                    type=mujoco.mjtGeom.mjGEOM_BOX,
                    size=size,
                    pos=list(g.pos),
                    quat=list(g.quat),
                    density=0.0,
                    group=PATCH_GEOM_GROUP,
                )
            else:
                body.add_geom(
                    name=f"{g.body}_{k}",
                    type=mujoco.mjtGeom.mjGEOM_SPHERE
                    if g.kind == "sphere"
                    else mujoco.mjtGeom.mjGEOM_BOX,
                    size=size,
                    pos=list(g.pos),
                    quat=list(g.quat),
                    density=rho,
                )
        return spec

    @property
    def model(self) -> mujoco.MjModel:
        """The character compiled alone (no floor); cached."""
        if self._model is None:
            self._model = self.make_spec().compile()
        return self._model

    def segment_masses(self) -> dict[str, float]:
        """Mass (kg) of each sim body, keyed by body part name."""
        m = self.model
        return {b: float(m.body_mass[m.body(b).id]) for b in SIM_BODIES}

    # ------------------------------------------------------------------ Motion -> state
    def _check_motion(self, motion: Motion) -> None:
        if not motion.skeleton.same_structure(self.skeleton):
            raise SimulationError(
                f"motion {motion.name!r} is on a different skeleton than the character "
                f"({motion.num_joints} joints vs {self.skeleton.num_joints}); build the "
                "character from this motion's skeleton"
            )

    def qpos_from_motion(
        self, motion: Motion, frames: Sequence[int] | NDArray | None = None
    ) -> F64:
        """``(T, 67)`` MuJoCo qpos (free joint then 15 ball quaternions) of motion frames."""
        self._check_motion(motion)
        idx = np.arange(motion.num_frames) if frames is None else np.asarray(frames, int)
        sub = motion if frames is None else _take_frames(motion, idx)
        pos, rot = sub.forward_kinematics()
        g = rot[:, self.anchors]  # (T, 16, 4) global rotation of each body
        q = np.empty((idx.size, 7 + 4 * len(BALL_JOINTS)))
        q[:, :3] = pos[:, self.anchors[0]]
        q[:, 3:7] = quat_canonical(g[:, 0])
        parent_g = g[:, _PARENT[1:]]
        rel = quat_mul(quat_conj(self.body_quat[1:]), quat_mul(quat_conj(parent_g), g[:, 1:]))
        q[:, 7:] = quat_canonical(quat_normalize(rel)).reshape(idx.size, -1)
        return q

    def qvel_from_motion(
        self, motion: Motion, frames: Sequence[int] | NDArray | None = None
    ) -> F64:
        """``(T, 51)`` MuJoCo qvel of motion frames (:func:`qvel_from_qpos` of the frames and
        their neighbours)."""
        self._check_motion(motion)
        n = motion.num_frames
        idx = np.arange(n) if frames is None else np.asarray(frames, int)
        if n < 2:
            return np.zeros((idx.size, 6 + 3 * len(BALL_JOINTS)))
        if frames is None:
            return qvel_from_qpos(self.qpos_from_motion(motion), motion.fps)
        lo = np.clip(idx - 1, 0, n - 1)
        hi = np.clip(idx + 1, 0, n - 1)
        q_lo, q_hi = self.qpos_from_motion(motion, lo), self.qpos_from_motion(motion, hi)
        return _differentiate(q_lo, q_hi, (hi - lo) / motion.fps)

    # ------------------------------------------------------------------ state -> Motion
    def body_transforms_from_qpos(self, qpos: F64) -> tuple[F64, F64]:
        """World positions ``(T, 16, 3)`` and rotations ``(T, 16, 4)`` of the bodies for qpos
        rows (pure numpy, same result as mj_kinematics)."""
        qpos = np.atleast_2d(np.asarray(qpos, dtype=np.float64))
        t = qpos.shape[0]
        pos = np.empty((t, len(SIM_BODIES), 3))
        rot = np.empty((t, len(SIM_BODIES), 4))
        pos[:, 0] = qpos[:, :3]
        rot[:, 0] = quat_normalize(qpos[:, 3:7])
        balls = quat_normalize(qpos[:, 7:].reshape(t, -1, 4))
        for b in range(1, len(SIM_BODIES)):
            p = _PARENT[b]
            pos[:, b] = pos[:, p] + quat_rotate(rot[:, p], self.body_pos[b])
            rot[:, b] = quat_mul(rot[:, p], quat_mul(self.body_quat[b], balls[:, b - 1]))
        return pos, rot

    def motion_from_body_transforms(
        self,
        xpos: F64,
        xquat: F64,
        fps: float,
        reference: Motion | None = None,
        times: F64 | None = None,
        name: str = "simulated",
    ) -> Motion:
        """A Motion on the original skeleton from simulated body transforms.

        ``xpos (T, 16, 3)`` and ``xquat (T, 16, 4)`` are world transforms of the sim bodies.
        Joints that are not simulated (dummy root, clavicles, toes, fingers, ...) take their
        local rotation from ``reference`` sampled at ``times`` (seconds; default ``k / fps``),
        or from the character's reference pose. Simulated bodies are reproduced exactly: each
        anchor joint's local rotation is solved against its (possibly mocap-driven) parent.
        The pelvis position goes into the pelvis joint's own translation if it has position
        channels, else into the root position.
        """
        xpos = np.asarray(xpos, dtype=np.float64)
        xquat = quat_normalize(np.asarray(xquat, dtype=np.float64))
        t = xpos.shape[0]
        skel = self.skeleton
        j = skel.num_joints
        if reference is not None:
            self._check_motion(reference)
            tt = np.arange(t) / fps if times is None else np.asarray(times, dtype=np.float64)
            ref = reference.sample(tt)
            local = np.array(ref.rotations)
            trans = np.array(ref.local_translations())
            root = np.array(ref.root_positions)
            has_tr = reference.translations is not None
        else:
            local = np.broadcast_to(self.ref_rotations, (t, j, 4)).copy()
            trans = np.broadcast_to(self.ref_translations, (t, j, 3)).copy()
            root = np.broadcast_to(self.ref_root, (t, 3)).copy()
            has_tr = bool(np.any(np.abs(self.ref_translations - skel.offsets) > 1e-12))
        body_of = {int(a): b for b, a in enumerate(self.anchors)}
        pelvis = int(self.anchors[0])
        grot = np.empty((t, j, 4))
        gpos = np.empty((t, j, 3))
        # Joints above the pelvis (a dummy root): mocap rotations, positioned afterwards.
        for k in range(j):
            p = int(skel.parents[k])
            if k in body_of:
                glob = xquat[:, body_of[k]]
                local[:, k] = glob if p < 0 else quat_mul(quat_conj(grot[:, p]), glob)
                grot[:, k] = glob
            else:
                grot[:, k] = local[:, k] if p < 0 else quat_mul(grot[:, p], local[:, k])
            if p < 0:
                gpos[:, k] = root
            else:
                gpos[:, k] = gpos[:, p] + quat_rotate(grot[:, p], trans[:, k])
            if k == pelvis:
                target = xpos[:, 0]
                if p >= 0 and has_tr and skel.layout.has_position(k):
                    trans[:, k] = quat_rotate(quat_conj(grot[:, p]), target - gpos[:, p])
                    gpos[:, k] = target
                else:  # move the whole chain above (or the root itself)
                    root = root + (target - gpos[:, k])
                    gpos[:, : k + 1] += (target - gpos[:, k])[:, None]
        local = quat_canonical(local)
        return Motion(
            skel,
            fps,
            root,
            local,
            trans if has_tr else None,
            name=name,
        )

    def motion_from_qpos(
        self,
        qpos: F64,
        fps: float,
        reference: Motion | None = None,
        times: F64 | None = None,
        name: str = "simulated",
    ) -> Motion:
        """:meth:`motion_from_body_transforms` of qpos rows."""
        pos, rot = self.body_transforms_from_qpos(qpos)
        return self.motion_from_body_transforms(pos, rot, fps, reference, times, name)

    # ------------------------------------------------------------------ checks
    def fk_errors(self, motion: Motion, frame: int = 0) -> F64:
        """``(16,)`` distance (m) between each MuJoCo body origin (mj_kinematics) and the
        library FK position of its anchor joint, for one frame."""
        self._check_motion(motion)
        m = self.model
        d = mujoco.MjData(m)
        d.qpos[:] = self.qpos_from_motion(motion, [frame])[0]
        mujoco.mj_kinematics(m, d)
        ids = [m.body(b).id for b in SIM_BODIES]
        lib = _take_frames(motion, np.array([frame])).global_positions()[0, self.anchors]
        return np.linalg.norm(d.xpos[ids] - lib, axis=1)

    def check_fk(self, motion: Motion, frame: int = 0, tol: float = 1e-3) -> float:
        """Raise :class:`SimulationError` with a diagnosis unless every body agrees with the
        library's FK within ``tol`` metres; returns the largest error."""
        err = self.fk_errors(motion, frame)
        worst = int(np.argmax(err))
        if err[worst] <= tol:
            return float(err[worst])
        body = SIM_BODIES[worst]
        raise SimulationError(
            f"MuJoCo and library FK disagree on frame {frame} of {motion.name!r}: body {body!r} "
            f"(joint {self.skeleton.names[self.anchors[worst]]!r}) is {err[worst] * 1000:.1f} mm "
            f"off (tolerance {tol * 1000:.1f} mm). Likely cause: "
            f"{self._diagnose(motion, frame, worst)}"
        )

    def _diagnose(self, motion: Motion, frame: int, body: int) -> str:
        skel = self.skeleton
        first_bad = body
        # the first body down the chain that is off explains the rest
        errs = self.fk_errors(motion, frame)
        chain = []
        b = body
        while b >= 0:
            chain.append(b)
            b = int(_PARENT[b])
        for b in reversed(chain):
            if errs[b] > 1e-3:
                first_bad = b
                break
        a = int(self.anchors[first_bad])
        pa = int(self.anchors[_PARENT[first_bad]]) if first_bad > 0 else -1
        between = [k for k in skel.chain(a)[:-1] if k not in skel.chain(pa)] if pa >= 0 else []
        causes = []
        tr = motion.local_translations()[frame]
        for k in [*between, a]:
            if np.linalg.norm(tr[k] - self.ref_translations[k]) > 1e-6:
                causes.append(
                    f"joint {skel.names[k]!r} has a translation that differs from "
                    "the reference pose (animated bone length)"
                )
        for k in between:
            ang = float(
                np.linalg.norm(
                    quat_log(quat_mul(quat_conj(self.ref_rotations[k]), motion.rotations[frame, k]))
                )
            )
            if ang > 1e-4:
                causes.append(
                    f"non-simulated joint {skel.names[k]!r} is rotated "
                    f"{np.degrees(ang):.1f} deg away from the character's reference "
                    "pose (it is folded into a rigid body); build the character "
                    "from a reference frame closer to this one"
                )
        if not causes:
            causes.append(
                "the motion's skeleton offsets differ from the character's, or the "
                "qpos conversion is inconsistent (a bug)"
            )
        return f"the chain first goes wrong at body {SIM_BODIES[first_bad]!r}: " + "; ".join(causes)

    # ------------------------------------------------------------------ lookups
    @staticmethod
    def body_name(name: str) -> str:
        """Canonical sim body name of ``name`` (a body part or alias); raises UnknownKeyError."""
        key = BODY_ALIASES.get(name, name)
        if key not in SIM_BODIES:
            raise UnknownKeyError(
                f"unknown body {name!r}; valid bodies are {list(SIM_BODIES)} "
                f"(aliases {dict(BODY_ALIASES)})"
            )
        return key


def _take_frames(motion: Motion, idx: NDArray[np.int64]) -> Motion:
    tr = None if motion.translations is None else motion.translations[idx]
    return motion.replace(
        root_positions=motion.root_positions[idx], rotations=motion.rotations[idx], translations=tr
    )


# ---------------------------------------------------------------------------------- building
def build_character(
    skeleton: Skeleton | Motion,
    parts: BodyPartMap | None = None,
    *,
    total_mass: float = 75.0,
    reference: Motion | None = None,
    frame: int = 0,
    mass_model: MassModel = "table",
    joint_limits: bool = True,
) -> Character:
    """Build the 51-DOF character of a skeleton.

    Args:
        skeleton: the skeleton, or a Motion (then it is also the ``reference``).
        parts: its body-part map (mapped automatically if omitted).
        total_mass: kg.
        reference: motion whose frame ``frame`` fixes the body frames (and so the pose of every
            folded joint); the rest pose (identity rotations) when omitted. The lowest ankle and
            ball heights over the whole reference place the foot soles on the ground.
        mass_model: ``"table"`` or ``"geometry"`` (see the module docstring).
        joint_limits: MuJoCo cone limits around the reference pose (:data:`JOINT_RANGE`).
    """
    if isinstance(skeleton, Motion):
        reference = skeleton if reference is None else reference
        skeleton = skeleton.skeleton
    if not np.isfinite(total_mass) or total_mass <= 0:
        raise SimulationError(f"total_mass must be a positive number of kg, got {total_mass!r}")
    if mass_model not in ("table", "geometry"):
        raise SimulationError(f"mass_model must be 'table' or 'geometry', got {mass_model!r}")
    parts = map_body_parts(skeleton) if parts is None else parts
    anchor_part = {b: b for b in SIM_BODIES}
    if "neck" in parts.joints:
        anchor_part["head"] = "neck"  # the head body pivots at the neck base
    anchors = np.array([parts.joint_of(anchor_part[b]) for b in SIM_BODIES], dtype=np.int64)
    if len(set(anchors.tolist())) != len(anchors):
        raise SimulationError(f"two sim bodies map to the same skeleton joint: {anchors.tolist()}")
    for b in range(1, len(SIM_BODIES)):
        if int(anchors[_PARENT[b]]) not in skeleton.chain(int(anchors[b])):
            raise SimulationError(
                f"joint {skeleton.names[anchors[b]]!r} ({SIM_BODIES[b]}) is not below "
                f"{skeleton.names[anchors[_PARENT[b]]]!r} ({SIM_BODIES[_PARENT[b]]}) "
                "in the skeleton"
            )

    if reference is None:
        j = skeleton.num_joints
        ref = Motion(skeleton, 30.0, np.zeros((1, 3)), np.tile([1.0, 0, 0, 0], (1, j, 1)))
        frame = 0
    else:
        if not reference.skeleton.same_structure(skeleton):
            raise SimulationError("reference motion is on a different skeleton")
        if not 0 <= frame < reference.num_frames:
            raise SimulationError(f"reference frame {frame} outside 0..{reference.num_frames - 1}")
        ref = reference
    one = _take_frames(ref, np.array([frame]))
    gpos_all, grot_all = one.forward_kinematics()
    gpos, grot = gpos_all[0], grot_all[0]
    P = gpos[anchors]
    G = grot[anchors]

    body_quat = np.empty((len(SIM_BODIES), 4))
    body_pos = np.empty((len(SIM_BODIES), 3))
    body_quat[0], body_pos[0] = G[0], P[0]
    for b in range(1, len(SIM_BODIES)):
        p = _PARENT[b]
        body_quat[b] = quat_normalize(quat_mul(quat_conj(G[p]), G[b]))
        body_pos[b] = quat_rotate(quat_conj(G[p]), P[b] - P[p])

    geoms = _make_geoms(skeleton, parts, anchors, ref, frame, P, G)
    char = Character(
        skeleton=skeleton,
        parts=parts,
        anchors=anchors,
        body_pos=body_pos,
        body_quat=quat_canonical(body_quat),
        ref_rotations=np.array(one.rotations[0]),
        ref_translations=np.array(one.local_translations()[0]),
        ref_root=np.array(one.root_positions[0]),
        total_mass=float(total_mass),
        mass_model=mass_model,
        joint_limits=joint_limits,
        geoms=geoms,
        density_scale=dict.fromkeys(SIM_BODIES, 1.0),
    )
    geo = char.segment_masses()
    if mass_model == "table":
        frac = _target_fractions()
        scale = {b: frac[b] * total_mass / geo[b] for b in SIM_BODIES}
    else:
        k = total_mass / sum(geo.values())
        scale = dict.fromkeys(SIM_BODIES, k)
    char.density_scale = scale
    char._model = None
    return char


def _make_geoms(
    skel: Skeleton,
    parts: BodyPartMap,
    anchors: NDArray[np.int64],
    ref: Motion,
    frame: int,
    P: F64,
    G: F64,
) -> tuple[_Geom, ...]:
    """Collision/mass geometry, computed in the reference pose's world frame and converted to
    each body's local frame."""
    idx = {b: i for i, b in enumerate(SIM_BODIES)}

    def at(b: str) -> F64:
        return P[idx[b]]

    leg = 0.5 * sum(
        np.linalg.norm(at(f"{s}_thigh") - at(f"{s}_shin"))
        + np.linalg.norm(at(f"{s}_shin") - at(f"{s}_foot"))
        for s in "lr"
    )
    s = float(leg) / _LEG_REF
    if not 0.3 < s < 3.0:
        raise SimulationError(
            f"implausible leg length {leg:.3f} m (hip to ankle); is the skeleton in metres?"
        )
    r = {k: v * s for k, v in _RADIUS.items()}

    def local(b: str, x: F64) -> F64:
        return quat_rotate(quat_conj(G[idx[b]]), x - P[idx[b]])

    def local_dir(b: str, v: F64) -> F64:
        return quat_rotate(quat_conj(G[idx[b]]), v)

    def capsule(b: str, a: F64, c: F64, radius: float) -> _Geom:
        la, lc = local(b, a), local(b, c)
        if np.linalg.norm(lc - la) < 1e-4:  # degenerate bone: a sphere
            return _Geom(b, "sphere", (radius,), pos=tuple(la))
        return _Geom(b, "capsule", (radius,), fromto=(*la, *lc))

    out: list[_Geom] = []
    # trunk: lateral capsules
    hip_l, hip_r = at("l_thigh"), at("r_thigh")
    hip_mid = 0.5 * (hip_l + hip_r)
    lat_p = _unit(hip_l - hip_r)
    up_p = at("waist") - hip_mid
    up_p = _unit(up_p - lat_p * float(lat_p @ up_p))
    half = max(0.5 * float(np.linalg.norm(hip_l - hip_r)) - 0.01 * s, 0.03 * s)
    c = hip_mid + up_p * 0.045 * s
    out.append(capsule("pelvis", c - lat_p * half, c + lat_p * half, r["pelvis"]))

    sh_l, sh_r = at("l_upper_arm"), at("r_upper_arm")
    lat_c = _unit(sh_l - sh_r)
    lat_w = _unit(lat_p + lat_c)
    c = 0.5 * (at("waist") + at("chest"))
    out.append(capsule("waist", c - lat_w * 0.06 * s, c + lat_w * 0.06 * s, r["waist"]))

    neck_base = at("head")  # the head body's anchor (neck joint, or head if no neck)
    c = at("chest") + 0.55 * (neck_base - at("chest"))
    half = max(0.5 * float(np.linalg.norm(sh_l - sh_r)) - 0.6 * r["chest"], 0.04 * s)
    out.append(capsule("chest", c - lat_c * half, c + lat_c * half, r["chest"]))

    # head (+ neck)
    head_j = parts.joint_of("head")
    head_p = ref.global_positions()[frame, head_j]
    ends = skel.layout.end_sites
    up_chest = _unit(neck_base - at("chest"))
    if np.linalg.norm(head_p - neck_base) > 1e-3:
        out.append(capsule("head", neck_base, head_p, r["neck"]))
        hdir = _unit(head_p - neck_base)
    else:
        hdir = up_chest
    grot_head = ref.forward_kinematics()[1][frame, head_j]
    end = np.asarray(ends.get(head_j, (0.0, 0.0, 0.0)), dtype=float)
    if np.linalg.norm(end) > 0.05 * s:
        centre = head_p + 0.5 * quat_rotate(grot_head, end)
    else:
        centre = head_p + hdir * 0.09 * s
    out.append(_Geom("head", "sphere", (r["head"],), pos=tuple(local("head", centre))))

    gpos_ref, grot_ref = ref.forward_kinematics()
    for side in "lr":
        # arms
        out.append(
            capsule(
                f"{side}_upper_arm", at(f"{side}_upper_arm"), at(f"{side}_forearm"), r["upper_arm"]
            )
        )
        out.append(
            capsule(f"{side}_forearm", at(f"{side}_forearm"), at(f"{side}_hand"), r["forearm"])
        )
        hand_j = int(anchors[idx[f"{side}_hand"]])
        hend = np.asarray(ends.get(hand_j, (0.0, 0.0, 0.0)), dtype=float)
        wrist = at(f"{side}_hand")
        if np.linalg.norm(hend) > 0.05 * s:
            hdir_w = _unit(quat_rotate(grot_ref[frame, hand_j], hend))
            length = min(0.6 * float(np.linalg.norm(hend)), 0.14 * s)
        else:  # straight continuation of the forearm
            hdir_w = _unit(wrist - at(f"{side}_forearm"))
            length = _HAND_LEN * s
        out.append(
            capsule(f"{side}_hand", wrist + hdir_w * 0.01 * s, wrist + hdir_w * length, r["hand"])
        )
        # legs
        out.append(capsule(f"{side}_thigh", at(f"{side}_thigh"), at(f"{side}_shin"), r["thigh"]))
        out.append(capsule(f"{side}_shin", at(f"{side}_shin"), at(f"{side}_foot"), r["shin"]))
        box, ball_x = _foot_box(
            skel,
            parts,
            anchors,
            ref,
            frame,
            side,
            s,
            G[idx[f"{side}_foot"]],
            gpos_ref,
            grot_ref,
        )
        out.append(box)
        out.append(_ball_patch(box, ball_x))
    return tuple(out)


def _ball_patch(box: _Geom, ball_x: float) -> _Geom:
    """The ball-of-foot contact patch: a small cube, aligned with the foot box, whose bottom
    face lies in the sole plane under the ball (``ball_x`` along the box's x axis from its
    centre), in the foot's local frame: flat on the floor like the box it stands in for."""
    hz, r = box.size[2], BALL_PATCH_HALF_SIZE
    local = np.array([ball_x, 0.0, -hz + r])
    pos = np.asarray(box.pos) + quat_rotate(np.asarray(box.quat), local)
    return _Geom(box.body, "box", (r, r, r), pos=tuple(pos), quat=box.quat, patch=True)


def _foot_box(
    skel: Skeleton,
    parts: BodyPartMap,
    anchors: NDArray[np.int64],
    ref: Motion,
    frame: int,
    side: str,
    s: float,
    g_foot: F64,
    gpos: F64,
    grot: F64,
) -> tuple[_Geom, float]:
    """The foot box in the foot's local frame, and the ball's (toe joint's) offset from the
    box centre along the box's x axis.

    The sole is placed from the clip: the ankle's lowest height over the reference motion is its
    height above the sole, and the ball (toe joint) sits its own lowest height above it; the
    box's roll comes from the frame where the ankle is lowest (most likely flat on the floor).
    """
    b = f"{side}_foot"
    fj = int(anchors[SIM_BODIES.index(b)])
    toe = parts.joints.get(f"{side}_toe")
    ankle_z = gpos[:, fj, 2]
    t_low = int(np.argmin(ankle_z))
    h_a = (
        float(np.clip(ankle_z.min(), 0.05 * s, 0.16 * s))
        if ref.num_frames > 1 or ankle_z.min() > 0.02
        else 0.08 * s
    )
    # ankle -> ball, in the foot's local frame (rigid: toes are folded at their reference pose)
    if toe is not None:
        f = quat_rotate(quat_conj(grot[frame, fj]), gpos[frame, toe] - gpos[frame, fj])
        h_b = (
            float(np.clip(gpos[:, toe, 2].min(), 0.0, h_a - 0.02 * s))
            if ref.num_frames > 1
            else 0.02 * s
        )
    else:
        end = np.asarray(skel.layout.end_sites.get(fj, (0.0, 0.0, 0.0)), dtype=float)
        if np.linalg.norm(end) > 0.05 * s:
            f = end
        else:  # forward of the pelvis, expressed in the foot frame
            fwd = np.cross(
                gpos[frame, parts.joint_of("l_thigh")] - gpos[frame, parts.joint_of("r_thigh")],
                [0.0, 0.0, 1.0],
            )
            f = quat_rotate(quat_conj(grot[frame, fj]), _unit(-fwd) * 0.13 * s)
        h_b = 0.02 * s
    # world up at the flattest frame, in foot-local coordinates
    u0 = quat_rotate(quat_conj(grot[t_low, fj]), np.array([0.0, 0.0, 1.0]))
    lateral = np.cross(f, u0)
    if np.linalg.norm(lateral) < 1e-6:
        lateral = _perp(f)
    lateral = _unit(lateral)
    fhat = _unit(f - lateral * float(lateral @ f))
    n = np.cross(lateral, fhat)
    if n @ u0 < 0:
        n = -n
    flen = float(np.linalg.norm(f))
    k = float(np.clip((h_a - h_b) / max(flen, 1e-6), 0.0, 0.8))
    up = np.sqrt(1.0 - k * k) * n - k * fhat  # sole normal: the ball is (h_a - h_b) below
    fwd = _unit(fhat - up * float(up @ fhat))
    lat = np.cross(up, fwd)
    x0 = -_FOOT["heel"] * s
    x1 = float(f @ fwd) + _FOOT["toe"] * s
    hz = _FOOT["half_height"] * s
    centre = fwd * 0.5 * (x0 + x1) + up * (-h_a + hz)
    quat = quat_from_matrix(np.stack([fwd, lat, up], axis=1))
    del g_foot
    box = _Geom(
        b,
        "box",
        (0.5 * (x1 - x0), _FOOT["half_width"] * s, hz),
        pos=tuple(centre),
        quat=tuple(quat),
    )
    return box, float(f @ fwd) - 0.5 * (x0 + x1)
