"""Cloth driven by the runner (Hodgins et al. 1995, "Secondary motions": sweatpants driven by
the simulated runner): loose trousers as MuJoCo flex cloth (``flexcomp``, one tube per leg
sewn to the pelvis at the waist, inextensible edges), in a model of their own where the runner's
bodies are copies of its collision geoms, set at every cloth step to where the runner's
bodies are and how fast they move (so the contacts see them move); before each step, cloth
vertices found inside a body capsule are moved out along its radius and stopped from moving
further in (the contacts alone let a fast limb drag the cloth into itself). The cloth
collides with them and drapes and swings; by default nothing acts back on the runner (the
paper's one-way coupling), and with ``feedback`` the cloth's contact forces are applied to
the runner's bodies (one tick late).
Why a model of its own: ``docs/athletics.md``."""

from __future__ import annotations

import math
import time
from pathlib import Path

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, ReactMocapError, SimulationError
from reactmocap.rotations import cross_rows, quat_exp, quat_mul, quat_normalize, quat_to_matrix
from reactmocap.sim.bodies import SIM_BODIES
from reactmocap.sim.world import World

__all__ = ["CLOTHES", "Cloth", "ClothSpec", "render_cloth_video"]

F64 = NDArray[np.float64]


class ClothSpec:
    """A garment's make: tube rings and points per ring, slack over the limb's radius (m),
    total mass (kg), the cloth's thickness (collision radius of its vertices, m), the cloth
    model's time step (s) and where the hem is (0 the waist, 1 the knee, 2 the ankle)."""

    def __init__(
        self, rings: int = 7, around: int = 7, slack: float = 0.05, mass: float = 0.4,
        thickness: float = 0.006, timestep: float = 0.008, hem: float = 1.6,
    ) -> None:  # fmt: skip
        if rings < 3 or around < 4:
            raise ConfigError("a cloth tube needs at least 3 rings of 4 points")
        for name, v in (("slack", slack), ("mass", mass), ("thickness", thickness),
                        ("timestep", timestep), ("hem", hem)):  # fmt: skip
            if not (math.isfinite(v) and v > 0):
                raise ConfigError(f"cloth {name} must be > 0, got {v!r}")
        self.rings, self.around, self.slack, self.mass = rings, around, slack, mass
        #: the cloth model's solver: PGS, 3 iterations (with CG at 15 the triangles near the
        #: knee cut into the thigh at 3 m/s, 9% of the frames over 1 cm; PGS costs about the
        #: same and holds them out: docs/athletics.md)
        self.solver = "PGS"
        self.iterations = 3
        #: the cloth-body contacts' time constant (s): under MuJoCo's safe minimum of two
        #: steps (its ``refsafe`` check is off in the cloth model), so a fast limb is stopped
        #: within a step
        self.contact_time = 0.006
        #: the cloth-body contacts' margin (m): they act from this far out, so a limb
        #: swinging into the cloth meets it before the cloth is inside (0 before 2026-12-02,
        #: 13:30 UTC: the deepest contact 1.09 cm at 3 m/s; docs/athletics.md)
        self.contact_margin = 0.002
        #: CG's line-search iterations (MuJoCo's default 50; where ``solver`` is CG)
        self.ls_iterations = 5
        #: stretchy (sweatpants): the edges are soft equality constraints of this time
        #: constant (s, at least two cloth steps), with damping
        self.stretch = 0.015
        self.stretch_damping = 0.001
        self.thickness, self.timestep, self.hem = thickness, timestep, hem
        #: passes of the vertex projection out of the body's capsules (0: the contacts and
        #: the tether only; with the PGS solver the projection no longer changed the
        #: penetration and took a fifth of the cloth's time)
        self.project = 0
        #: the projection also stops a moved vertex moving into the body (its velocity
        #: along the surface normal is raised to the body surface's)
        self.project_velocity = True
        #: the head and arms collide with the cloth (by default they are only measured
        #: against it: the trousers meet the legs and the trunk)
        self.collide_arms = False
        #: how far a free vertex may go from where it was made on the leg (m; 0: anywhere)
        self.tether = 0.05
        #: how far outside the thigh's capsule the tether keeps the homes of the rings
        #: carried by both the thigh and the shin (m; 0: where the blend puts them, which is
        #: up to 1.7 cm inside the thigh when the knee bends)
        self.knee_clearance = 0.012


#: barycentric points of a triangle where the drawn surface's depth is sampled
_SURFACE_SAMPLES = np.array(
    [
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
        [1 / 3, 1 / 3, 1 / 3],
        [2 / 3, 1 / 6, 1 / 6],
        [1 / 6, 2 / 3, 1 / 6],
        [1 / 6, 1 / 6, 2 / 3],
    ]
)
_CAPSULE, _SPHERE = int(mujoco.mjtGeom.mjGEOM_CAPSULE), int(mujoco.mjtGeom.mjGEOM_SPHERE)
#: collision bits of the copies of the runner's bodies in the cloth model: each leg's own
#: (thigh, shin, foot), the trunk's, and the head's and arms' (``_LOOSE``: measured against
#: the cloth, and collided with it only with ``ClothSpec.collide_arms``)
_BITS = {"l_": 4, "r_": 8}
_TRUNK, _LOOSE = 2, 32
#: MuJoCo's warnings of a state gone bad (it then resets the cloth's model)
_BAD = np.array([mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL,
                 mujoco.mjtWarning.mjWARN_BADQACC], dtype=np.intp)  # fmt: skip


