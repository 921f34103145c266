"""The simulated world: a floor, gravity, friction, characters (each attached to one MjSpec under
a prefix, ``a/``, ``b/``, ...), an optional :class:`Scene` (extra bodies such as bicycles and
obstacles), the servo actuators every ball joint carries, and which character and body each geom
belongs to. Why the contact and solver settings are what they are: ``docs/design.md``."""

from __future__ import annotations

import string
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal, Protocol

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, SimulationError
from reactmocap.library.motion import Motion
from reactmocap.sim.character import BALL_JOINTS, SIM_BODIES, Character

if TYPE_CHECKING:
    from reactmocap.sim.servo import PDServo

__all__ = [
    "PATCH_ROLL",
    "PATCH_TORSION",
    "PREFIXES",
    "Scene",
    "World",
    "WorldCharacter",
    "WorldConfig",
]

F64 = NDArray[np.float64]
#: name prefixes of a world's characters, in order (``a/`` and ``b/`` for the usual pair)
PREFIXES = tuple(f"{c}/" for c in string.ascii_lowercase)


class Scene(Protocol):
    """Extra bodies in a World (bicycles, obstacles): :meth:`build` adds them to the MjSpec
    after the characters are attached (so constraints may name character bodies) and before it
    is compiled; :meth:`configure` runs once the World has applied its own contact settings to
    every geom (a scene re-applies its own there)."""

    def build(self, spec: mujoco.MjSpec) -> None: ...

    def configure(self, world: World) -> None: ...


_INTEGRATORS = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
}
_SOLVERS = {
    "newton": mujoco.mjtSolver.mjSOL_NEWTON,
    "cg": mujoco.mjtSolver.mjSOL_CG,
    "pgs": mujoco.mjtSolver.mjSOL_PGS,
}
_CONES = {"pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL, "elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC}


def _add_servo_actuators(spec: mujoco.MjSpec, prefix: str) -> None:
    """Three inert actuators per ball joint of one character (``<joint>/servo0..2``): joint
    transmission, fixed gain, affine bias, all zero; unit gear axes until a servo sets them."""
    for joint in BALL_JOINTS:
        for a in range(3):
            gear = [0.0] * 6
            gear[a] = 1.0
            spec.add_actuator(
                name=f"{prefix}{joint}/servo{a}",
                target=prefix + joint,
                trntype=mujoco.mjtTrn.mjTRN_JOINT,
                gaintype=mujoco.mjtGain.mjGAIN_FIXED,
                biastype=mujoco.mjtBias.mjBIAS_AFFINE,
                gainprm=[0.0] * 10,
                biasprm=[0.0] * 10,
                gear=gear,
            )


@dataclass(frozen=True)
class WorldConfig:
    """World parameters (all overridable; defaults from the papers and our measurements)."""

    timestep: float = 0.0005
    friction: float = 1.0
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    integrator: Literal["euler", "implicitfast", "implicit", "rk4"] = "implicitfast"
    solver: Literal["newton", "cg", "pgs"] = "newton"
    cone: Literal["pyramidal", "elliptic"] = "pyramidal"
    iterations: int = 50
    contact_solref: tuple[float, float] = (0.01, 1.0)
    contact_solimp: tuple[float, float, float] = (0.9, 0.95, 0.001)
    #: contacts between characters: stiffer than the floor's, so a kick's foot stops within
    #: about a centimetre of the body it hits (MuJoCo's soft contact would otherwise let a
    #: 10 m/s foot sink ~4 cm per 10 ms of time constant)
    body_contact_solref: tuple[float, float] = (0.002, 1.0)
    self_collision: bool = False
    #: light joint damping (Deva: a weak damper everywhere), in 1/s: each ball DOF gets
    #: ``joint_damping * I_dof`` with ``I_dof`` its outboard inertia in the reference pose
    joint_damping: float = 1.0
    #: limit softness for the ball-joint cones
    limit_solref: tuple[float, float] = (0.02, 1.0)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.timestep) and 0 < self.timestep <= 0.01):
            raise ConfigError(f"timestep must be in (0, 0.01] s, got {self.timestep!r}")
        if not (np.isfinite(self.friction) and self.friction >= 0):
            raise ConfigError(f"friction must be >= 0, got {self.friction!r}")
        if self.integrator not in _INTEGRATORS:
            raise ConfigError(
                f"integrator must be one of {list(_INTEGRATORS)}, got {self.integrator!r}"
            )
        if self.solver not in _SOLVERS:
            raise ConfigError(f"solver must be one of {list(_SOLVERS)}, got {self.solver!r}")
        if self.cone not in _CONES:
            raise ConfigError(f"cone must be one of {list(_CONES)}, got {self.cone!r}")
        for name in ("contact_solref", "body_contact_solref"):
            tc = getattr(self, name)[0]
            if tc < 2 * self.timestep:
                raise ConfigError(
                    f"{name} time constant {tc} must be at least twice the timestep "
                    f"{self.timestep} (MuJoCo would silently clamp it)"
                )
        if self.joint_damping < 0:
            raise ConfigError(f"joint_damping must be >= 0, got {self.joint_damping!r}")


