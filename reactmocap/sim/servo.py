"""The inertia-scaled PD servo over every ball joint (Zordan & Hodgins 2002; Zordan et al. 2005),
``tau = I (kp e - kv qdot)`` with ``I`` the outboard inertia block of the joint and
``e = log(q^-1 q_d)``, run inside MuJoCo as the World's servo actuators so that a rollout steps
``mj_step(nstep=k)`` between control ticks. Each World has at most one servo
(:attr:`World.servo`); controllers set its targets, gains and feed-forward. Why it is built this
way (actuator gears from a Cholesky factor, implicit damping, half turns): ``docs/design.md``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, SimulationError, UnknownKeyError
from reactmocap.rotations import einsum, quat_log, quat_normalize
from reactmocap.sim.character import BALL_JOINTS
from reactmocap.sim.world import World

__all__ = ["PDServo", "critical_kv"]


def _cholesky_public(a: NDArray[np.float64], signature: str, out: NDArray[np.float64]) -> None:
    """np.linalg.cholesky into ``out``, NaN where a block is not positive definite: the
    fallback for a numpy without the private gufunc below (the same values)."""
    try:
        out[...] = np.linalg.cholesky(a)
    except np.linalg.LinAlgError:
        out.fill(np.nan)


# np.linalg.cholesky's own LAPACK gufunc without its wrapper (half the cost); a private name,
# so a numpy that moves it gets the public call
_cholesky_lo: Callable[..., object]
try:
    from numpy.linalg import _umath_linalg  # type: ignore[attr-defined]

    _cholesky_lo = _umath_linalg.cholesky_lo
except (ImportError, AttributeError):
    _cholesky_lo = _cholesky_public

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)


def critical_kv(kp: float) -> float:
    """kv giving critical damping for ``kp`` on an isolated joint (``kv = 2 sqrt(kp)``):
    with tau = I (kp e - kv qdot) each joint behaves as a unit-mass oscillator."""
    return 2.0 * float(np.sqrt(kp))


# conj(q) * qd == R @ q with R[i, j] = _RSIGN[i, j] * qd[_RIDX[i, j]] (Hamilton product)
_RIDX = np.array([[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]])
_RSIGN = np.array(
    [[1.0, 1.0, 1.0, 1.0], [1.0, -1.0, -1.0, 1.0], [1.0, 1.0, -1.0, -1.0], [1.0, -1.0, 1.0, -1.0]]
)
#: joints closer than this (rad) to a half turn get their stiffness as a held torque (see above)
HALF_TURN_MARGIN = 0.4


def _right_matrix(qd: F64) -> F64:
    """``(n, 4, 4)`` matrices ``R`` with ``conj(q) * qd == R @ q`` (Hamilton product)."""
    return qd[:, _RIDX] * _RSIGN


class PDServo:
    """The PD servo of a World's characters, run by the World's servo actuators. A World has at
    most one: use :attr:`World.servo`, which makes it on first use (constructing one directly
    registers it as the World's).

    Args:
        world: the world.
        kp: stiffness (1/s^2) of every joint; kv: damping (1/s; ``None``: critical). Both 0 by
            default: the servo is inert until a controller sets gains (:meth:`set_gains`).
        torque_limit: optional torque limit (N m) per actuator axis, scalar.
        refresh_every: re-linearise (inertia, rotation vectors, gears, ``ctrl``) at least every
            this many steps; also before the first step after new targets, gains or state.

    Step with :meth:`step` (``mj_step(nstep=...)`` between refreshes), or call :meth:`apply`
    before each single ``mj_step``.
    """

    def __init__(
        self,
        world: World,
        kp: float = 0.0,
        kv: float | None = None,
        torque_limit: float | None = None,
        refresh_every: int = 4,
    ) -> None:
        if world.has_servo:
            raise ConfigError("this World already has a servo: use world.servo")
        self.world = world
        idx = list(range(len(world.characters)))
        self.character_indices = tuple(idx)
        n = NJ * len(idx)
        self.n = n
        m, d = world.model, world.data
        qidx, didx, aidx = [], [], []
        for i in idx:
            wc = world.characters[i]
            qidx.append(wc.ball_qpos_start + np.arange(4 * NJ))
            didx.append(wc.ball_dof_start + np.arange(3 * NJ))
            aidx.append(wc.actuator_adr + np.arange(3 * NJ))
        self._qidx = np.concatenate(qidx).astype(np.intp)
        self._didx = np.concatenate(didx).astype(np.intp)
        self._aidx = np.concatenate(aidx).astype(np.intp)
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
        # views on the actuators' gears and controls: (n, 3, 3) rows = gear of actuator k,
        # (n, 3, 1) controls; contiguous for the usual (sorted) character lists
        a0 = int(self._aidx[0])
        self._contiguous = bool(np.array_equal(self._aidx, np.arange(a0, a0 + 3 * n)))
        if self._contiguous:
            self._gear = m.actuator_gear[a0 : a0 + 3 * n, :3].reshape(n, 3, 3)
            self._ctrl = d.ctrl[a0 : a0 + 3 * n].reshape(n, 3, 1)
            if not (
                np.shares_memory(self._gear, m.actuator_gear)
                and np.shares_memory(self._ctrl, d.ctrl)
            ):
                raise SimulationError("actuator views are copies (internal error)")
        else:
            self._gear = np.empty((n, 3, 3))
            self._ctrl = np.empty((n, 3, 1))
        # buffers, and views on them made once (a refresh is ~20 numpy calls on 15-30 rows,
        # where Python-level slicing would cost a quarter of the time): rows [0, n) of the
        # quaternion buffer hold the joint rotations q0, rows [n, 2n) conj(q0) * q_d
        q = np.empty((2 * n, 4))
        self._q0_flat, self._q0_col, self._p_col = q[:n].reshape(-1), q[:n, :, None], q[n:, :, None]
        self._v, self._w = q[:, 1:], q[:, 0]
        self._v0, self._v1, self._v2 = q[:, 1], q[:, 2], q[:, 3]
        self._s = np.empty(2 * n)
        self._half = np.empty(2 * n)
        self._half0 = self._half[:n]
        self._f = np.empty(2 * n)
        self._f_col = self._f[:, None]
        x = np.empty((2 * n, 3))  # half rotation vectors r0 / 2 and e0 / 2
        self._x, self._x0, self._x1 = x, x[:n], x[n:]
        self._sum = np.empty((n, 3, 1))
        self._sum_flat = self._sum[:, :, 0]
        self._inertia = np.empty((n, 3, 3))
        # the Cholesky factors L, and views made once: L^T (row k: column l_k of L), and the
        # last entry of each, NaN where LAPACK found a block not positive definite
        self._chol = np.empty((n, 3, 3))
        self._chol_t = self._chol.transpose(0, 2, 1)
        self._chol_last = self._chol[:, 2, 2]
        # MjData's arrays read at every refresh (the World keeps one MjData), and
        # qfrc_applied's rows of the servo's DOFs as a view
        self._mjM, self._mjqpos = d.M, d.qpos
        d0 = int(self._didx[0])
        self._qfrc = (
            d.qfrc_applied[d0 : d0 + 3 * n]
            if np.array_equal(self._didx, np.arange(d0, d0 + 3 * n))
            else None
        )
        self._any_hot = False
        self.targets = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
        # set_targets' buffers: one character's target lengths and right-matrix entries
        self._len = np.empty(NJ)
        self._len_col = self._len[:, None]
        self._rd_entries = np.empty((NJ, 4, 4))
        self._rd = _right_matrix(self.targets)
        #: extra joint torques (N m, child frame) added to the servo's output, e.g. gravity
        #: compensation or a balance controller's; ``(n, 3)``, written in place by controllers
        #: and copied into ``qfrc_applied`` at each refresh
        self.feedforward = np.zeros((n, 3))
        self._kp_base = np.zeros(n)  # per-joint gains as set
        self._kv_base = np.zeros(n)
        self._kp = np.zeros(n)  # per-joint effective gains (frozen, off)
        self._kv = np.zeros(n)
        self._enabled = np.ones(n, dtype=bool)
        self._frozen = np.zeros(n, dtype=bool)
        self._gain_scale = np.ones(n)
        self._hot = np.zeros(n, dtype=bool)  # near a half turn: stiffness held in qfrc_applied
        # per-axis gains (set_axis_gains): each joint's gears are shaped by S = A^T diag(sqrt(g))
        # A, so its torque is S I S (kp e - kv qdot); identity (exactly) where no axis is scaled
        self._shape = np.tile(np.eye(3), (n, 1, 1))
        self._shaped = np.zeros(n, dtype=bool)
        self._any_shaped = False
        self._shape_tmp = np.empty((NJ, 3, 3))
        self._shape_root = np.empty((NJ, 3))
        self._shape_less = np.empty((NJ, 3), dtype=bool)
        self._eye = np.eye(3)
        self._lts = np.empty((n, 3, 3))
        self.freeze_scale = 4.0
        if torque_limit is not None and not (np.isfinite(torque_limit) and torque_limit > 0):
            raise ConfigError(f"torque_limit must be a positive number, got {torque_limit!r}")
        self.torque_limit = torque_limit
        # Euler integrates only joint damping implicitly: there the damping's diagonal goes to
        # dof_damping at each refresh (the former scheme); implicit(fast) takes the full 3x3
        self._diag_damping = m.opt.integrator == int(mujoco.mjtIntegrator.mjINT_EULER)
        self._base_damping = m.dof_damping[self._didx].copy()
        m.actuator_forcelimited[self._aidx] = torque_limit is not None
        m.opt.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)  # World: off until now
        if refresh_every < 1:
            raise ConfigError(f"refresh_every must be >= 1, got {refresh_every}")
        self.refresh_every = int(refresh_every)
        self._since = 0  # steps since the last refresh
        self._dirty = True
        self._epoch = world.state_epoch
        self.set_gains(kp, kv)
        self.set_targets_to_current()
        world.attach_servo(self)

    # ------------------------------------------------------------------ configuration
    def set_gains(self, kp: float, kv: float | None = None, character: int | None = None) -> None:
        """Stiffness ``kp`` (1/s^2) and damping ``kv`` (1/s; ``None``: critical) of one
        character's joints, or of every character's."""
        kv = critical_kv(kp) if kv is None else kv
        if not (np.isfinite(kp) and np.isfinite(kv) and kp >= 0 and kv >= 0):
            raise ConfigError(f"kp and kv must be finite and >= 0, got kp={kp!r}, kv={kv!r}")
        rows = slice(None) if character is None else self._rows(character, None)
        self._kp_base[rows] = float(kp)
        self._kv_base[rows] = float(kv)
        self._refresh_gains()

    def gains(self, character: int) -> tuple[float, float]:
        """``(kp, kv)`` last set for ``character`` (before gain scales, freezes and switches)."""
        row = int(self._rows(character, None)[0])
        return float(self._kp_base[row]), float(self._kv_base[row])

    def set_gain_scale(self, character: int, joints: Sequence[str] | None, scale: float) -> None:
        """Multiply kp by ``scale`` (and kv by its square root, staying critical) for some
        joints, e.g. a stance leg that carries the body on gains scaled by a foot's inertia."""
        if not (np.isfinite(scale) and scale > 0):
            raise ConfigError(f"gain scale must be a positive number, got {scale!r}")
        rows = self._rows(character, joints)
        if np.all(self._gain_scale[rows] == scale):
            return
        self._gain_scale[rows] = scale
        self._refresh_gains()

    def set_gain_scales(
        self, character: int, scales: F64, enabled: NDArray[np.bool_] | None = None
    ) -> None:
        """:meth:`set_gain_scale` for each of one character's joints at once, ``scales``
        ``(15,)``; NaN keeps a joint's scale. One gain refresh rather than one per joint.
        ``enabled`` ``(15,)``: also switch each joint on or off, as :meth:`enable` does (it
        refreshes then, changed or not, as :meth:`enable`), in the same refresh."""
        scales = np.asarray(scales, dtype=np.float64)
        keep = np.isnan(scales)
        if scales.shape != (NJ,) or not np.all(keep | (np.isfinite(scales) & (scales > 0))):
            raise ConfigError(f"gain scales must be ({NJ},) positive numbers or NaN")
        if enabled is not None and np.shape(enabled) != (NJ,):
            raise ConfigError(f"enabled must be ({NJ},) bools, got shape {np.shape(enabled)}")
        rows = self._rows(character, None)
        old = self._gain_scale[rows]
        new = np.where(keep, old, scales)
        if enabled is None and np.array_equal(new, old):
            return
        if enabled is not None:
            self._enabled[rows] = enabled
        self._gain_scale[rows] = new
        self._refresh_gains()

    def _refresh_gains(self) -> None:
        scale = np.where(self._frozen, self.freeze_scale, 1.0) * self._gain_scale
        on = self._enabled | self._frozen
        self._kp[:] = np.where(on, self._kp_base * scale, 0.0)
        self._kv[:] = np.where(on, self._kv_base * np.sqrt(scale), 0.0)
        self._write_gains()
        self._dirty = True

    def _write_gains(self) -> None:
        """Actuator gains from the per-joint gains; half-turn joints keep only the damping.
        ``bias[1] = -gain`` exactly: MuJoCo then treats the actuator as a position servo."""
        m = self.world.model
        gain = np.repeat(np.where(self._hot, 0.0, self._kp), 3)
        m.actuator_gainprm[self._aidx, 0] = gain
        m.actuator_biasprm[self._aidx, 0] = 0.0
        m.actuator_biasprm[self._aidx, 1] = -gain
        m.actuator_biasprm[self._aidx, 2] = 0.0 if self._diag_damping else -np.repeat(self._kv, 3)

    def set_axis_gains(self, character: int, axes: F64, scale: F64) -> None:
        """Per-axis gains of one character's joints: ``axes`` ``(15, 3, 3)`` (row ``i`` of
        joint ``j``: a unit axis in the child frame, rows orthonormal), ``scale`` ``(15, 3)``
        in [0, 1] the share of the joint's stiffness and damping left about each axis (0: the
        axis is free, e.g. a stance knee's bending that a controller drives by torque alone).
        Each tick without allocation; a joint whose scales are all 1 keeps the full servo
        exactly."""
        if scale.shape != (NJ, 3) or not (scale.min() >= 0.0 and scale.max() <= 1.0):
            raise ConfigError(f"axis gain scales must be ({NJ}, 3) values in [0, 1]")
        if axes.shape != (NJ, 3, 3):
            raise ConfigError(f"axes must be ({NJ}, 3, 3), got {axes.shape}")
        if character not in self.character_indices:
            raise ConfigError(
                f"character {character} is not driven by this servo {self.character_indices}"
            )
        base = self.character_indices.index(character) * NJ
        sl = slice(base, base + NJ)
        np.less(scale, 1.0, out=self._shape_less)
        np.any(self._shape_less, axis=1, out=self._shaped[sl])
        # S = I + A^T diag(sqrt(g) - 1) A: exactly I where every g is 1
        np.sqrt(scale, out=self._shape_root)
        self._shape_root -= 1.0
        np.multiply(axes, self._shape_root[:, :, None], out=self._shape_tmp)
        np.matmul(axes.transpose(0, 2, 1), self._shape_tmp, out=self._shape[sl])
        self._shape[sl] += self._eye
        self._any_shaped = bool(self._shaped.any())
        self._dirty = True

    def _base(self, character: int) -> int:
        """The first of one character's rows."""
        if character not in self.character_indices:
            raise ConfigError(
                f"character {character} is not driven by this servo {self.character_indices}"
            )
        return self.character_indices.index(character) * NJ

    def _rows(self, character: int, joints: Sequence[str] | None) -> NDArray[np.intp]:
        base = self._base(character)
        if joints is None:
            return np.arange(base, base + NJ)
        rows = []
        for j in joints:
            if j not in BALL_JOINTS:
                raise UnknownKeyError(f"unknown joint {j!r}; ball joints are {list(BALL_JOINTS)}")
            rows.append(base + BALL_JOINTS.index(j))
        return np.array(rows, dtype=np.intp)

    def enable(self, character: int, joints: Sequence[str] | None = None, on: bool = True) -> None:
        """Switch the servo on or off for some joints (off = passive, ragdoll: zero gain and
        zero damping in their actuators)."""
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
        """``(n,)`` joints clamped by :meth:`freeze`."""
        return self._frozen.copy()

    @property
    def enabled(self) -> NDArray[np.bool_]:
        """``(n,)`` joints the servo drives (not switched off by :meth:`enable`)."""
        return self._enabled.copy()

    @property
    def hot(self) -> NDArray[np.bool_]:
        """``(n,)`` joints near a half turn at the last refresh (stiffness held as a torque)."""
        return self._hot.copy()

    @property
    def dof_indices(self) -> NDArray[np.intp]:
        """``(3 n,)`` the ball-joint DOFs the servo drives, in its joint order."""
        return self._didx.copy()

    @property
    def qpos_indices(self) -> NDArray[np.intp]:
        """``(4 n,)`` the ball-joint quaternion entries of ``qpos``, in its joint order."""
        return self._qidx.copy()

    @property
    def due(self) -> bool:
        """Whether the next step re-linearises first (new targets, gains or state)."""
        return self._due()

    # ------------------------------------------------------------------ targets
    def set_targets(self, character: int, quats: F64) -> None:
        """Desired local rotations ``(15, 4)`` (wxyz, MuJoCo ball order) of one character.
        Frozen joints keep their clamp targets."""
        base = self._base(character)
        sl = slice(base, base + NJ)  # every control tick: no fancy indexing
        q = np.asarray(quats, dtype=np.float64).reshape(NJ, 4)
        # the reductions themselves: ndarray.all/any add a Python call each, every tick
        if not np.logical_and.reduce(np.isfinite(q), axis=None):
            raise SimulationError("PD targets contain NaN or inf")
        # the same operations as q / sqrt(sum q^2) and q[:, _RIDX] * _RSIGN, into buffers
        einsum("ij,ij->i", q, q, out=self._len)
        np.sqrt(self._len, out=self._len)
        keep = self._frozen[sl]
        targets = self.targets[sl]
        if np.logical_or.reduce(keep):
            targets[:] = np.where(keep[:, None], targets, q / self._len_col)
        else:
            np.divide(q, self._len_col, out=targets)
        targets.take(_RIDX, axis=1, out=self._rd_entries)
        np.multiply(self._rd_entries, _RSIGN, out=self._rd[sl])
        self._dirty = True

    def set_targets_to_current(self) -> None:
        q = quat_normalize(self.world.data.qpos[self._qidx].reshape(self.n, 4))
        q = np.where(self._frozen[:, None], self.targets, q)
        self.targets[:] = q
        self._rd[:] = _right_matrix(q)
        self._dirty = True

    # ------------------------------------------------------------------ stepping
    def refresh(self) -> None:
        """Control-rate update: re-linearise the actuators at the current state (inertia
        factor into the gears, rotation vectors into ``ctrl``), copy :attr:`feedforward`
        into ``qfrc_applied``. After it the actuators' torque equals :meth:`torques`."""
        d = self.world.data
        self._mjM.take(self._midx, out=self._inertia)
        # a block that is not positive definite comes back as NaN (quietly: the error below
        # says it)
        with np.errstate(invalid="ignore"):
            _cholesky_lo(self._inertia, signature="d->d", out=self._chol)
        lt = self._chol_t
        total = np.add.reduce(self._chol_last)
        if total != total:  # only a state that diverged since the engine's check
            raise SimulationError(
                f"simulation went unstable at t = {float(d.time):.4f} s: a joint inertia of "
                "the servo is not positive definite"
            )
        self._mjqpos.take(self._qidx, out=self._q0_flat)
        np.matmul(self._rd, self._q0_col, out=self._p_col)  # conj(q0) * q_d
        # both logs at once, as mju_quat2Vel: 2 atan2(|v|, |w|) sign(w) v / |v| (shortest arc)
        s, half, f, w = self._s, self._half, self._f, self._w
        np.hypot(self._v0, self._v1, out=s)
        np.hypot(s, self._v2, out=s)
        np.maximum(s, 1e-300, out=s)
        np.abs(w, out=half)
        np.arctan2(s, half, out=half)  # half angle in [0, pi/2]
        np.divide(half, s, out=f)
        np.copysign(f, w, out=f)
        np.multiply(self._v, self._f_col, out=self._x)
        xs = self._sum
        np.add(self._x0, self._x1, out=self._sum_flat)
        xs *= 2.0  # r0 + e0
        if self._any_shaped:  # the gears shaped per axis: G = L^T S, so G^T G = S I S
            lt = np.matmul(lt, self._shape, out=self._lts)
        np.matmul(lt, xs, out=self._ctrl)
        np.copyto(self._gear, lt)
        if not self._contiguous:
            m = self.world.model
            m.actuator_gear[self._aidx, :3] = self._gear.reshape(-1, 3)
            d.ctrl[self._aidx] = self._ctrl.reshape(-1)
        if self.torque_limit is not None:
            self._set_force_range(lt)
        if self._diag_damping:
            diag = (
                np.einsum("nji,nji->ni", lt, lt)  # diag(G^T G): the shaped inertia's
                if self._any_shaped
                else np.einsum("nii->ni", self._inertia)
            )
            self.world.model.dof_damping[self._didx] = self._base_damping + (
                self._kv[:, None] * diag
            ).reshape(-1)
        if self._qfrc is not None:
            self._qfrc[:] = self.feedforward.reshape(-1)
        else:
            d.qfrc_applied[self._didx] = self.feedforward.reshape(-1)
        if self._any_hot or np.maximum.reduce(self._half0) > 0.5 * (np.pi - HALF_TURN_MARGIN):
            self._half_turns(self._half0 > 0.5 * (np.pi - HALF_TURN_MARGIN), self._x1)
        self._since = 0
        self._dirty = False
        self._epoch = self.world.state_epoch

    def _set_force_range(self, lt: NDArray[np.floating]) -> None:
        assert self.torque_limit is not None
        norm = np.sqrt(np.einsum("nij,nij->ni", lt, lt)).reshape(-1)
        lim = self.torque_limit / np.maximum(norm, 1e-300)
        fr = self.world.model.actuator_forcerange
        fr[self._aidx, 0] = -lim
        fr[self._aidx, 1] = lim

    def _half_turns(self, hot: NDArray[np.bool_], half_e0: F64) -> None:
        """Joints near a half turn: actuator damping only, stiffness ``kp I e0`` held in
        ``qfrc_applied`` until the next refresh."""
        if not np.array_equal(hot, self._hot):
            self._hot[:] = hot
            self._write_gains()
        self._any_hot = bool(hot.any())
        if not self._any_hot:
            return
        rows = np.flatnonzero(hot)
        e0 = 2.0 * half_e0[rows]
        inertia = self._inertia[rows]
        if self._any_shaped:
            shape = self._shape[rows]
            inertia = shape @ inertia @ shape
        tau = self._kp[rows, None] * np.matmul(inertia, e0[:, :, None])[:, :, 0]
        if self.torque_limit is not None:
            np.clip(tau, -self.torque_limit, self.torque_limit, out=tau)
        dofs = self._didx.reshape(self.n, 3)[rows]
        self.world.data.qfrc_applied[dofs] += tau

    def _due(self) -> bool:
        return (
            self._dirty
            or self._since >= self.refresh_every
            or self._epoch != self.world.state_epoch
        )

    def step(self, nstep: int = 1) -> None:
        """Advance ``nstep`` physics steps with the servo on: refresh when due, and
        ``mj_step(m, d, nstep=k)`` in between (bit-identical to single steps)."""
        m, d = self.world.model, self.world.data
        while nstep > 0:
            if self._due():
                self.refresh()
            k = min(nstep, self.refresh_every - self._since)
            mujoco.mj_step(m, d, nstep=k)
            self._since += k
            nstep -= k

    def apply(self) -> None:
        """Compatibility: refresh if due, for a caller that then runs one ``mj_step``."""
        if self._due():
            self.refresh()
        self._since += 1

    def joint_inertia(self, character: int) -> F64:
        """``(15, 3, 3)`` current outboard inertia blocks ``I`` of one character's ball joints
        (from MuJoCo's mass matrix of the last step)."""
        rows = self._rows(character, None)
        return self.world.data.M[self._midx[rows]]

    def torques(self, character: int | None = None) -> F64:
        """``(n, 3)`` full servo torques ``I (kp e - kv qdot)`` at the current state, with the
        exact log and the full 3x3 damping (reference computation; allocates), or ``(15, 3)``
        those of one ``character``. Excludes :attr:`feedforward`."""
        d = self.world.data
        rows = slice(None) if character is None else self._rows(character, None)
        inertia = d.M[self._midx[rows]]
        if self._any_shaped:
            shape = self._shape[rows]
            inertia = shape @ inertia @ shape
        u = -self._kv[rows, None] * d.qvel[self._didx].reshape(self.n, 3)[rows]
        kp = self._kp[rows]
        if kp.any():  # a damping-only servo (the whole-body tracker's) needs no log
            q = quat_normalize(d.qpos[self._qidx].reshape(self.n, 4)[rows])
            u += kp[:, None] * quat_log(np.matmul(self._rd[rows], q[:, :, None])[:, :, 0])
        return np.matmul(inertia, u[:, :, None])[:, :, 0]

    def clear(self) -> None:
        """Remove the servo's torques and damping (the joints go passive) until the next
        refresh, which :meth:`step` and :meth:`apply` do first."""
        d, m = self.world.data, self.world.model
        d.qfrc_applied[self._didx] = 0.0
        m.actuator_gear[self._aidx, :3] = 0.0
        m.dof_damping[self._didx] = self._base_damping
        d.ctrl[self._aidx] = 0.0
        self._dirty = True

    def pose_error(self) -> F64:
        """``(n,)`` current angle (rad) between each joint and its target."""
        d = self.world.data
        q = quat_normalize(d.qpos[self._qidx].reshape(self.n, 4))
        r = np.matmul(self._rd, q[:, :, None])[:, :, 0]
        return 2.0 * np.arctan2(np.linalg.norm(r[:, 1:], axis=1), np.abs(r[:, 0]))