def _body_bits(name: str) -> int:
    if name == "pelvis":  # the waistband is sewn to it
        return 0
    if name.endswith(("thigh", "shin", "foot")):
        return _BITS[name[:2]]
    return _TRUNK if name in ("waist", "chest") else _LOOSE


#: the garments by name: ``pants`` (loose trousers, 7 rings of 7 points, hem 60% of the way
#: down the shin; 9 rings of 8 before 2026-12-02: 20% dearer for no less penetration),
#: ``pants-light`` (the same with 6 points around instead of 7: cheaper, coarser) and
#: ``shorts`` (hem above the knee)
CLOTHES: dict[str, ClothSpec] = {
    "pants": ClothSpec(),
    "pants-light": ClothSpec(rings=7, around=6),
    "shorts": ClothSpec(rings=6, around=8, hem=0.85),
}


def _geom_xml(m: mujoco.MjModel, g: int, bits: int) -> str:
    kind = {int(mujoco.mjtGeom.mjGEOM_CAPSULE): "capsule", int(mujoco.mjtGeom.mjGEOM_BOX): "box",
            int(mujoco.mjtGeom.mjGEOM_SPHERE): "sphere",
            int(mujoco.mjtGeom.mjGEOM_ELLIPSOID): "ellipsoid",
            int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder"}.get(int(m.geom_type[g]))  # fmt: skip
    if kind is None:
        return ""
    size = " ".join(f"{x:.5f}" for x in m.geom_size[g][: {"sphere": 1, "capsule": 2,
                                                          "cylinder": 2}.get(kind, 3)])  # fmt: skip
    pos = " ".join(f"{x:.5f}" for x in m.geom_pos[g])
    quat = " ".join(f"{x:.6f}" for x in m.geom_quat[g])

    def geom(kind: str, rgba: str) -> str:
        return (f'<geom type="{kind}" size="{size}" pos="{pos}" quat="{quat}" contype="{bits}" '
                f'conaffinity="0" density="0" rgba="{rgba}"/>')  # fmt: skip

    xml = geom(kind, "0.35 0.55 0.85 1")
    if kind == "capsule":
        # an invisible cylinder twin: MuJoCo 4.0.0's capsule-triangle test only finds a
        # capsule's end over a triangle or a triangle's corner in the capsule, so a limb
        # lying across a triangle (corners outside) makes no contact; the cylinder goes
        # through the general convex test, which finds it (the capsule keeps the ends)
        xml += geom("cylinder", "0 0 0 0")
    return xml


class Cloth:
    """A garment on character ``character`` of ``world``, as an engine controller: every
    ``control_every`` steps (a multiple of the runner's tick near the cloth's time step) it
    steps the cloth over that time with the copies of the character's bodies carried along
    at their velocities, after moving the cloth's vertices out of the body's capsules.

    Attributes (after a rollout): ``penetration_max`` and ``penetration_mean`` (m, the
    deepest overlap of cloth and body over the run, and its mean over ticks with contact),
    ``finite`` (the cloth's state stayed finite), ``frames`` ``(F, V, 3)`` vertex positions
    and ``frame_bodies`` ``(F, 16, 7)`` the body poses at ``frame_times``.
    """

    def __init__(
        self, world: World, kind: str | ClothSpec = "pants", *, feedback: bool = False,
        character: int = 0, control_every: int = 8, record_fps: float = 30.0,
    ) -> None:  # fmt: skip
        if isinstance(kind, str):
            if kind not in CLOTHES:
                raise ConfigError(f"unknown cloth {kind!r}; valid clothes are {sorted(CLOTHES)}")
            spec = CLOTHES[kind]
        else:
            spec = kind
        if not (isinstance(control_every, int) and control_every >= 1):
            raise ConfigError(f"control_every must be an int >= 1, got {control_every!r}")
        self.world = world
        self.spec = spec
        self.feedback = bool(feedback)
        self.character = character
        # the cloth steps once per its time step: every so many of the runner's ticks
        self.control_every = control_every * max(
            1, round(spec.timestep / (control_every * world.timestep))
        )
        self.record_fps = float(record_fps)
        self.wc = world.characters[character]
        self._roots = world.model.body_rootid[self.wc.body_ids]
        self.model: mujoco.MjModel | None = None
        self.data: mujoco.MjData | None = None
        self._reset_record()

    def _reset_record(self) -> None:
        self.penetration_max = 0.0
        self._pen_sum = 0.0
        self._pen_n = 0
        self._ticks = 0
        self._over_1cm = 0
        self.surface_max = 0.0
        self._surface: list[float] = []
        self.penetration_mean = 0.0
        self.finite = True
        self.frames: list[F64] = []
        self.frame_bodies: list[F64] = []
        self.frame_times: list[float] = []
        self.wall_s = 0.0
        self.cpu_s = 0.0
        self._next_frame = 0.0
        # the forces on the body's parts applied over the last step, and the next step's
        # (two buffers that swap roles every step)
        self._applied = np.zeros((len(SIM_BODIES), 6))
        self._force = np.zeros((len(SIM_BODIES), 6))

    # ------------------------------------------------------------------ building
    def _tube(self, side: str) -> F64:
        """``(rings, around, 3)`` world points of one trouser leg around the leg's current
        pose: rings from the waistband down the thigh and, for a hem below the knee, the
        shin; radius the limb's plus slack. The ring at the knee lies in the plane halving
        the knee's bend (it stays clear of both segments' capsules)."""
        m, d = self.world.model, self.world.data
        pre = self.wc.prefix
        hip = d.xanchor[m.joint(pre + f"{side}_hip").id]
        knee = d.xanchor[m.joint(pre + f"{side}_knee").id]
        ankle = d.xanchor[m.joint(pre + f"{side}_ankle").id]

        def radius(body: str) -> float:
            b = self.wc.body_id(f"{side}_{body}")
            g = np.flatnonzero(m.geom_bodyid == b)
            return float(m.geom_size[g, 0].max()) if g.size else 0.06

        r_thigh, r_shin = radius("thigh"), radius("shin")
        top = d.xpos[self.wc.body_id("pelvis")]
        # the waistband: a little above the hip joint, toward the body's middle
        start = hip + np.array([0.0, 0.0, 0.06]) + 0.2 * (top - hip) * np.array([1.0, 1.0, 0.0])
        up = (knee - start) / np.linalg.norm(knee - start)
        down = (ankle - knee) / np.linalg.norm(ankle - knee)
        hem = self.spec.hem  # 0 waist, 1 knee, 2 ankle
        fwd = d.xmat[self.wc.body_ids[0]].reshape(3, 3)[:, 0]
        ang = 2 * np.pi * np.arange(self.spec.around) / self.spec.around
        pts = []
        for u in np.linspace(0.0, hem, self.spec.rings):
            if u < 1.0:
                c = start + u * (knee - start)
                axis = up
                r = r_thigh + self.spec.slack * (1.3 if u < 0.2 else 1.0)
                if u > 0.8:  # toward the knee the ring turns into the bend's halving plane
                    w = (u - 0.8) / 0.2
                    axis = (1 - 0.5 * w) * up + 0.5 * w * down
            else:
                c = knee + (u - 1.0) * (ankle - knee)
                axis = down
                r = max(r_shin, r_thigh * (2.0 - u)) + self.spec.slack * (1.0 + 0.4 * (u - 1.0))
                if u < 1.2:
                    w = (1.2 - u) / 0.2
                    axis = (1 - 0.5 * w) * down + 0.5 * w * up
            axis = axis / np.linalg.norm(axis)
            e1 = fwd - axis * float(fwd @ axis)
            e1 /= np.linalg.norm(e1)
            e2 = np.cross(axis, e1)
            pts.append(c + r * (np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2))
        return np.array(pts)

    def _build(self) -> None:
        m, d = self.world.model, self.world.data
        wc = self.wc
        patches = set(wc.patch_ids.tolist())
        bodies = []
        for i, b in enumerate(wc.body_ids):
            own = [int(g) for g in np.flatnonzero(m.geom_bodyid == b) if int(g) not in patches]
            bits = _body_bits(SIM_BODIES[i])
            bodies.append((i, "".join(_geom_xml(m, g, bits) for g in own)))
        sp = self.spec
        ring = sp.around
        flexes = []
        # the body parts each trouser leg meets (the contacts' and the projection's)
        self._affinity: list[int] = []
        for side in ("l", "r"):
            pts = self._tube(side).reshape(-1, 3)
            # each trouser leg meets its own leg and the trunk (and the head and arms with
            # ``collide_arms``; they are measured against it either way); the two legs of the
            # trousers do not squeeze between the thighs (there is no crotch), and the
            # waistband is sewn to the pelvis (carried by it), so the pelvis is left out
            affinity = _BITS[side + "_"] | _TRUNK | (_LOOSE if sp.collide_arms else 0)
            self._affinity.append(affinity)
            tris = []
            for j in range(sp.rings - 1):
                for i in range(ring):
                    a, b = j * ring + i, j * ring + (i + 1) % ring
                    tris += [(a, b, a + ring), (b, b + ring, a + ring)]
            flexes.append(
                f'<flexcomp name="{side}_leg" type="direct" dim="2" radius="{sp.thickness}" '
                f'mass="{0.5 * sp.mass}" rgba="0.2 0.2 0.25 1" '
                f'point="{" ".join(f"{x:.5f}" for x in pts.ravel())}" '
                f'element="{" ".join(str(x) for x in np.ravel(tris))}">'
                f'<edge equality="true" solref="{max(sp.stretch, 2 * sp.timestep)} 1" '
                f'damping="{sp.stretch_damping}"/>'
                f'<contact contype="0" conaffinity="{affinity}" selfcollide="none" '
                f'solref="{sp.contact_time} 1" solimp="0.99 0.999 0.001" '
                f'margin="{sp.contact_margin}"/></flexcomp>'
            )
        parts = []
        hit = np.bitwise_or.reduce(self._affinity)
        # the copies the cloth collides with move by free joints (the contacts see their
        # velocities); the others (the pelvis, and the head and arms unless collided) are
        # mocap bodies: no dofs in the cloth's mass matrix and constraint Jacobian
        self._moving = np.array([bool(_body_bits(n) & hit) for n in SIM_BODIES])
        for i, geoms in bodies:
            pos = " ".join(map(str, d.xpos[wc.body_ids[i]]))
            quat = " ".join(map(str, d.xquat[wc.body_ids[i]]))
            if not self._moving[i]:
                parts.append(f'<body name="b{i}" pos="{pos}" quat="{quat}" mocap="true">'
                             f"{geoms}</body>")  # fmt: skip
                continue
            # heavy and weightless: the cloth barely moves it, and it is set each step
            parts.append(f'<body name="b{i}" pos="{pos}" quat="{quat}" gravcomp="1"><freejoint/>'
                         '<inertial pos="0 0 0" mass="1000" diaginertia="10 10 10"/>'
                         f"{geoms}</body>")  # fmt: skip
        # multiccd off: its extra contacts per capsule/cylinder-triangle pair changed no
        # figure of a 10 s run and cost about 5% of the cloth's time (2026-12-02)
        xml = (
            f'<mujoco><option timestep="{sp.timestep}" solver="{sp.solver}" iterations="{sp.iterations}" '
            f'ls_iterations="{sp.ls_iterations}" '
            'integrator="implicitfast" gravity="0 0 -9.81"><flag refsafe="disable" multiccd="disable"/></option>'
            '<visual><global offwidth="640" offheight="480"/></visual>'
            '<worldbody><light pos="0 0 6" dir="0 0 -1" directional="true"/>'
            '<geom name="floor" type="plane" size="0 0 0.05" rgba="0.82 0.84 0.86 1" '
            'contype="16" conaffinity="0"/>' + "".join(parts + flexes) + "</worldbody></mujoco>"
        )
        try:
            self.model = mujoco.MjModel.from_xml_string(xml)
        except ValueError as exc:
            raise SimulationError(f"MuJoCo could not compile the cloth: {exc}") from exc
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)
        m, d = self.model, self.data
        copies = np.array([m.body(f"b{i}").id for i in range(len(SIM_BODIES))])
        self._copies = copies
        self._mocap = np.flatnonzero(~self._moving)
        self._free_parts = np.flatnonzero(self._moving)
        joints = m.body_jntadr[copies[self._free_parts]]
        # the free copies' qpos and qvel (first in the model, in order): views the steps write
        nfree = len(joints)
        if not (np.array_equal(m.jnt_qposadr[joints], 7 * np.arange(nfree))
                and np.array_equal(m.jnt_dofadr[joints], 6 * np.arange(nfree))
                and np.array_equal(m.body_mocapid[copies[self._mocap]],
                                   np.arange(len(self._mocap)))):  # fmt: skip
            raise SimulationError("the cloth model's body copies are not laid out as expected")
        self._qbody = d.qpos[: 7 * nfree].reshape(nfree, 7)
        self._vbody = d.qvel[: 6 * nfree].reshape(nfree, 6)
        mb = self.model.geom_bodyid
        ids = {int(self.model.body(f"b{i}").id): i for i in range(len(SIM_BODIES))}
        self._geom_part = np.array([ids.get(int(b), -1) for b in mb])
        self._collider_setup()

    def _tether_setup(self, free: NDArray[np.intp], flex: NDArray[np.intp]) -> None:
        """Where each free vertex was made, carried by the pelvis, thigh and shin copies
        (blended near the hip and the knee by its ring's place down the leg)."""
        m, d = self.model, self.data
        assert m is not None and d is not None
        ring = (free - m.flex_vertadr[flex]) // self.spec.around
        u = np.linspace(0.0, self.spec.hem, self.spec.rings)[ring]
        w_pelvis = np.clip((0.4 - u) / 0.4, 0.0, 1.0)
        w_shin = np.clip((u - 0.8) / 0.4, 0.0, 1.0)
        weight = np.column_stack([w_pelvis, 1.0 - w_pelvis - w_shin, w_shin])
        sides = np.array(["l", "r"])[flex]
        parts = np.zeros((len(free), 3), dtype=np.intp)
        for j, name in ((1, "thigh"), (2, "shin")):
            parts[:, j] = [SIM_BODIES.index(f"{sd}_{name}") for sd in sides]
        b = np.array([m.body(f"b{i}").id for i in range(len(SIM_BODIES))])[parts]
        x = d.flexvert_xpos[free]
        local = np.einsum("vjki,vjk->vji", d.xmat[b].reshape(*b.shape, 3, 3),
                          x[:, None] - d.xpos[b])  # fmt: skip
        # home = sum_j w_j (R_pj local_j + pos_pj), one product with the stacked bodies'
        # transposed rotations and positions (``_stack``): a row of weighted local points
        # per body and the weights
        nb = len(SIM_BODIES)
        mat = np.zeros((len(free), 4 * nb))
        rows = np.arange(len(free))
        for j in range(3):
            p = parts[:, j]
            for i in range(3):
                np.add.at(mat, (rows, 3 * p + i), weight[:, j] * local[:, j, i])
            np.add.at(mat, (rows, 3 * nb + p), weight[:, j])
        self._tmat = mat
        self._stack = np.zeros((4 * nb, 3))
        self._home = np.zeros((len(free), 3))
        self._off = np.zeros((len(free), 3))
        self._scale = np.zeros(len(free))
        # the knee's rings (carried by both the thigh and the shin): their blended homes sink
        # into the back of the thigh when the knee bends, so they are moved out of its capsule
        knee = np.flatnonzero((w_shin > 0) & (w_shin < 1))
        thigh = parts[knee, 1]
        caps = np.flatnonzero((m.geom_type == _CAPSULE) & (self._geom_part >= 0))
        cap = caps[np.searchsorted(self._geom_part[caps], thigh)]
        if not np.array_equal(self._geom_part[cap], thigh):
            raise SimulationError("a thigh of the cloth model has no capsule")
        mat = np.zeros((len(cap), 9))
        for i, g in enumerate(cap):
            mujoco.mju_quat2Mat(mat[i], m.geom_quat[g])
        self._knee, self._knee_part = knee, thigh
        self._knee_pos, self._knee_axis = m.geom_pos[cap].copy(), mat[:, 2::3].copy()
        self._knee_half = m.geom_size[cap, 1].copy()
        self._knee_radius = m.geom_size[cap, 0] + self.spec.knee_clearance

    def _tether(self, x: F64, pos: F64, rot: F64) -> None:
        """Keep each free vertex within ``spec.tether`` of where it was made on the leg
        (NvCloth's "max distance" constraint): a loose tube cannot then fall across the limb
        it hangs around, which neither the contacts nor the projection undo."""
        nb = len(rot)
        self._stack[: 3 * nb].reshape(nb, 3, 3)[:] = rot.transpose(0, 2, 1)
        self._stack[3 * nb :] = pos
        home = np.matmul(self._tmat, self._stack, out=self._home)
        if self.spec.knee_clearance > 0:
            # the knee rings' homes out of the thigh's capsule, along its radius
            r, k = rot[self._knee_part], self._knee
            rel = home[k] - np.einsum("gij,gj->gi", r, self._knee_pos) - pos[self._knee_part]
            ax = np.einsum("gij,gj->gi", r, self._knee_axis)
            s = np.clip(np.einsum("gi,gi->g", rel, ax), -self._knee_half, self._knee_half)
            rel -= s[:, None] * ax
            dist = np.sqrt(np.einsum("gi,gi->g", rel, rel))
            home[k] += (
                rel * (np.maximum(self._knee_radius - dist, 0.0) / np.maximum(dist, 1e-9))[:, None]
            )
        off = np.subtract(x, home, out=self._off)
        # each offset scaled to the tether's length where it is longer (by 1 elsewhere)
        scale = np.einsum("vi,vi->v", off, off, out=self._scale)
        np.maximum(scale, self.spec.tether**2, out=scale)
        np.sqrt(scale, out=scale)
        np.divide(self.spec.tether, scale, out=scale)
        np.multiply(off, scale[:, None], out=off)
        np.add(home, off, out=x)

    def _collider_setup(self) -> None:
        """What the vertex projection needs: the vertices' slide-joint addresses and rest
        positions (world), the waistband's place on the pelvis copy, the capsules (and the
        head's sphere, a capsule of no length) in their bodies' frames, and which of them each
        vertex's trouser leg collides with."""
        m, d = self.model, self.data
        assert m is not None and d is not None
        b0 = int(m.body("b0").id)
        affinity = np.array(self._affinity)
        hit = np.bitwise_or.reduce(affinity) | _LOOSE
        kinds = np.isin(m.geom_type, (_CAPSULE, _SPHERE))
        caps = np.flatnonzero((self._geom_part >= 0) & (m.geom_contype & hit > 0) & kinds)
        axes = np.zeros((len(caps), 3))
        for i, g in enumerate(caps):
            mat = np.zeros(9)
            mujoco.mju_quat2Mat(mat, m.geom_quat[g])
            axes[i] = mat.reshape(3, 3)[:, 2]
        body = m.flex_vertbodyid
        free = np.flatnonzero(m.body_jntnum[body] == 3)
        body = body[free]
        # the vertices are particles in the world (not children of the pelvis copy: coupled
        # to its free joint, every vertex's rows of the mass matrix and the constraint
        # Jacobian carried its 6 dofs: MuJoCo's step was about 1.3x dearer in a run)
        if len(free) != m.nflexvert or not (m.body_parentid[body] == 0).all():
            raise SimulationError("the cloth's vertices are expected to be free in the world")
        flex = np.searchsorted(m.flex_vertadr, free, side="right") - 1
        # the waistband (each tube's first ring) is sewn to the pelvis: carried by its copy
        self._pin = np.flatnonzero(free - m.flex_vertadr[flex] < self.spec.around)
        r0 = d.xmat[b0].reshape(3, 3)
        self._pin_local = (d.flexvert_xpos[free[self._pin]] - d.xpos[b0]) @ r0
        self._vq = m.jnt_qposadr[m.body_jntadr[body]][:, None] + np.arange(3)
        self._tether_setup(free, flex)
        self._vd = m.jnt_dofadr[m.body_jntadr[body]][:, None] + np.arange(3)
        self._vall = np.arange(len(free))
        self._vrest = m.body_pos[body].copy()
        # the vertices' qpos and qvel (after the free copies', in order): views
        q0, v0 = 7 * len(self._free_parts), 6 * len(self._free_parts)
        if not (np.array_equal(self._vq.ravel(), q0 + np.arange(self._vq.size))
                and np.array_equal(self._vd.ravel(), v0 + np.arange(self._vd.size))):  # fmt: skip
            raise SimulationError("the cloth's vertices are not laid out as expected")
        self._xq = d.qpos[q0 : q0 + self._vq.size].reshape(-1, 3)
        self._xv = d.qvel[v0 : v0 + self._vd.size].reshape(-1, 3)
        self._x = np.zeros_like(self._vrest)
        self._vmask = (m.geom_contype[caps][None] & affinity[flex][:, None]) > 0
        self._vmask[self._pin] = False  # the waistband is never projected
        self._pin_rest = self._vrest[self._pin]
        self._spin = np.zeros((3, 3))
        self._sew_frame = np.zeros((3, 6))
        self._arm = np.zeros((len(self._pin), 6))
        self._cpart = self._geom_part[caps]
        self._cpos = m.geom_pos[caps].copy()
        self._caxis = axes
        self._chalf = np.where(m.geom_type[caps] == _CAPSULE, m.geom_size[caps, 1], 0.0)
        self._crad = m.geom_size[caps, 0] + self.spec.thickness
        self._cgeom = caps
        # the drawn surface: both trouser legs' triangles (global vertex ids) and, per
        # triangle, the capsules its leg meets (only those pairs are measured), in one set
        # (numpy's per-call overhead is most of a frame's measure)
        elems, pairs = [], []
        for f in range(m.nflex):
            adr, num = m.flex_elemdataadr[f], m.flex_elemnum[f]
            elems.append(m.flex_elem[adr : adr + 3 * num].reshape(-1, 3) + m.flex_vertadr[f])
            near = (m.geom_contype[caps] & (affinity[f] | _LOOSE)) > 0
            pairs.append(np.broadcast_to(near, (num, len(caps))))
        self._selems = np.concatenate(elems)
        self._spairs = np.concatenate(pairs)
        self._sradius = m.geom_size[caps, 0]

    # ------------------------------------------------------------------ controller
    def reset(self, world: World) -> None:
        del world
        self._reset_record()
        self._build()
        # the cloth starts moving with the pelvis, as if it had been worn before
        assert self.data is not None
        pos, _ = self._poses()
        vel, omega = self._velocities(pos)
        x = self._vrest + self._xq
        self._xv[:] = vel[0] + cross_rows(omega[0], x - pos[0])
        self._record(0.0)

    def _poses(self) -> tuple[F64, F64]:
        d = self.world.data
        ids = self.wc.body_ids
        return d.xpos[ids], d.xquat[ids]  # (copies: indexed by an array)

    def _velocities(self, pos: F64) -> tuple[F64, F64]:
        """World linear velocity of each body's origin (at ``pos``) and world angular
        velocity (from ``cvel``, which holds them about the subtree's centre of mass)."""
        d = self.world.data
        cvel = d.cvel[self.wc.body_ids]
        omega = cvel[:, :3]
        return cvel[:, 3:] + cross_rows(omega, pos - d.subtree_com[self._roots]), omega

    def control(self, world: World, t: float) -> None:
        assert self.model is not None and self.data is not None
        wall, cpu = time.perf_counter(), time.process_time()
        m, d = self.model, self.data
        pos, quat = self._poses()
        vel, omega = self._velocities(pos)
        rot = world.data.xmat[self.wc.body_ids].reshape(-1, 3, 3)
        local = np.einsum("bji,bj->bi", rot, omega)
        dt = self.control_every * world.timestep
        n = max(1, round(dt / m.opt.timestep))
        h = dt / n
        free, mocap = self._free_parts, self._mocap
        self._vbody[:, :3] = vel[free]
        self._vbody[:, 3:] = local[free]
        for k in range(n):
            # the runner's bodies carried over the tick by their velocities (the contacts
            # see them move, so the cloth is pushed along rather than overlapped)
            if k:
                pos_k = pos + vel * (k * h)
                quat_k = quat_normalize(quat_mul(quat, quat_exp(local * (k * h))))
                rot_k = quat_to_matrix(quat_k)
            else:
                pos_k, quat_k, rot_k = pos, quat, rot
            self._qbody[:, :3] = pos_k[free]
            self._qbody[:, 3:] = quat_k[free]
            d.mocap_pos[:] = pos_k[mocap]
            d.mocap_quat[:] = quat_k[mocap]
            self._sew(pos_k[0], rot_k[0], vel[0], omega[0])
            if self.spec.project or self.spec.tether > 0:
                self._project(pos_k, rot_k, (vel, omega) if self.spec.project_velocity else None)
            mujoco.mj_step(m, d)
        # MuJoCo resets a model whose state or acceleration went bad (and warns): its state
        # is finite again then; a sum is non-finite when an element is (cheaper than isfinite)
        total = float(d.qpos.sum()) + float(d.qvel.sum())
        if d.warning.number[_BAD].any() or not math.isfinite(total):
            self.finite = False
            raise SimulationError(f"the cloth went non-finite at t = {t:.3f} s")
        self._measure(world)
        if t + 1e-9 >= self._next_frame:
            self._record(t)
        self.wall_s += time.perf_counter() - wall
        self.cpu_s += time.process_time() - cpu

    def _place(self, d: mujoco.MjData, bodies: F64) -> None:
        """Put the body copies in ``d`` (this cloth's model's data) at poses ``bodies``
        ``(16, 7)`` (position, quaternion): the free ones by their joints, the others as
        mocap bodies."""
        free, mocap = self._free_parts, self._mocap
        d.qpos[: 7 * len(free)] = bodies[free].ravel()
        d.mocap_pos[:] = bodies[mocap, :3]
        d.mocap_quat[:] = bodies[mocap, 3:]

    def _project(self, pos: F64, rot: F64, velocity: tuple[F64, F64] | None = None) -> None:
        """Move the free vertices that are inside a body capsule (closer to its axis than
        its radius and the cloth's thickness) out along the capsule's radius, a few passes
        for where capsules overlap (behind a bent knee): with the contacts alone, a fast
        limb drags the cloth into itself, and once through, the cloth stays there. With
        ``velocity`` (the bodies' world linear velocities at their origins and angular
        velocities) a moved vertex also stops moving into the body: its velocity along the
        capsule's outward normal is raised to the body surface's there (what the soft contacts
        take several steps to do; its sliding along the surface is kept)."""
        part = self._cpart
        x = np.add(self._vrest, self._xq, out=self._x)
        if self.spec.tether > 0:
            self._tether(x, pos, rot)
        if self.spec.project:
            a = np.einsum("gij,gj->gi", rot[part], self._cpos) + pos[part]
            ax = np.einsum("gij,gj->gi", rot[part], self._caxis)
        # later passes look only at the vertices the one before moved (the others are out)
        v = self._vall
        lo, hi, crad = -self._chalf, self._chalf, self._crad
        moved: list[NDArray[np.intp]] = []
        normals: list[F64] = []
        caps: list[NDArray[np.intp]] = []
        for _ in range(self.spec.project):
            rel = x[v, None, :] - a
            s = np.minimum(np.maximum(np.einsum("vgi,gi->vg", rel, ax), lo), hi)
            rel -= s[..., None] * ax
            dist = np.sqrt(np.einsum("vgi,vgi->vg", rel, rel))
            depth = (crad - dist) * self._vmask[v]
            g = depth.argmax(axis=1)
            rows = np.arange(len(v))
            k = np.flatnonzero(depth[rows, g] > 0)
            if not k.size:
                break
            v, g = v[k], g[k]
            normal = rel[k, g] / np.maximum(dist[k, g], 1e-9)[:, None]
            x[v] += normal * depth[k, g][:, None]
            moved.append(v)
            normals.append(normal)
            caps.append(g)
        if not moved and self.spec.tether <= 0:
            return
        np.subtract(x, self._vrest, out=self._xq)
        if velocity is None or not moved:
            return
        vel, omega = velocity
        for w, normal, g in zip(moved, normals, caps):
            b = part[g]
            rel = self._xv[w] - (vel[b] + cross_rows(omega[b], x[w] - pos[b]))
            vn = np.einsum("vi,vi->v", rel, normal)
            self._xv[w] -= np.minimum(vn, 0.0)[:, None] * normal

    def _sew(self, pos: F64, rot: F64, vel: F64, omega: F64) -> None:
        """The waistband where the pelvis has it, moving with it (``pos``, ``rot``, ``vel``
        and ``omega`` the pelvis copy's)."""
        # the ring's points and their velocities about the pelvis in one product:
        # local @ [R^T | (W R)^T], W the cross-product matrix of omega (d/dt R = W R)
        w = self._spin
        w[0, 1], w[1, 0] = -omega[2], omega[2]
        w[0, 2], w[2, 0] = omega[1], -omega[1]
        w[1, 2], w[2, 1] = -omega[0], omega[0]
        frame = self._sew_frame
        frame[:, :3] = rot.T
        np.matmul(rot.T, w.T, out=frame[:, 3:])
        arm = np.matmul(self._pin_local, frame, out=self._arm)
        self._xq[self._pin] = arm[:, :3] + (pos - self._pin_rest)
        self._xv[self._pin] = arm[:, 3:] + vel

    def _measure(self, world: World) -> None:
        assert self.model is not None and self.data is not None
        m, d = self.model, self.data
        self._ticks += 1
        if not d.ncon and not self.feedback:
            return
        con = d.contact
        # cloth-body contacts: the body's geom is the contact's one geom (the flex's side is
        # -1; the copies and the floor collide with nothing but the cloth), the floor has
        # no part
        g = con.geom.max(axis=1)
        mine = self._geom_part[g] >= 0
        # the contact distance is the geometric one between the cloth's triangles inflated
        # by its thickness and the body geom (the margin adds contacts a little apart, whose
        # distance is positive): the cloth's mid-surface (what is drawn) is inside the body by
        # what is left after that
        dist = con.dist[mine]
        deepest = max(0.0, float(-dist.min()) - self.spec.thickness) if dist.size else 0.0
        self.penetration_max = max(self.penetration_max, deepest)
        self._over_1cm += deepest > 0.01
        if deepest > 0:
            self._pen_sum += deepest
            self._pen_n += 1
            self.penetration_mean = self._pen_sum / self._pen_n
        if not self.feedback:
            return
        # MuJoCo gives a contact's force one contact at a time; the rest over the cloth's
        # contacts at once (the stacked product, the cross product and the per-body sums in
        # contact order give the bits the per-contact loop gave)
        hit = np.flatnonzero(mine)
        f6 = np.empty((hit.size, 6))
        for k, i in enumerate(hit.tolist()):
            mujoco.mj_contactForce(m, d, i, f6[k])
        frames = con.frame[hit].reshape(-1, 3, 3)
        fw = np.matmul(frames.transpose(0, 2, 1), f6[:, :3, None])[..., 0]  # on geom 2 from 1
        on_body = np.where(con.flex[hit, :1] >= 0, fw, -fw)
        part = self._geom_part[g[hit]]
        arm = con.pos[hit] - world.data.xipos[self.wc.body_ids[part]]
        force = self._force
        force.fill(0.0)
        np.add.at(force[:, :3], part, on_body)
        np.add.at(force[:, 3:], part, np.cross(arm, on_body))
        xfrc = world.data.xfrc_applied
        ids = self.wc.body_ids
        xfrc[ids] -= self._applied
        xfrc[ids] += force
        self._applied, self._force = force, self._applied

    def _surface_depth(self) -> float:
        """How deep the drawn cloth (its triangles, sampled at the edge midpoints, the
        centroid and halfway from it to each corner) is inside the body's capsules (m). The
        contacts do not see a triangle that a limb has gone through between its corners."""
        m, d = self.model, self.data
        assert m is not None and d is not None
        g, half, radius = self._cgeom, self._chalf, self._sradius
        corners = d.flexvert_xpos[self._selems]
        # only the (triangle, capsule) pairs near enough for a sample to reach in: the samples
        # lie within half the farthest corner's distance of the centroid (the edge midpoints
        # and the points halfway to the corners), so that bound leaves none out
        centre = corners.mean(axis=1)
        spoke = corners - centre[:, None]
        reach = 0.5 * np.sqrt(np.einsum("eki,eki->ek", spoke, spoke).max(axis=1))
        ax = d.geom_xmat[g][:, 2::3]
        rel = centre[:, None, :] - d.geom_xpos[g]
        s = np.clip(np.einsum("egi,gi->eg", rel, ax), -half, half)
        rel -= s[..., None] * ax
        near = self._spairs & (np.einsum("egi,egi->eg", rel, rel) < (radius + reach[:, None]) ** 2)
        e, k = np.nonzero(near)
        if not e.size:
            return 0.0
        pts = np.einsum("sk,ekd->esd", _SURFACE_SAMPLES, corners[e])
        rel = pts - d.geom_xpos[g[k]][:, None]
        axk = ax[k]
        s = np.clip(np.einsum("esi,ei->es", rel, axk), -half[k, None], half[k, None])
        rel -= s[..., None] * axk[:, None]
        dist = np.sqrt(np.einsum("esi,esi->es", rel, rel))
        return max(0.0, float((radius[k, None] - dist).max()))

    def _record(self, t: float) -> None:
        assert self.data is not None
        depth = self._surface_depth()
        self.surface_max = max(self.surface_max, depth)
        self._surface.append(depth)
        pos, quat = self._poses()
        self.frames.append(self.data.flexvert_xpos.copy())
        self.frame_bodies.append(np.concatenate([pos, quat], axis=1))
        self.frame_times.append(t)
        self._next_frame = t + 1.0 / self.record_fps

    def report(self) -> dict[str, float | bool]:
        surface = self._surface
        return {
            "cloth": True,
            "cloth_feedback": self.feedback,
            "cloth_penetration_max_m": max(self.penetration_max, self.surface_max),
            "cloth_contact_depth_max_m": self.penetration_max,
            "cloth_penetration_mean_m": self.penetration_mean,
            "cloth_steps_over_1cm": self._over_1cm / max(self._ticks, 1),
            "cloth_surface_depth_max_m": self.surface_max,
            "cloth_surface_depth_median_m": float(np.median(surface)) if surface else 0.0,
            "cloth_surface_depth_p95_m": float(np.percentile(surface, 95)) if surface else 0.0,
            "cloth_frames_over_1cm": float(np.mean(np.array(surface) > 0.01)) if surface else 0.0,
            "cloth_finite": self.finite,
            "cloth_wall_s": self.wall_s,
            "cloth_cpu_s": self.cpu_s,
            "cloth_vertices": int(self.model.nflexvert) if self.model is not None else 0,
        }


