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
    quat_log,
    quat_mul,
    quat_normalize,
    quat_rotate,
    quat_to_matrix,
)
from reactmocap.sim.bodies import (
    BALL_JOINTS,
    BODY_ALIASES,
    JOINT_RANGE,
    SIM_BODIES,
    SIM_PARENTS,
    TREE,
)
from reactmocap.sim.geometry import BALL_PATCH_HALF_SIZE, PATCH_GEOM_GROUP, GeomSpec, make_geoms

__all__ = [
    "BALL_JOINTS",
    "BALL_PATCH_HALF_SIZE",
    "BODY_ALIASES",
    "SIM_BODIES",
    "SIM_PARENTS",
    "PATCH_GEOM_GROUP",
    "Character",
    "SegmentInertia",
    "build_character",
    "qvel_between",
    "qvel_from_qpos",
]

F64 = NDArray[np.float64]
MassModel = Literal["table", "geometry"]


#: where a virtual chest starts on a single spine joint: this fraction of the way to the neck
VIRTUAL_CHEST = 0.45


def _kind(part: str) -> str:
    return part[2:] if part[:2] in ("l_", "r_") else part


def _target_fractions() -> dict[str, float]:
    """Mass fraction per sim body (the one table, over the bodies the character has)."""
    total = sum(MASS_FRACTIONS[b] for b in SIM_BODIES)
    return {b: MASS_FRACTIONS[b] / total for b in SIM_BODIES}


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
    return qvel_between(q[lo], q[hi], (hi - lo) / fps)


def qvel_between(qa: F64, qb: F64, span: F64) -> F64:
    """``(N, 51)`` the constant qvel taking qpos rows ``qa`` ``(N, 67)`` to ``qb`` in ``span``
    ``(N,)`` seconds each (MuJoCo's ``mj_differentiatePos``)."""
    n = qa.shape[0]
    lin = (qb[:, :3] - qa[:, :3]) / span[:, None]
    rel = quat_mul(quat_conj(qa[:, 3:].reshape(n, -1, 4)), qb[:, 3:].reshape(n, -1, 4))
    ang = quat_log(rel) / span[:, None, None]
    return np.concatenate([lin, ang.reshape(n, -1)], axis=1)


@dataclass(frozen=True)
class SegmentInertia:
    """Explicit mass properties of one sim body, in the world frame of the reference pose (as
    anthropometric tables and the thesis's SD/FAST listings print them): ``mass`` (kg), ``com``
    ``(3,)`` (m) and ``inertia`` ``(3, 3)`` about the COM (kg m^2)."""

    mass: float
    com: tuple[float, float, float]
    inertia: tuple[tuple[float, float, float], ...]


