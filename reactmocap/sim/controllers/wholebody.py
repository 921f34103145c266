"""Whole-body mocap tracking by inverse dynamics with optimised ground forces (Macchietto et al.
2009, Lee et al. 2010, Muico et al. 2009): each tick a small least-squares program for every
DOF's acceleration (the pelvis moved only by ground forces at the sole corners in contact,
inside friction pyramids), realised as joint torques. Only joint torques act: the result is
physical. A foot pivoting in the mocap touches through its ball-of-foot patch. The program,
and why: ``docs/design.md``."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray
from scipy.optimize import nnls

from reactmocap.errors import ConfigError, SimulationError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from reactmocap.sim.character import BALL_JOINTS
from reactmocap.sim.controllers.base import check_character, check_params
from reactmocap.sim.feet import foot_soles, sole_corners_world
from reactmocap.sim.reference import ReferencePath, reference_path
from reactmocap.sim.servo import critical_kv
from reactmocap.sim.world import World

__all__ = ["WholeBodyPlan", "WholeBodyTracker"]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)
NV = 6 + 3 * NJ
# friction pyramid edge directions per unit of mu (world x+, x-, y+, y-)
_PYRAMID = np.array([[1, 0], [-1, 0], [0, 1], [0, -1]], dtype=np.float64)
_UP = np.array([[0.0], [0.0], [1.0]])
# the patch's centre-of-pressure corners along the foot's (x, y) axes
_PATCH_CORNERS = ((1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0))


@dataclass(frozen=True)
class _Support:
    """The contact model of one control tick: ``feet`` supporting; ``points`` ``(k, 3)`` where
    forces act; ``basis`` ``(nb, 3)`` the world force of each unit generator, ``owner`` ``(nb,)``
    its point; ``gen`` ``(51, nb)`` the generators as generalised forces; ``rows`` ``(r, 51)``
    and ``bias`` ``(r,)`` the no-slip rows (``rows qdd + bias = -k_c rows qdot``)."""

    feet: tuple[int, ...]
    points: F64
    basis: F64
    owner: NDArray[np.int64]
    gen: F64
    rows: F64
    bias: F64


@dataclass(frozen=True)
class WholeBodyPlan:
    """One solution of the tracking program. ``qacc`` ``(51,)`` planned accelerations
    (MuJoCo ``qvel`` order), ``torques`` ``(15, 3)`` joint torques (child frames),
    ``support`` the supporting feet (0 left, 1 right), ``points`` ``(k, 3)`` where their
    ground forces act (sole corners; for a pivoting foot its ball patch and the patch's
    centre-of-pressure corners) and ``forces`` ``(k, 3)`` the ground force at each (world, N),
    ``generalized_contact`` ``(51,)`` those forces as generalised forces ``J_c^T f``,
    ``desired_qacc`` ``(51,)`` what perfect tracking would ask for."""

    qacc: F64
    torques: F64
    support: tuple[int, ...]
    points: F64
    forces: F64
    desired_qacc: F64
    generalized_contact: F64


class WholeBodyTracker:
    """Tracks ``reference`` from clip time ``start`` with inverse dynamics and optimised ground
    forces (see the module docstring), through the servo's feed-forward of one character. The
    servo itself is damping only (``servo_kv``, inertia-scaled): its stiffness, held between
    ticks against a moving target, fought the plan.

    Args:
        kp_root, kv_root: pelvis position gains (1/s^2, 1/s; kv critical by default).
        kp_rot, kv_rot: pelvis orientation gains.
        kp_joint, kv_joint: joint gains inside ``qdd_des`` (1/s^2, 1/s; ``None``: critical).
            A third of critical damping tracked more benchmark windows (64% against 48%, first
            version of this controller) but
            blew up on the synthetic ``sway`` clip, so the default stays critical.
        root_weight: weight of the pelvis rows of ``W`` against 1 for joints (dropped while
            no foot supports: then only momentum moves the pelvis).
        contact_weight, contact_kv: ``w_c`` and ``k_c`` of the no-slip term.
        friction: fraction of the floor's friction coefficient the plan may use.
        reach: a foot is planted in the mocap when its sole is within ``reach`` m of the
            floor (no speed test: a pivoting or rolling foot still carries weight); a sole
            corner supports when it is below ``floor + touch`` in the simulation (0: exactly
            MuJoCo's contact set; a 1 cm band put forces on hovering corners, which the
            simulation then did not produce).
        force_reg: ``lam``, the regulariser on the pyramid coefficients (relative).
        pivot_rate: a planted foot pivots (touches through its ball patch) while the mocap
            foot's yaw rate is above this (rad/s); ``None``: feet never pivot. Measured on the
            benchmark windows: 80% tracked with 2.0 or 3.0, 74% without pivots. With a
            :class:`ReferencePath` given, its own ``planted`` and ``pivoting`` are used.
        servo_kv: the servo's damping (1/s).

    Defaults were chosen on the shared walk, run and kick clips (``benchmarks/bench_sim.py``).
    """

    def __init__(
        self,
        world: World,
        character: int,
        reference: Motion | ReferencePath,
        start: float = 0.0,
        *,
        kp_root: float = 100.0,
        kv_root: float | None = None,
        kp_rot: float = 500.0,
        kv_rot: float | None = None,
        kp_joint: float,
        kv_joint: float | None = None,
        root_weight: float = 30.0,
        contact_weight: float = 1e4,
        contact_kv: float = 20.0,
        friction: float = 0.7,
        reach: float = 0.05,
        touch: float = 0.0,
        force_reg: float = 1e-6,
        pivot_rate: float | None = 2.0,
        servo_kv: float,
        control_every: int,
    ) -> None:
        check_character(world, character)
        check_params(
            {
                "kp_root": kp_root, "kp_rot": kp_rot, "kp_joint": kp_joint,
                "root_weight": root_weight, "contact_weight": contact_weight,
                "contact_kv": contact_kv, "friction": friction, "reach": reach, "touch": touch,
                "force_reg": force_reg, "pivot_rate": pivot_rate, "servo_kv": servo_kv,
                "kv_root": kv_root, "kv_rot": kv_rot, "kv_joint": kv_joint,
            },
        )  # fmt: skip
        servo = world.servo
        m = world.model
        if np.any(m.opt.gravity[:2]):
            raise ConfigError("WholeBodyTracker assumes vertical gravity")
        self.servo = servo
        self.world = world
        self.character = character
        self.servo_kv = float(servo_kv)
        self.control_every = int(control_every)
        wc = world.characters[character]
        self.wc = wc
        kvj = critical_kv(kp_joint) if kv_joint is None else float(kv_joint)
        self.kp = np.r_[np.full(3, kp_root), np.full(3, kp_rot), np.full(3 * NJ, kp_joint)]
        self.kv = np.r_[
            np.full(3, critical_kv(kp_root) if kv_root is None else kv_root),
            np.full(3, critical_kv(kp_rot) if kv_rot is None else kv_rot),
            np.full(3 * NJ, kvj),
        ]
        self._kp0, self._kv0 = self.kp.copy(), self.kv.copy()
        self.w = np.r_[np.full(6, root_weight), np.ones(3 * NJ)]
        self._w_air = np.r_[np.zeros(6), np.ones(3 * NJ)]
        self.sqrt_wc = float(np.sqrt(contact_weight))
        self.contact_kv = float(contact_kv)
        self.mu = float(friction) * float(world.config.friction)
        self.touch = float(touch)
        self.sqrt_reg = float(np.sqrt(force_reg))
        self.feet, self.sole, self._corners = foot_soles(world, character, "WholeBodyTracker")
        self.floor_z = float(world.data.geom_xpos[m.geom("floor").id, 2])
        self._dofs = wc.qvel_slice
        self._full = np.zeros((m.nv, m.nv))
        self._jacp = np.zeros((3, m.nv))
        self._jacd = np.zeros((3, m.nv))
        self._jacr = np.zeros((3, m.nv))
        self._jacrd = np.zeros((3, m.nv))
        self.patch = wc.patch_ids
        self.patch_half = m.geom_size[self.patch, 2].copy()
        self.patch_arm = m.geom_friction[self.patch, 2].copy()
        rows = character * NJ
        self._ff = servo.feedforward[rows : rows + NJ]  # (15, 3) view
        self._servo_rows = slice(rows, rows + NJ)
        edges = np.column_stack([self.mu * _PYRAMID, np.ones(4)])  # (4, 3)
        self._edges = edges.T  # (3, 4) columns: unnormalised pyramid edges
        self.last_plan: WholeBodyPlan | None = None
        #: ``(6,)`` extra pelvis acceleration asked of the plan (world linear m/s^2, local
        #: angular rad/s^2), on top of its feedback; set by
        #: :class:`~reactmocap.sim.controllers.predictive.PredictiveTracker`, zero otherwise
        self.root_bias = np.zeros(6)
        #: the clip as this tracker follows it
        self.path = (
            reference
            if isinstance(reference, ReferencePath)
            else reference_path(world, character, reference, reach=reach, pivot_rate=pivot_rate)
        )
        self.clock = self.path.clock(start)
        self.release()

    # ------------------------------------------------------------------ reference
    def reference(self, t: float) -> tuple[F64, F64, F64, NDArray[np.bool_]]:
        """The mocap at rollout time ``t``: ``qpos`` (67,), ``qvel`` (51,), ``qacc`` (51,) and
        the planted feet (2,) (see :meth:`ReferencePath.sample`)."""
        return self.path.sample(self.clock.frame(t), self.clock.coast(t))

    # ------------------------------------------------------------------ control
    def release(self) -> None:
        """Give both feet back their sole boxes (undo any pivot). The tracker switches patches
        at each tick; call this when done with a world that lives on."""
        for f in range(2):
            self.world.set_foot_patch(self.character, f, False)

    def _support(self, d: mujoco.MjData, planted: NDArray[np.bool_]) -> _Support:
        """The contact model at the current state: the sole corners MuJoCo has in contact, or
        the ball patch of a pivoting foot, of the feet planted in the mocap."""
        m = self.world.model
        corners = sole_corners_world(d, self.sole, self._corners)
        patch_on = self.world.foot_patch_on(self.character)
        qdot = d.qvel[self._dofs]
        sl = self._dofs
        feet: list[int] = []
        pts: list[F64] = []
        gens: list[F64] = []  # (3, ne) world force per unit coefficient, per point
        jacs: list[F64] = []
        rows: list[F64] = []
        bias: list[F64] = []

        def point(p: F64, body: int, edges: F64, still: bool) -> None:
            mujoco.mj_jac(m, d, self._jacp, None, p, body)
            jac = self._jacp[:, sl].copy()
            pts.append(p)
            gens.append(edges)
            jacs.append(jac)
            if still:
                mujoco.mj_jacDot(m, d, self._jacd, None, p, body)
                rows.append(jac)
                bias.append(self._jacd[:, sl] @ qdot)

        for f in range(2):
            if not planted[f]:
                continue
            body = int(self.feet[f])
            if patch_on[f]:
                rot = d.geom_xmat[self.patch[f]].reshape(3, 3)
                p = d.geom_xpos[self.patch[f]] - rot[:, 2] * self.patch_half[f]  # bottom face
                low = p[2] - self.patch_half[f] * np.abs(rot[2, :2]).sum()  # its lowest corner
                if low - self.floor_z >= self.touch:
                    continue
                feet.append(f)
                point(p, body, self._edges, True)
                # the foot does not roll or pitch on its patch; its yaw is free
                mujoco.mj_jac(m, d, None, self._jacr, p, body)
                mujoco.mj_jacDot(m, d, None, self._jacrd, p, body)
                rows.append(self._jacr[:2, sl].copy())
                bias.append(self._jacrd[:2, sl] @ qdot)
                axes = d.geom_xmat[self.sole[f]].reshape(3, 3)[:, :2].T.copy()
                axes[:, 2] = 0.0  # the centre-of-pressure range lies on the floor
                axes /= np.linalg.norm(axes, axis=1, keepdims=True)
                for sx, sy in _PATCH_CORNERS:
                    cop = p + self.patch_arm[f] * (sx * axes[0] + sy * axes[1])
                    point(cop, body, _UP, False)
                continue
            touching = corners[f, :, 2] - self.floor_z < self.touch
            if not touching.any():
                continue
            feet.append(f)
            for p in corners[f, touching]:
                point(p, body, self._edges, True)
        if not feet:
            z = np.zeros((0, 3))
            return _Support(
                (), z, z, np.zeros(0, np.int64), np.zeros((NV, 0)), np.zeros((0, NV)), np.zeros(0)
            )
        owner = np.concatenate([np.full(e.shape[1], k) for k, e in enumerate(gens)])
        return _Support(
            feet=tuple(feet),
            points=np.array(pts),
            basis=np.concatenate(gens, axis=1).T,
            owner=owner,
            gen=np.concatenate([j.T @ e for j, e in zip(jacs, gens)], axis=1),
            rows=np.concatenate(rows),
            bias=np.concatenate(bias),
        )

    def plan(self, t: float) -> WholeBodyPlan:
        """Solve the tracking program at rollout time ``t`` for the current state (MuJoCo's
        quantities of the last step). Does not touch the simulation."""
        m, d = self.world.model, self.world.data
        qr, vr, ar, planted = self.reference(t)
        sl = self._dofs
        q = d.qpos[self.wc.qpos_slice]
        v = d.qvel[sl]
        if not (np.isfinite(q).all() and np.isfinite(v).all()):
            raise SimulationError(f"WholeBodyTracker: the state at t = {t:.4f} s is not finite")
        # position error in qvel coordinates: world translation, local rotation vectors
        rel = quat_mul(quat_conj(q[3:].reshape(NJ + 1, 4)), qr[3:].reshape(NJ + 1, 4))
        rel *= np.where(rel[:, :1] < 0, -1.0, 1.0)
        err = np.r_[qr[:3] - q[:3], quat_log(rel).reshape(-1)]
        acc_des = ar + self.kp * err + self.kv * (vr - v)
        acc_des[:6] += self.root_bias

        mujoco.mj_fullM(m, d, self._full)
        big_m = self._full[sl, sl]
        # gravity and Coriolis; MuJoCo's passive joint damping is left out of the plan on
        # purpose, so it acts as extra damping (compensating it, first version: 50% of the benchmark windows
        # tracked instead of 64%)
        h = d.qfrc_bias[sl]
        sup = self._support(d, planted)
        nc = len(sup.points)
        nb = sup.gen.shape[1]
        nj = 3 * NJ
        # qdd = G z + g0 with z = [joint accelerations (45), pyramid coefficients (4 nc)]:
        # the pelvis rows come from the pelvis's Newton-Euler equation
        qb = sup.gen
        rhs = np.linalg.solve(big_m[:6, :6], np.column_stack([big_m[:6, 6:], qb[:6], h[:6]]))
        g = np.zeros((NV, nj + nb))
        g[:6, :nj] = -rhs[:, :nj]
        g[:6, nj:] = rhs[:, nj : nj + nb]
        g[6:, :nj] = np.eye(nj)
        g0 = np.zeros(NV)
        g0[:6] = -rhs[:, -1]
        # with nothing to push on, the pelvis follows momentum whatever the joints do: asking
        # the joints to steer it anyway made them whip and blew up falls (tumbling kicks)
        w = self.w if nc else self._w_air
        rows_a = [w[:, None] * g]
        rows_b = [w * (acc_des - g0)]
        if nc:
            # the corners in contact do not move (J_c qdd + Jdot_c qdot = -k_c v_c), so the
            # planned forces are the ones MuJoCo's rigid-ish contact will produce: with only
            # the tangential rows and a soft weight, joint accelerations missed the plan by
            # 100-350 rad/s^2 in double support
            jt = sup.rows
            rows_a.append(self.sqrt_wc * (jt @ g))
            rows_b.append(-self.sqrt_wc * (jt @ g0 + sup.bias + self.contact_kv * (jt @ v)))
        a_mat = np.concatenate(rows_a)
        b_vec = np.concatenate(rows_b)
        ay, ab = a_mat[:, :nj], a_mat[:, nj:]
        qmat, rmat = np.linalg.qr(ay)
        if nb:
            # project the free joint accelerations out, then NNLS over the pyramid coefficients
            pab = ab - qmat @ (qmat.T @ ab)
            pb = b_vec - qmat @ (qmat.T @ b_vec)
            scale = float(np.linalg.norm(pab, axis=0).max()) or 1.0
            lhs = np.concatenate([pab, self.sqrt_reg * scale * np.eye(nb)])
            beta, _ = nnls(lhs, np.r_[pb, np.zeros(nb)], maxiter=50 * nb)
        else:
            beta = np.zeros(0)
        y = np.linalg.solve(rmat, qmat.T @ (b_vec - ab @ beta))
        qdd = g @ np.r_[y, beta] + g0
        tau = big_m[6:] @ qdd + h[6:] - qb[6:] @ beta
        forces = np.zeros((nc, 3))
        np.add.at(forces, sup.owner, sup.basis * beta[:, None])
        return WholeBodyPlan(
            qacc=qdd, torques=tau.reshape(NJ, 3), support=sup.feet, points=sup.points,
            forces=forces, desired_qacc=acc_des, generalized_contact=qb @ beta,
        )  # fmt: skip

    def scale_gains(self, scale: float) -> None:
        """The tracking gains (joints and pelvis) times ``scale``, damping times its root."""
        self.kp[:] = self._kp0 * scale
        self.kv[:] = self._kv0 * np.sqrt(scale)

    def hold(self, t: float) -> None:
        """From rollout time ``t`` on, follow the reference's pose at ``t``."""
        self.clock = self.clock.held_from(t)

    def reset(self, world: World) -> None:
        servo = world.servo
        servo.enable(self.character, on=True)
        servo.set_gains(0.0, self.servo_kv, self.character)
        servo.refresh_every = self.control_every

    def control(self, world: World, t: float) -> None:
        pivoting = self.path.pivoting[self.clock.nearest(t)]
        for f in range(2):
            world.set_foot_patch(self.character, f, bool(pivoting[f]))
        plan = self.plan(t)
        self.last_plan = plan
        # the servo (damping only by default) keeps acting between ticks; at the tick the
        # total joint torque is the plan's
        self._ff[:] = plan.torques - self.servo.torques()[self._servo_rows]