def render_cloth_video(cloth: Cloth, path: str | Path, size: tuple[int, int] = (512, 384)) -> Path:
    """The recorded frames of a dressed run rendered with MuJoCo (the body as its collision
    geoms, the cloth as its flex). Raises :class:`~reactmocap.response.render.RenderUnavailable`
    where no GL context exists."""
    from reactmocap.response.plots import write_video
    from reactmocap.response.render import free_camera, offscreen_renderer

    if cloth.model is None or not cloth.frames:
        raise ReactMocapError("the cloth has no recorded frames (run it first)")
    m = cloth.model
    d = mujoco.MjData(m)
    width, height = size
    renderer = offscreen_renderer(m, size)
    cam = free_camera(3.2, -12.0, 120.0)
    frames = np.empty((len(cloth.frames), height, width, 3), dtype=np.uint8)
    try:
        for i, (verts, bodies) in enumerate(zip(cloth.frames, cloth.frame_bodies)):
            cloth._place(d, bodies)
            mujoco.mj_kinematics(m, d)
            # the flex vertices as recorded (they are bodies with slide joints: set them by
            # their world positions through the free-vertex qpos)
            _set_vertices(m, d, verts)
            cam.lookat[:] = (bodies[0, 0], bodies[0, 1], 0.8)
            renderer.update_scene(d, camera=cam)
            frames[i] = renderer.render()
    finally:
        renderer.close()
    return Path(write_video(frames, path, cloth.record_fps))


def _set_vertices(m: mujoco.MjModel, d: mujoco.MjData, verts: F64) -> None:
    """Put the flex's free vertices at world positions ``verts`` (pinned ones follow their
    body), through their slide joints."""
    mujoco.mj_kinematics(m, d)
    for v in range(m.nflexvert):
        body = int(m.flex_vertbodyid[v])
        jnt = int(m.body_jntadr[body])
        if jnt < 0 or m.body_jntnum[body] != 3:
            continue
        parent = int(m.body_parentid[body])
        rot = d.xmat[parent].reshape(3, 3)
        local = rot.T @ (verts[v] - d.xpos[parent]) - m.body_pos[body]
        adr = int(m.jnt_qposadr[jnt])
        d.qpos[adr : adr + 3] = local
    mujoco.mj_fwdPosition(m, d)  # the flex's vertex positions are made here