@dataclass(eq=False)
class WorldCharacter:
    """One character inside a World: where its bodies, qpos and qvel live."""

    index: int
    prefix: str
    character: Character
    body_ids: NDArray[np.int64]  # (16,) in SIM_BODIES order
    qpos_adr: int  # free joint start; 7 + 60 contiguous values
    dof_adr: int  # free joint dof start; 6 + 45 contiguous values
    geom_ids: NDArray[np.int64]
    body_lookup: dict[str, int] = field(default_factory=dict)
    #: (2,) left, right: each foot's sole box and ball-of-foot patch geoms
    sole_ids: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    patch_ids: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    #: first of the character's 45 servo actuators: 3 per ball joint, BALL_JOINTS order
    actuator_adr: int = -1

    @property
    def qpos_slice(self) -> slice:
        return slice(self.qpos_adr, self.qpos_adr + 7 + 4 * len(BALL_JOINTS))

    @property
    def qvel_slice(self) -> slice:
        return slice(self.dof_adr, self.dof_adr + 6 + 3 * len(BALL_JOINTS))

    @property
    def ball_qpos_start(self) -> int:
        return self.qpos_adr + 7

    @property
    def ball_dof_start(self) -> int:
        return self.dof_adr + 6

    def body_id(self, name: str) -> int:
        return self.body_lookup[Character.body_name(name)]


#: torsional friction arm (m) of the ball-of-foot patch
PATCH_TORSION = 0.005
#: rolling friction arm (m) of the ball-of-foot patch: how far the centre of pressure may move
PATCH_ROLL = 0.03