@dataclass(eq=False)
class Character:
    """A built character: its MuJoCo spec, the skeleton mapping and the reference pose.

    Attributes:
        skeleton: the source skeleton (outputs are written on it).
        parts: body-part map of ``skeleton``.
        anchors: ``(16,)`` skeleton joint index whose frame each sim body carries (the waist
            and chest share one on a skeleton with a single spine joint).
        body_pos, body_quat: ``(16, 3)``, ``(16, 4)`` rest transform of each body relative to its
            parent body (the pelvis: relative to the world).
        ref_rotations, ref_translations, ref_root: the reference pose the frames were taken from
            (its non-simulated joints are the defaults when writing a Motion back).
        total_mass: kg.
    """

    skeleton: Skeleton
    parts: BodyPartMap
    anchors: NDArray[np.int64]
    #: ``(16, 3)`` each body's origin in its anchor joint's frame: zero but for a virtual chest
    anchor_offsets: F64
    body_pos: F64
    body_quat: F64
    ref_rotations: F64
    ref_translations: F64
    ref_root: F64
    total_mass: float
    mass_model: MassModel
    joint_limits: bool
    geoms: tuple[GeomSpec, ...]
    density_scale: dict[str, float]
    _model: mujoco.MjModel | None = field(default=None, repr=False)
    #: explicit mass, COM (body frame) and full inertia ``(ixx, iyy, izz, ixy, ixz, iyz)`` per
    #: body (see :func:`build_character`'s ``inertials``); None: mass from the geoms
    inertials: dict[str, tuple[float, tuple[float, ...], tuple[float, ...]]] | None = None

    # ------------------------------------------------------------------ model
    def make_spec(self) -> mujoco.MjSpec:
        """A fresh MjSpec of this character alone (bodies, joints, geoms; no floor, no options)."""
        spec = mujoco.MjSpec()
        spec.compiler.degree = False
        dens = PART_DENSITY
        bodies: dict[str, mujoco.MjsBody] = {}
        for i, (name, parent, joint) in enumerate(TREE):
            parent_body = spec.worldbody if parent is None else bodies[parent]
            body = parent_body.add_body(name=name, pos=self.body_pos[i], quat=self.body_quat[i])
            bodies[name] = body
            if self.inertials is not None:
                mass, ipos, full = self.inertials[name]
                body.mass = mass
                body.ipos = list(ipos)
                body.fullinertia = list(full)
                body.explicitinertial = True
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
        parent_g = g[:, SIM_PARENTS[1:]]
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
        return qvel_between(q_lo, q_hi, (hi - lo) / motion.fps)

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
            p = SIM_PARENTS[b]
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
        pos, rot = _take_frames(motion, np.array([frame])).forward_kinematics()
        lib = pos[0, self.anchors] + quat_rotate(rot[0, self.anchors], self.anchor_offsets)
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
            b = int(SIM_PARENTS[b])
        for b in reversed(chain):
            if errs[b] > 1e-3:
                first_bad = b
                break
        a = int(self.anchors[first_bad])
        pa = int(self.anchors[SIM_PARENTS[first_bad]]) if first_bad > 0 else -1
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
    inertials: Mapping[str, SegmentInertia] | None = None,
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
        inertials: explicit mass properties for every sim body (e.g. the thesis's listing, see
            ``reactmocap.athletics.bodies``), in the reference pose's world frame; they replace
            the geoms' mass (``total_mass`` and ``mass_model`` are then unused) and the geoms
            only collide.
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
    waist, chest = SIM_BODIES.index("waist"), SIM_BODIES.index("chest")
    # one spine joint: the waist and chest share it; the chest body then starts part-way up
    # the spine (a virtual joint the mocap holds straight)
    shared = anchors[waist] == anchors[chest]
    rest = np.delete(anchors, chest) if shared else anchors
    if len(set(rest.tolist())) != len(rest):
        raise SimulationError(f"two sim bodies map to the same skeleton joint: {anchors.tolist()}")
    for b in range(1, len(SIM_BODIES)):
        if int(anchors[SIM_PARENTS[b]]) not in skeleton.chain(int(anchors[b])):
            raise SimulationError(
                f"joint {skeleton.names[anchors[b]]!r} ({SIM_BODIES[b]}) is not below "
                f"{skeleton.names[anchors[SIM_PARENTS[b]]]!r} ({SIM_BODIES[SIM_PARENTS[b]]}) "
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
    anchor_offsets = np.zeros((len(SIM_BODIES), 3))
    if shared:
        up = P[SIM_BODIES.index("head")] - P[chest]
        P[chest] = P[chest] + VIRTUAL_CHEST * up
        anchor_offsets[chest] = quat_rotate(quat_conj(G[chest]), VIRTUAL_CHEST * up)

    body_quat = np.empty((len(SIM_BODIES), 4))
    body_pos = np.empty((len(SIM_BODIES), 3))
    body_quat[0], body_pos[0] = G[0], P[0]
    for b in range(1, len(SIM_BODIES)):
        p = SIM_PARENTS[b]
        body_quat[b] = quat_normalize(quat_mul(quat_conj(G[p]), G[b]))
        body_pos[b] = quat_rotate(quat_conj(G[p]), P[b] - P[p])

    geoms = make_geoms(skeleton, parts, anchors, ref, frame, P, G)
    char = Character(
        skeleton=skeleton,
        parts=parts,
        anchors=anchors,
        anchor_offsets=anchor_offsets,
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
    if inertials is not None:
        char.inertials = _body_inertials(inertials, P, G)
        char.total_mass = float(sum(v.mass for v in inertials.values()))
    char._model = None
    return char


def _body_inertials(
    given: Mapping[str, SegmentInertia], P: F64, G: F64
) -> dict[str, tuple[float, tuple[float, ...], tuple[float, ...]]]:
    """World-frame segment inertials -> each body's frame (COM offset, full inertia)."""
    missing = [b for b in SIM_BODIES if b not in given]
    if missing:
        raise SimulationError(f"inertials lack bodies {missing}")
    out = {}
    for i, b in enumerate(SIM_BODIES):
        seg = given[b]
        inertia = np.asarray(seg.inertia, dtype=np.float64)
        if not (np.isfinite(seg.mass) and seg.mass > 0) or inertia.shape != (3, 3):
            raise SimulationError(f"body {b!r}: mass must be > 0 and inertia 3x3")
        rot = quat_to_matrix(G[i])  # body -> world
        com = rot.T @ (np.asarray(seg.com, dtype=np.float64) - P[i])
        local = rot.T @ inertia @ rot
        full = (local[0, 0], local[1, 1], local[2, 2], local[0, 1], local[0, 2], local[1, 2])
        out[b] = (float(seg.mass), tuple(float(x) for x in com), tuple(float(x) for x in full))
    return out
