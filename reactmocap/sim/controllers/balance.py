"""Stance balance for mocap tracking (Zordan & Hodgins 2002; Coros et al. 2010; the thesis's
ch. 7 in Jacobian form): gravity compensation, a centre-of-mass servo and a trunk orientation
servo realised by the stance legs as feed-forward torques on top of the PD servo. Only joint
torques act, so the result is physical. Details: ``docs/design.md``."""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from reactmocap.sim.character import BALL_JOINTS, qvel_between
from reactmocap.sim.controllers.base import check_character, check_params
from reactmocap.sim.feet import foot_soles, sole_corners_world
from reactmocap.sim.reference import ReferencePath, as_path
from reactmocap.sim.servo import critical_kv
from reactmocap.sim.world import World

__all__ = ["StanceBalance"]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)


def _cross(a: F64, b: F64) -> F64:
    """3-vector cross product (np.cross has ~10 us of overhead per call)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


class StanceBalance:
    """Writes balance feed-forward torques into the servo of one ``character`` tracking
    ``reference`` from clip time ``start``; use it after a PD tracker of the same character.

    A foot supports when it touches the floor in the simulation *and* is planted in the mocap
    at that time (sole within ``reach`` m of the floor, moving slower than 0.6 m/s): the
    mocap's contact timing keeps a swing foot that brushes the floor from taking weight.

    Args:
        kp_com, kv_com: horizontal COM servo gains (1/s^2, 1/s); kp_height for the vertical.
        kp_rot, kv_rot: trunk orientation gains (1/s^2, 1/s).
        friction: fraction of the friction cone the horizontal support force may use.
        stance_gain_scale: servo stiffness multiplier (damping by its square root) for the
            hip, knee and ankle of a supporting leg: their inertia-scaled gains follow a thigh,
            shin or foot, while the load is the whole body (a landing knee buckled ~30 deg).
        velocity_feedforward: add ``kv I w_d`` so the servo damps toward the mocap's joint
            velocity instead of toward rest.
    """

    def __init__(
        self,
        world: World,
        character: int,
        reference: Motion | ReferencePath,
        start: float = 0.0,
        *,
        kp_com: float = 100.0,
        kv_com: float | None = None,
        kp_height: float = 25.0,
        kp_rot: float = 200.0,
        kv_rot: float | None = None,
        friction: float = 0.7,
        reach: float = 0.02,
        velocity_feedforward: bool = True,
        stance_gain_scale: float = 16.0,
        control_every: int,
    ) -> None:
        check_character(world, character)
        check_params(
            {
                "kp_com": kp_com, "kv_com": kv_com, "kp_height": kp_height, "kp_rot": kp_rot,
                "kv_rot": kv_rot, "friction": friction, "reach": reach,
                "stance_gain_scale": stance_gain_scale,
            },
        )  # fmt: skip
        if stance_gain_scale <= 0:
            raise ConfigError(f"stance_gain_scale must be > 0, got {stance_gain_scale!r}")
        servo = world.servo
        self.servo = servo
        self.world = world
        self.character = character
        self.control_every = int(control_every)
        kv_h = critical_kv(kp_com) if kv_com is None else float(kv_com)
        self.kp = np.array([kp_com, kp_com, kp_height], dtype=np.float64)
        self.kv = np.array([kv_h, kv_h, critical_kv(kp_height)])
        self.kp_rot = float(kp_rot)
        self.kv_rot = critical_kv(kp_rot) if kv_rot is None else float(kv_rot)
        self.friction = float(friction)
        self.reach = float(reach)
        self.velocity_feedforward = velocity_feedforward
        self.stance_gain_scale = float(stance_gain_scale)
        self._legs = [[f"{s}_hip", f"{s}_knee", f"{s}_ankle"] for s in "lr"]
        self._stance: tuple[int, ...] = ()  # supporting feet at the last tick
        m = world.model
        wc = world.characters[character]
        self.wc = wc
        self.root = int(wc.body_ids[0])
        self.mass = float(m.body_subtreemass[self.root])
        self.gravity = -np.asarray(m.opt.gravity, dtype=np.float64)  # support per kg
        self.feet, self.sole, self._corners = foot_soles(world, character, "StanceBalance")
        self.floor_geoms = np.flatnonzero(m.geom_bodyid == 0)
        self.mu = float(world.config.friction)
        rows = character * NJ
        self._ff = servo.feedforward[rows : rows + NJ].reshape(-1)  # (45,) view
        self._dofs = slice(wc.ball_dof_start, wc.ball_dof_start + 3 * NJ)
        self._jacp = np.zeros((3, m.nv))
        self._jacr = np.zeros((3, m.nv))
        self._child = np.asarray(wc.body_ids[1:])
        self._balls = np.array([m.joint(wc.prefix + j).id for j in BALL_JOINTS])
        if np.any(self.gravity[:2]):
            raise ConfigError("StanceBalance assumes vertical gravity")
        self._weight = m.body_subtreemass[self._child] * self.gravity[2]  # (15,) N
        self._tau = np.zeros((NJ, 3))
        self._tau_local = np.empty((NJ, 3))
        path = as_path(world, character, reference)
        self.clock = path.clock(start)
        self._reference(path)

    def hold(self, t: float) -> None:
        """From rollout time ``t`` on, follow the reference's pose at ``t``."""
        self.clock = self.clock.held_from(t)

    def reset(self, world: World) -> None:
        del world
        self._stance = ()

    def _reference(self, path: ReferencePath) -> None:
        """Mocap COM (position, velocity, acceleration), pelvis orientation, foot stance and
        joint velocities per frame."""
        m = self.world.model
        d = mujoco.MjData(m)
        q = path.q
        n = path.num_frames
        com = np.empty((n, 3))
        sole = np.empty((n, 2))
        foot = np.empty((n, 2, 3))
        for i in range(n):  # once per clip, not in the step loop
            d.qpos[self.wc.qpos_slice] = q[i]
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            com[i] = d.subtree_com[self.root]
            sole[i] = sole_corners_world(d, self.sole, self._corners)[:, :, 2].min(axis=1)
            foot[i] = d.xpos[self.feet]
        h = 1.0 / path.fps
        grad = (lambda a: np.gradient(a, h, axis=0)) if n > 2 else (lambda a: 0.0 * a)
        self.com = com
        self.com_vel = grad(com)
        self.com_acc = grad(self.com_vel)
        speed = np.linalg.norm(grad(foot), axis=-1)
        self.planted = (sole < self.reach) & (speed < 0.6)  # (n, 2)
        self.root_quat = q[:, 3:7]
        # the velocity of each frame-to-frame segment (the targets interpolate linearly)
        seg = qvel_between(q[:-1], q[1:], np.full(max(n - 1, 0), 1.0 / path.fps))
        self.joint_vel = (
            np.concatenate([seg, seg[-1:]])[:, 6:].reshape(n, NJ, 3)
            if n > 1
            else (np.zeros((n, NJ, 3)))
        )

    def _sample(self, t: float) -> tuple[F64, F64, F64, F64, NDArray[np.bool_], F64]:
        """Mocap COM position, velocity, acceleration, pelvis rotation, planted feet and
        joint velocities at rollout time ``t``."""
        i0, i1, a = self.clock.bracket(t)
        lerp = lambda arr: (1 - a) * arr[i0] + a * arr[i1]  # noqa: E731
        i = round(i0 + a)
        return (
            lerp(self.com), lerp(self.com_vel), lerp(self.com_acc), self.root_quat[i],
            self.planted[i], self.joint_vel[i0],
        )  # fmt: skip

    def _support_points(self, planted: NDArray[np.bool_]) -> tuple[list[int], list[F64]]:
        """Supporting feet (touching the floor and planted in the mocap) and, for each, where
        its ground force acts: the centre of its floor contacts."""
        d = self.world.data
        feet: list[int] = []
        points: list[F64] = []
        n = d.ncon
        if n == 0:
            return feet, points
        geoms = d.contact.geom[:n]
        floor = np.zeros(n, dtype=bool)
        for g in self.floor_geoms:  # the floor plane: one geom
            floor |= (geoms == g).any(axis=1)
        for k in range(2):
            if not planted[k]:
                continue
            hit = floor & (geoms == self.sole[k]).any(axis=1)
            if not hit.any():  # an ankle torque on a foot in the air only spins the foot
                continue
            p = d.contact.pos[:n][hit].mean(axis=0)
            feet.append(k)
            points.append(p)
        return feet, points

    def control(self, world: World, t: float) -> None:
        m, d = world.model, world.data
        ff = self._ff
        # gravity compensation: the torque that holds each joint's subtree up,
        # (subtree com - anchor) x (m g_up), in the child frame. Not qfrc_bias: its Coriolis
        # part, held between control ticks, destabilised light feet.
        r = d.subtree_com[self._child] - d.xanchor[self._balls]
        rot = d.xmat[self._child].reshape(NJ, 3, 3)
        # r x (0, 0, w) = (r_y w, -r_x w, 0); np.cross costs 40 us here
        np.multiply(r[:, 1], self._weight, out=self._tau[:, 0])
        np.multiply(r[:, 0], -self._weight, out=self._tau[:, 1])
        np.einsum("nji,nj->ni", rot, self._tau, out=self._tau_local)
        ff[:] = self._tau_local.reshape(-1)
        c_d, v_d, a_d, q_d, planted, wd = self._sample(t)
        if self.velocity_feedforward:
            inertia = self.servo.joint_inertia(self.character)
            ff += (
                self.servo.gains(self.character)[1] * np.einsum("nij,nj->ni", inertia, wd)
            ).reshape(-1)
        feet, points = self._support_points(planted)
        if tuple(feet) != self._stance and self.stance_gain_scale != 1.0:
            for k, leg in enumerate(self._legs):
                scale = self.stance_gain_scale if k in feet else 1.0
                self.servo.set_gain_scale(self.character, leg, scale)
        self._stance = tuple(feet)
        if not feet:
            return
        mujoco.mj_subtreeVel(m, d)
        c = d.subtree_com[self.root]
        v = d.subtree_linvel[self.root]
        force = self.mass * (self.gravity + a_d + self.kp * (c_d - c) + self.kv * (v_d - v))
        force[2] = max(force[2], 0.0)
        q = d.xquat[self.root]
        e_world = d.xmat[self.root].reshape(3, 3) @ quat_log(quat_mul(quat_conj(q), q_d))
        w = d.cvel[self.root, :3]  # world-frame angular velocity of the pelvis
        trunk_inertia = 0.1 * self.mass  # scale of the body's inertia about the pelvis (kg m^2)
        torque = trunk_inertia * (self.kp_rot * e_world - self.kv_rot * w)
        # split between two supporting feet by where the COM lies between them
        if len(feet) == 2:
            a, b = points[0][:2], points[1][:2]
            ab = b - a
            s = float(np.clip(np.dot(c[:2] - a, ab) / max(np.dot(ab, ab), 1e-9), 0.0, 1.0))
            shares: tuple[float, ...] = (1.0 - s, s)
        else:
            shares = (1.0,)
        forces = []
        for share in shares:
            f = share * force
            fh = float(np.hypot(f[0], f[1]))
            lim = self.friction * self.mu * f[2]
            if fh > lim:
                f[:2] *= lim / fh
            forces.append(f)
        # centroidal balance: the feet's moments make up what the forces' moments about the
        # COM lack, so the net wrench turns the body as asked and no more
        moment = torque.copy()
        for p, f in zip(points, forces, strict=True):
            moment -= _cross(p - c, f)
        jp, jr = self._jacp, self._jacr
        for k, p, f, share in zip(feet, points, forces, shares, strict=True):
            # what the sole can pass on: the centre of pressure stays on the sole (about its
            # axes: roll <= Fz * half width, pitch <= Fz * half length), twist by friction
            g = self.sole[k]
            rot = d.geom_xmat[g].reshape(3, 3)
            half = m.geom_size[g]
            lim = f[2] * np.array([half[1], half[0], self.mu * 0.5 * half[1]])
            t_local = np.clip(rot.T @ (share * moment), -lim, lim)
            mujoco.mj_jac(m, d, jp, jr, p, int(self.feet[k]))
            ff -= jp[:, self._dofs].T @ f + jr[:, self._dofs].T @ (rot @ t_local)
