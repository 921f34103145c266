"""Inertia-scaled PD servo for every ball joint (Zordan & Hodgins 2002; Zordan et al. 2005):

    tau = I (kp * e - kv * qdot),   e = log(q^-1 q_d)  (rotation vector, child frame)

``I`` is the 3x3 diagonal block of MuJoCo's joint-space inertia matrix for the ball joint: the
composite inertia of everything outboard of the joint about the joint, in the joint's frame,
which is what the papers mean by "the inertia of the outboard body". One ``kp`` and one ``kv``
for all joints; per-joint gains exist only for :meth:`PDServo.freeze` (Deva's spring-damper
clamp) and for switching joints off.

Cost, and how it is kept low (measured with ``benchmarks/bench_sim.py``): the torque is
computed for all joints of all characters at once with preallocated buffers and numpy ufuncs
writing into them (``out=``), no Python loop over joints and no allocation per step:

* the target enters through a precomputed 4x4 matrix per joint, so ``q^-1 q_d`` for all joints
  is one batched ``matmul``;
* the log is ``v * atan2(|v|, |w|) / |v|`` with the sign of ``w`` (shortest arc); clamping
  ``|v|`` to 1e-12 gives the right small-angle limit with no branch;
* ``I`` is gathered from MuJoCo's sparse ``d.M`` with one ``np.take`` over precomputed CSR
  indices, refreshed every ``inertia_every`` steps (``d.M`` is from the step's start, so it
  lags by one step; an inertia that changes by a fraction of a percent per 0.5 ms).

About 17 numpy calls per step remain; each costs ~0.5 us on 2-joint-batch sized arrays, so the
servo costs roughly a fifth of one mj_step of a standing character.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, SimulationError, UnknownKeyError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_normalize
from reactmocap.sim.character import BALL_JOINTS
from reactmocap.sim.world import World

__all__ = ["PDServo", "critical_kv"]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)


def critical_kv(kp: float) -> float:
    """kv giving critical damping for ``kp`` on an isolated joint (``kv = 2 sqrt(kp)``):
    with tau = I (kp e - kv qdot) each joint behaves as a unit-mass oscillator."""
    return 2.0 * float(np.sqrt(kp))


def _right_matrix(qd: F64) -> F64:
    """``(n, 4, 4)`` matrices ``R`` with ``conj(q) * qd == R @ q`` (Hamilton product)."""
    w, x, y, z = qd[:, 0], qd[:, 1], qd[:, 2], qd[:, 3]
    # right-multiplication matrix of qd: a * qd = Rq(qd) @ a
    rq = np.stack(
        [
            np.stack([w, -x, -y, -z], -1),
            np.stack([x, w, z, -y], -1),
            np.stack([y, -z, w, x], -1),
            np.stack([z, y, -x, w], -1),
        ],
        axis=1,
    )
    return rq * np.array([1.0, -1.0, -1.0, -1.0])  # conj(q) = diag(1,-1,-1,-1) q


class PDServo:
    """PD servo over the ball joints of some (default: all) characters of a World.

    Args:
        world: the world.
        kp: stiffness (1/s^2); kv: damping (1/s). Defaults: kp 900, kv critical (60).
        characters: indices of the characters to actuate (default all).
        torque_limit: optional per-DOF torque limit (N m), scalar.
        inertia_every: refresh ``I`` every this many steps (1 = every step).
    """

    def __init__(
        self,
        world: World,
        kp: float = 900.0,
        kv: float | None = None,
        characters: Sequence[int] | None = None,
        torque_limit: float | None = None,
        inertia_every: int = 1,
    ) -> None:
        self.world = world
        idx = list(range(len(world.characters))) if characters is None else list(characters)
        for i in idx:
            if not 0 <= i < len(world.characters):
                raise ConfigError(f"character index {i} outside 0..{len(world.characters) - 1}")
        self.character_indices = tuple(idx)
        n = NJ * len(idx)
        self.n = n
        m = world.model
        qidx, didx = [], []
        for i in idx:
            wc = world.characters[i]
            qidx.append(wc.ball_qpos_start + np.arange(4 * NJ))
            didx.append(wc.ball_dof_start + np.arange(3 * NJ))
        self._qidx = np.concatenate(qidx).astype(np.intp)
        self._didx = np.concatenate(didx).astype(np.intp)
        # CSR positions of every (row, col) of each 3x3 diagonal block (lower triangle mirrored)
        midx = np.empty((n, 3, 3), dtype=np.intp)
        dofs = self._didx.reshape(n, 3)
        for k in range(n):
            for a in range(3):
                for b in range(3):
                    r, c = dofs[k, max(a, b)], dofs[k, min(a, b)]
                    start = m.M_rowadr[r]
                    cols = m.M_colind[start : start + m.M_rownnz[r]]
                    hit = np.flatnonzero(cols == c)
                    if hit.size != 1:
                        raise SimulationError("unexpected sparsity of MuJoCo's mass matrix")
                    midx[k, a, b] = start + hit[0]
        self._midx = midx
        # buffers
        self._q = np.empty((n, 4))
        self._qd = np.empty((n, 3))
        self._r = np.empty((n, 4, 1))
        self._s = np.empty(n)
        self._aw = np.empty(n)
        self._e = np.empty((n, 3))
        self._tmp = np.empty((n, 3))
        self._tau = np.empty((n, 3, 1))
        self._inertia = np.empty((n, 3, 3))
        self._rd = np.empty((n, 4, 4))
        self.targets = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
        self._kpcol = np.empty((n, 1))
        self._kvcol = np.empty((n, 1))
        self._enabled = np.ones(n, dtype=bool)
        self._frozen = np.zeros(n, dtype=bool)
        self.freeze_scale = 4.0
        self.torque_limit = torque_limit
        if inertia_every < 1:
            raise ConfigError(f"inertia_every must be >= 1, got {inertia_every}")
        self.inertia_every = int(inertia_every)
        self._count = 0
        self.set_gains(kp, critical_kv(kp) if kv is None else kv)
        self.set_targets_to_current()
        self.update_inertia()

    # ------------------------------------------------------------------ configuration
    def set_gains(self, kp: float, kv: float) -> None:
        if not (np.isfinite(kp) and np.isfinite(kv) and kp >= 0 and kv >= 0):
            raise ConfigError(f"kp and kv must be finite and >= 0, got kp={kp!r}, kv={kv!r}")
        self.kp = float(kp)
        self.kv = float(kv)
        self._refresh_gains()

    def _refresh_gains(self) -> None:
        scale = np.where(self._frozen, self.freeze_scale, 1.0)
        on = self._enabled | self._frozen
        # 2 * kp: the servo computes half the rotation vector (see apply)
        self._kpcol[:, 0] = np.where(on, 2.0 * self.kp * scale, 0.0)
        self._kvcol[:, 0] = np.where(on, self.kv * np.sqrt(scale), 0.0)

    def _rows(self, character: int, joints: Sequence[str] | None) -> NDArray[np.intp]:
        if character not in self.character_indices:
            raise ConfigError(
                f"character {character} is not driven by this servo {self.character_indices}"
            )
        base = self.character_indices.index(character) * NJ
        if joints is None:
            return np.arange(base, base + NJ)
        rows = []
        for j in joints:
            if j not in BALL_JOINTS:
                raise UnknownKeyError(f"unknown joint {j!r}; ball joints are {list(BALL_JOINTS)}")
            rows.append(base + BALL_JOINTS.index(j))
        return np.array(rows, dtype=np.intp)

    def enable(self, character: int, joints: Sequence[str] | None = None, on: bool = True) -> None:
        """Switch the servo on or off for some joints (off = passive, ragdoll)."""
        self._enabled[self._rows(character, joints)] = on
        self._refresh_gains()

    def freeze(self, character: int, joints: Sequence[str] | None = None) -> None:
        """Deva's freeze: clamp the joints at their current rotation with a spring-damper
        (``freeze_scale`` times the servo's stiffness, damping scaled to stay critical)."""
        rows = self._rows(character, joints)
        q = quat_normalize(self.world.data.qpos[self._qidx].reshape(self.n, 4)[rows])
        self.targets[rows] = q
        self._rd[rows] = _right_matrix(q)
        self._frozen[rows] = True
        self._refresh_gains()

    def unfreeze(self, character: int, joints: Sequence[str] | None = None) -> None:
        self._frozen[self._rows(character, joints)] = False
        self._refresh_gains()

    @property
    def frozen(self) -> NDArray[np.bool_]:
        return self._frozen.copy()

    # ------------------------------------------------------------------ targets
    def set_targets(self, character: int, quats: F64) -> None:
        """Desired local rotations ``(15, 4)`` (wxyz, MuJoCo ball order) of one character.
        Frozen joints keep their clamp targets."""
        rows = self._rows(character, None)
        q = np.asarray(quats, dtype=np.float64).reshape(NJ, 4)
        if not np.all(np.isfinite(q)):
            raise SimulationError("PD targets contain NaN or inf")
        q = quat_normalize(q)
        keep = self._frozen[rows]
        q = np.where(keep[:, None], self.targets[rows], q)
        self.targets[rows] = q
        self._rd[rows] = _right_matrix(q)

    def set_targets_from_qpos(self, character: int, qpos: F64) -> None:
        self.set_targets(character, np.asarray(qpos)[7:].reshape(NJ, 4))

    def set_targets_from_motion(self, character: int, motion: Motion, frame: int) -> None:
        ch = self.world.characters[character].character
        self.set_targets_from_qpos(character, ch.qpos_from_motion(motion, [frame])[0])

    def set_targets_to_current(self) -> None:
        q = quat_normalize(self.world.data.qpos[self._qidx].reshape(self.n, 4))
        q = np.where(self._frozen[:, None], self.targets, q)
        self.targets[:] = q
        self._rd[:] = _right_matrix(q)

    # ------------------------------------------------------------------ per step
    def update_inertia(self) -> None:
        np.take(self.world.data.M, self._midx, out=self._inertia)

    def inertia(self) -> F64:
        """``(n, 3, 3)`` current inertia blocks (copy)."""
        return self._inertia.copy()

    def compute(self) -> F64:
        """Torques ``(n, 3)`` for the current state (no side effects on MuJoCo). Vectorised."""
        d = self.world.data
        if self._count % self.inertia_every == 0:
            np.take(d.M, self._midx, out=self._inertia)
        self._count += 1
        q = self._q
        np.take(d.qpos, self._qidx, out=q.reshape(-1))
        np.take(d.qvel, self._didx, out=self._qd.reshape(-1))
        r = self._r
        np.matmul(self._rd, q[:, :, None], out=r)  # conj(q) * q_d
        v = r[:, 1:, 0]
        w = r[:, 0, 0]
        s = self._s
        np.multiply(v, v, out=self._tmp)
        np.add.reduce(self._tmp, axis=1, out=s)
        np.sqrt(s, out=s)
        np.maximum(s, 1e-12, out=s)
        np.abs(w, out=self._aw)
        np.arctan2(s, self._aw, out=self._aw)  # half angle
        np.divide(self._aw, s, out=s)
        np.copysign(s, w, out=s)  # shortest arc
        e = self._e
        np.multiply(v, s[:, None], out=e)  # half rotation vector
        np.multiply(e, self._kpcol, out=e)  # (2 kp) * e/2
        np.multiply(self._qd, self._kvcol, out=self._tmp)
        np.subtract(e, self._tmp, out=e)
        np.matmul(self._inertia, e[:, :, None], out=self._tau)
        if self.torque_limit is not None:
            np.clip(self._tau, -self.torque_limit, self.torque_limit, out=self._tau)
        return self._tau[:, :, 0]

    def apply(self) -> None:
        """Compute and write the torques into ``qfrc_applied`` (the ball DOFs it owns)."""
        tau = self.compute()
        self.world.data.qfrc_applied[self._didx] = tau.reshape(-1)

    def clear(self) -> None:
        self.world.data.qfrc_applied[self._didx] = 0.0

    def pose_error(self) -> F64:
        """``(n,)`` current angle (rad) between each joint and its target."""
        d = self.world.data
        q = quat_normalize(d.qpos[self._qidx].reshape(self.n, 4))
        r = np.matmul(self._rd, q[:, :, None])[:, :, 0]
        return 2.0 * np.arctan2(np.linalg.norm(r[:, 1:], axis=1), np.abs(r[:, 0]))


def step_with_servo(world: World, servo: PDServo | None, nstep: int) -> None:
    """Step ``nstep`` times, applying the servo before each step."""
    m, d = world.model, world.data
    if servo is None:
        mujoco.mj_step(m, d, nstep=nstep)
        return
    for _ in range(nstep):
        servo.apply()
        mujoco.mj_step(m, d)