class World:
    """A MuJoCo model and data with a floor, characters (one or two for tracking and responses;
    none or many with a :class:`Scene`) and the scene's bodies."""

    def __init__(
        self,
        characters: Character | Sequence[Character],
        config: WorldConfig | None = None,
        *,
        scene: Scene | None = None,
        **overrides: object,
    ) -> None:
        chars = [characters] if isinstance(characters, Character) else list(characters)
        least = 0 if scene is not None else 1
        if not least <= len(chars) <= len(PREFIXES):
            raise ConfigError(f"a World holds {least}-{len(PREFIXES)} characters, got {len(chars)}")
        cfg = config or WorldConfig()
        if overrides:
            from dataclasses import replace

            try:
                cfg = replace(cfg, **overrides)  # type: ignore[arg-type]
            except TypeError as exc:
                raise ConfigError(f"unknown world option: {exc}") from None
        self.config = cfg
        spec = mujoco.MjSpec()
        spec.compiler.degree = False
        opt = spec.option
        opt.timestep = cfg.timestep
        opt.gravity = list(cfg.gravity)
        opt.integrator = _INTEGRATORS[cfg.integrator]
        opt.solver = _SOLVERS[cfg.solver]
        opt.cone = _CONES[cfg.cone]
        opt.iterations = cfg.iterations
        # never reset silently on divergence: rollouts detect it and raise SimulationError
        opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
        # the servo actuators are inert until a PDServo switches actuation on (saves ~1 us/step)
        opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
        floor = spec.worldbody.add_geom(
            name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0]
        )
        floor.contype = 1
        floor.conaffinity = 1
        for k, ch in enumerate(chars):
            frame = spec.worldbody.add_frame()
            spec.attach(ch.make_spec(), prefix=PREFIXES[k], frame=frame)
        for k in range(len(chars)):
            _add_servo_actuators(spec, PREFIXES[k])
        if scene is not None:
            scene.build(spec)
        try:
            self.model = spec.compile()
        except Exception as exc:  # mujoco raises ValueError with the compiler's message
            raise SimulationError(f"MuJoCo could not compile the world: {exc}") from exc
        self.spec = spec
        m = self.model
        self.data = mujoco.MjData(m)
        self._mv = np.empty(m.nv)
        #: bumped whenever the state is set from outside the integrator (set_pose, set_state):
        #: a PDServo then re-linearises its actuators before the next step
        self.state_epoch = 0
        self._servo: PDServo | None = None
        self.characters: list[WorldCharacter] = []
        for k, ch in enumerate(chars):
            pre = PREFIXES[k]
            ids = np.array([m.body(pre + b).id for b in SIM_BODIES], dtype=np.int64)
            root = m.joint(pre + "root").id
            balls = [m.joint(pre + j).id for j in BALL_JOINTS]
            qadr = int(m.jnt_qposadr[root])
            dadr = int(m.jnt_dofadr[root])
            if [int(m.jnt_qposadr[j]) for j in balls] != [qadr + 7 + 4 * i for i in range(15)]:
                raise SimulationError("ball joints are not contiguous in qpos (internal error)")
            geoms = np.flatnonzero(np.isin(m.geom_bodyid, ids))
            feet = [m.body(f"{pre}{side}_foot").id for side in "lr"]
            patches = [m.geom(f"{pre}{side}_foot_ball").id for side in "lr"]
            soles = [
                g for f in feet for g in geoms
                if m.geom_bodyid[g] == f and m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX
                and g not in patches
            ]  # fmt: skip
            if len(soles) != 2:
                raise SimulationError("each foot needs exactly one sole box (internal error)")
            acts = [m.actuator(f"{pre}{j}/servo{a}").id for j in BALL_JOINTS for a in range(3)]
            if acts != list(range(acts[0], acts[0] + 3 * len(BALL_JOINTS))) or any(
                int(m.actuator_trnid[a, 0]) != balls[i // 3] for i, a in enumerate(acts)
            ):
                raise SimulationError("servo actuators are not contiguous (internal error)")
            self.characters.append(
                WorldCharacter(
                    k,
                    pre,
                    ch,
                    ids,
                    qadr,
                    dadr,
                    geoms,
                    {b: int(i) for b, i in zip(SIM_BODIES, ids)},
                    actuator_adr=acts[0],
                    sole_ids=np.array(soles, dtype=np.int64),
                    patch_ids=np.array(patches, dtype=np.int64),
                )
            )
        char = np.full(m.ngeom, -1, dtype=np.int64)
        body = np.full(m.ngeom, -1, dtype=np.int64)
        for wc in self.characters:
            for i, bid in enumerate(wc.body_ids):
                sel = m.geom_bodyid == bid
                char[sel] = wc.index
                body[sel] = i
        char.flags.writeable = False
        body.flags.writeable = False
        #: ``(ngeom,)`` the character each geom belongs to (-1: the floor)
        self.geom_character = char
        #: ``(ngeom,)`` the index into SIM_BODIES of each geom's body (-1: the floor)
        self.geom_body = body
        self._apply_contact_settings()
        self._apply_joint_settings()
        self.set_friction(cfg.friction)
        self.scene = scene
        if scene is not None:
            scene.configure(self)
        mujoco.mj_forward(m, self.data)

    # ------------------------------------------------------------------ settings
    def _apply_contact_settings(self) -> None:
        m, cfg = self.model, self.config
        n = len(self.characters)
        all_bits = 1 | sum(1 << (k + 1) for k in range(n))
        for wc in self.characters:
            own = 1 << (wc.index + 1)
            m.geom_contype[wc.geom_ids] = own
            m.geom_conaffinity[wc.geom_ids] = all_bits if cfg.self_collision else all_bits & ~own
        m.geom_conaffinity[m.geom("floor").id] = all_bits
        m.geom_condim[:] = 3
        for wc in self.characters:
            m.geom_contype[wc.patch_ids] = 0
            m.geom_conaffinity[wc.patch_ids] = 0
            m.geom_condim[wc.patch_ids] = 6
            m.geom_friction[wc.patch_ids, 1:] = (PATCH_TORSION, PATCH_ROLL)
        # characters' geoms carry the body-body settings; the floor's dominate its contacts
        # through solmix (MuJoCo mixes solref by solmix weights; condim and friction unaffected)
        floor = m.geom("floor").id
        m.geom_solref[:] = cfg.body_contact_solref
        m.geom_solref[floor] = cfg.contact_solref
        m.geom_solmix[:] = 1.0
        m.geom_solmix[floor] = 1e9
        m.geom_solimp[:, :3] = cfg.contact_solimp

    def _apply_joint_settings(self) -> None:
        """Light damping scaled by each DOF's outboard inertia in the reference pose."""
        m, d, cfg = self.model, self.data, self.config
        for wc in self.characters:
            d.qpos[wc.qpos_slice] = wc.character.model.qpos0
        # the mass matrix only: no collision pass (characters all at their origin would touch)
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_makeM(m, d)
        diag = np.empty(m.nv)
        diag[:] = d.M[m.M_rowadr + m.M_rownnz - 1]  # diagonal = last entry of each CSR row
        for wc in self.characters:
            dofs = np.arange(wc.ball_dof_start, wc.ball_dof_start + 3 * len(BALL_JOINTS))
            m.dof_damping[dofs] = cfg.joint_damping * diag[dofs]
        m.jnt_solref[:] = cfg.limit_solref
        mujoco.mj_resetData(m, d)

    def set_foot_patch(self, character: int, foot: int, on: bool) -> None:
        """Move a foot's contact (``foot`` 0 left, 1 right) from its sole box to its ball-of-foot
        patch (``on``) or back. Takes effect at the next collision pass. A model setting, not
        part of :meth:`get_state`: whoever switches a patch on switches it back."""
        m = self.model
        wc = self.characters[character]
        box, patch = int(wc.sole_ids[foot]), int(wc.patch_ids[foot])
        live, dead = (patch, box) if on else (box, patch)
        if m.geom_contype[live] == 0:
            m.geom_contype[live] = m.geom_contype[dead]
            m.geom_conaffinity[live] = m.geom_conaffinity[dead]
            m.geom_contype[dead] = 0
            m.geom_conaffinity[dead] = 0

    def foot_patch_on(self, character: int) -> NDArray[np.bool_]:
        """``(2,)`` whether each foot (left, right) currently touches through its patch."""
        return self.model.geom_contype[self.characters[character].patch_ids] != 0

    def set_friction(
        self, mu: float, character: int | None = None, bodies: tuple[str, ...] | None = None
    ) -> None:
        """Sliding friction coefficient of every contact, or of one character's contacts (only
        those of its ``bodies``, names of SIM_BODIES, when given). MuJoCo takes the larger of
        two geoms' coefficients, so the floor keeps the smallest any character has and each
        character's geoms carry its own."""
        if not (np.isfinite(mu) and mu >= 0):
            raise ConfigError(f"friction must be >= 0, got {mu!r}")
        m = self.model
        if character is None:
            m.geom_friction[:, 0] = mu
            return
        geoms = self.characters[character].geom_ids
        if bodies is not None:
            unknown = sorted(set(bodies) - set(SIM_BODIES))
            if unknown:
                raise ConfigError(f"bodies: unknown {unknown}; expected names of {SIM_BODIES}")
            picked = [SIM_BODIES.index(b) for b in bodies]
            geoms = geoms[np.isin(self.geom_body[geoms], picked)]
        m.geom_friction[geoms, 0] = mu
        floor = m.geom("floor").id
        m.geom_friction[floor, 0] = min(
            float(m.geom_friction[wc.geom_ids, 0].min()) for wc in self.characters
        )

    def characters_touching(self) -> bool:
        """Whether two characters are in contact now (MuJoCo's contacts of the last step)."""
        d = self.data
        if d.ncon == 0 or len(self.characters) < 2:
            return False
        own = self.geom_character[d.contact.geom[: d.ncon]]
        return bool(np.any((own[:, 0] >= 0) & (own[:, 1] >= 0) & (own[:, 0] != own[:, 1])))

    # ------------------------------------------------------------------ state
    @property
    def time(self) -> float:
        return float(self.data.time)

    @property
    def timestep(self) -> float:
        return float(self.model.opt.timestep)

    def set_pose(self, index: int, qpos: F64, qvel: F64 | None = None) -> None:
        """Set one character's qpos (67) and qvel (51, zero if omitted); run mj_forward."""
        wc = self.characters[index]
        qpos = np.asarray(qpos, dtype=np.float64)
        if qpos.shape != (7 + 4 * len(BALL_JOINTS),) or not np.all(np.isfinite(qpos)):
            raise SimulationError(f"qpos must be 67 finite numbers, got shape {qpos.shape}")
        self.data.qpos[wc.qpos_slice] = qpos
        self.data.qvel[wc.qvel_slice] = 0.0 if qvel is None else qvel
        self.state_epoch += 1
        mujoco.mj_forward(self.model, self.data)

    def set_from_motion(
        self, index: int, motion: Motion, frame: int, velocity: bool = True
    ) -> None:
        """Put a character in a motion frame (pose and finite-difference velocities)."""
        ch = self.characters[index].character
        q = ch.qpos_from_motion(motion, [frame])[0]
        v = ch.qvel_from_motion(motion, [frame])[0] if velocity else None
        self.set_pose(index, q, v)

    def body_transforms(self, index: int) -> tuple[F64, F64]:
        """World positions ``(16, 3)`` and rotations ``(16, 4)`` of a character's bodies."""
        ids = self.characters[index].body_ids
        return self.data.xpos[ids].copy(), self.data.xquat[ids].copy()

    def get_state(self) -> F64:
        """Full integration state (time, qpos, qvel, warm start, ctrl, applied forces...).
        The servo actuators' gears and gains are model parameters, not state: restoring a
        state makes a PDServo re-linearise (``state_epoch``) before its next step."""
        spec = mujoco.mjtState.mjSTATE_INTEGRATION
        out = np.empty(mujoco.mj_stateSize(self.model, spec))
        mujoco.mj_getState(self.model, self.data, out, spec)
        return out

    def set_state(self, state: F64) -> None:
        spec = mujoco.mjtState.mjSTATE_INTEGRATION
        mujoco.mj_setState(self.model, self.data, np.asarray(state, dtype=np.float64), spec)
        self.state_epoch += 1
        mujoco.mj_forward(self.model, self.data)

    def step(self, n: int = 1) -> None:
        """Advance ``n`` physics steps with the servo (if any) and the forces currently in
        ``qfrc_applied``/``xfrc_applied``."""
        if self._servo is not None:
            self._servo.step(n)
        else:
            mujoco.mj_step(self.model, self.data, nstep=n)

    def attach_servo(self, servo: PDServo) -> None:
        """Make ``servo`` the world's (a PDServo registers itself when made): :meth:`step`
        steps through it from now on."""
        self._servo = servo

    @property
    def has_servo(self) -> bool:
        return self._servo is not None

    @property
    def servo(self) -> PDServo:
        """The world's PD servo over every character's ball joints, made on first use (inert
        until a controller sets gains; actuation stays off in a world that never asks)."""
        if self._servo is None:
            from reactmocap.sim.servo import PDServo

            PDServo(self)  # registers itself
        assert self._servo is not None
        return self._servo

    def kinetic_energy(self, index: int | None = None) -> float:
        """Kinetic energy (J) of one character (or of everything), 0.5 v^T M v."""
        m, d = self.model, self.data
        mv = self._mv  # made once: the rollout's guard asks every few steps
        mujoco.mj_mulM(m, d, mv, d.qvel)
        if index is None:
            return 0.5 * float(d.qvel @ mv)
        s = self.characters[index].qvel_slice
        return 0.5 * float(d.qvel[s] @ mv[s])

    def com(self, index: int) -> F64:
        """Centre of mass of a character (world)."""
        wc = self.characters[index]
        root = wc.body_ids[0]
        return self.data.subtree_com[root].copy()
