"""The athletic controllers' actuation layer for one character: anatomical joint angles that move
smoothly (the thesis's Hermite transitions, section 3.2) toward what a controller asks, turned
into the world servo's targets; per-joint stiffness and damping in body units; gravity
compensation, with the stance legs carrying the body, as the servo's feed-forward. Why stiffness
and damping are set this way: ``docs/athletics.md``."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import Athlete
from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.response.blend import smoothstep  # the one Hermite ease; re-exported here
from reactmocap.rotations import einsum, quat_conj, quat_log, quat_mul, quat_rotate
from reactmocap.sim.bodies import BALL_JOINT_INDEX, BALL_JOINTS, SIM_BODIES
from reactmocap.sim.world import World

__all__ = ["JOINT_KINDS", "Rig", "joint_index", "per_joint"]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)
#: joint kinds, each ball joint's kind (both sides share one)
JOINT_KINDS = ("waist", "back", "neck", "shoulder", "elbow", "wrist", "hip", "knee", "ankle")
_KIND = np.array([JOINT_KINDS.index(j[2:] if j[:2] in ("l_", "r_") else j) for j in BALL_JOINTS])
#: the servo's base stiffness (1/s^2); the rig's per-joint scales make the absolute stiffness
SERVO_KP = 1000.0
#: physics steps between the servo's re-linearisations (the controllers' tick, 4 ms)
SERVO_REFRESH = 8


def joint_index(name: str) -> int:
    """Index of a ball joint (``"l_knee"``) in ``BALL_JOINTS``; unknown names list the valid."""
    try:
        return BALL_JOINT_INDEX[name]
    except KeyError:
        raise UnknownKeyError(f"unknown joint {name!r}; joints are {list(BALL_JOINTS)}") from None


def per_joint(values: Mapping[str, float], default: float = 0.0) -> F64:
    """``(15,)`` from values by joint kind (``"knee"``: both knees) or joint (``"l_knee"``);
    a joint's own entry wins over its kind's."""
    out = np.full(NJ, float(default))
    for key, v in values.items():
        if key in JOINT_KINDS:
            out[_KIND == JOINT_KINDS.index(key)] = v
    for key, v in values.items():
        if key not in JOINT_KINDS:
            out[joint_index(key)] = v
    return out


class Rig:
    """Drives one character of ``world`` through the world's servo.

    * **Targets:** anatomical angles ``(15, 3)`` (:class:`~reactmocap.athletics.bodies.Athlete`)
      move from where they are toward a goal along a Hermite curve of a given duration per
      joint (:meth:`move`); :attr:`offset` ``(15, 3)`` is added on top each tick (the balance
      servo's corrections); :meth:`apply` writes the servo's targets.
    * **Stiffness** (:meth:`set_stiffness`) in units of ``m g L`` N m/rad (body mass, leg
      length), turned into the servo's per-joint gain scales with each joint's outboard inertia
      at the moment it is set; the servo's own damping stays critical for that inertia.
    * **Damping** (:meth:`set_damping`) in units of ``m L sqrt(g L)`` N m s/rad goes into
      MuJoCo's joint damping (integrated implicitly): the damping a joint needs when it carries
      the body, which no outboard-inertia-scaled gain gives. :meth:`release` restores the
      model's damping.
    * **Per-axis gains** (:attr:`axis_gain`): a share of each joint's stiffness and damping
      per anatomical axis (the servo's :meth:`~reactmocap.sim.servo.PDServo.set_axis_gains`),
      e.g. a stance knee free in bending, driven by feed-forward, and held in roll and yaw.
    * **Feed-forward** (:meth:`apply`): every joint holds its subtree up against gravity, and
      the legs whose feet carry weight (``support`` shares) push the body's weight into the
      ground through their Jacobians at the ankle (a force through the ankle: the ankle's own
      torque stays the balance servo's, and no feedback runs through the centre of pressure).
    """

    def __init__(self, world: World, athlete: Athlete, character: int = 0) -> None:
        if not 0 <= character < len(world.characters):
            raise ConfigError(f"character {character} is not in the world")
        self.world = world
        self.athlete = athlete
        self.character = character
        m = world.model
        wc = world.characters[character]
        self.wc = wc
        self.servo = world.servo
        self.mass = float(m.body_subtreemass[wc.body_ids[0]])
        g = float(np.linalg.norm(m.opt.gravity))
        length = athlete.leg_length
        self.stiffness_unit = self.mass * g * length
        self.damping_unit = self.mass * length * np.sqrt(g * length)
        self._dofs = np.arange(wc.ball_dof_start, wc.ball_dof_start + 3 * NJ)
        self._base_damping = m.dof_damping[self._dofs].copy()
        self._goal = np.zeros((NJ, 3))
        self._start = np.zeros((NJ, 3))
        self._t0 = np.zeros(NJ)
        self._dur = np.ones(NJ)
        self._jumped: float | None = None  # the time every joint last jumped to its goal
        self._jump_accel = False  # that jump's accelerate
        self._accel = np.zeros(NJ, dtype=bool)  # joints on an accelerating (s^2) path
        self.offset = np.zeros((NJ, 3))
        self.stiffness = np.zeros(NJ)
        self._kp = np.zeros(NJ)  # the servo's kp (1/s^2) per joint, as set_stiffness set it
        self.damping = np.zeros(NJ)
        rows = self.servo.character_indices.index(character) * NJ
        #: this character's rows ``(15, 3)`` of the servo's feed-forward torques (child
        #: frames): gravity compensation, and what the laws add for the step
        self.feedforward = self.servo.feedforward[rows : rows + NJ]
        self._child = np.asarray(wc.body_ids[1:])
        self._balls = np.array([m.joint(wc.prefix + j).id for j in BALL_JOINTS])
        up = -np.asarray(m.opt.gravity, dtype=np.float64)
        self._up = up / max(float(np.linalg.norm(up)), 1e-12)
        self._weight = m.body_subtreemass[self._child] * g  # (15,) N
        # each subtree's weight up (15, 3) and its columns as the cross product takes them
        # (index arrays made once: a list index is converted at every use)
        w = self._weight[:, None] * self._up
        self._c120, self._c201 = np.array([1, 2, 0]), np.array([2, 0, 1])
        self._w_201, self._w_120 = w[:, self._c201], w[:, self._c120]
        self._weight_n = self.mass * g
        self._tau = np.zeros((NJ, 3))
        # gravity compensation's buffers, and MjData's arrays it reads (the World keeps one
        # MjData; each attribute read makes a new array)
        d = world.data
        self._mj_arrays = (d.subtree_com, d.xanchor, d.xmat)
        self._r = np.empty((NJ, 3))
        self._r_anchor = np.empty((NJ, 3))
        self._r_other = np.empty((NJ, 3))
        self._rot = np.empty((NJ, 9))
        self._rot3 = self._rot.reshape(NJ, 3, 3)
        self._jacp = np.zeros((3, m.nv))
        self._feet = [int(wc.body_ids[SIM_BODIES.index(f)]) for f in ("l_foot", "r_foot")]
        self._leg_cols = [
            np.arange(wc.ball_dof_start + 3 * joint_index(f"{s}_hip"),
                      wc.ball_dof_start + 3 * joint_index(f"{s}_ankle") + 3)
            for s in "lr"
        ]  # fmt: skip
        #: weight share carried by each foot (left, right), set by the controller each tick
        self.support = np.zeros(2)
        #: the vertical ground force the supporting legs make, in body weights (1: hold the body
        #: up; more: decelerate a fall)
        self.support_scale = 1.0
        #: direction (world, unit) of that ground force, or one per foot (``(2, 3)``); None:
        #: against gravity
        self.support_dir: F64 | None = None
        #: where on each foot (world, ``(2, 3)``) that force acts; None: through the ankle
        self.support_point: F64 | None = None
        self._ankles = [self._balls[joint_index(f"{s}_ankle")] for s in "lr"]
        self._knees = [joint_index(f"{s}_knee") for s in "lr"]
        self._knee_qpos = np.concatenate(
            [wc.ball_qpos_start + 4 * k + np.arange(4) for k in self._knees]
        )
        self.gravity_compensation = True
        #: ``(15, 3)`` share of each joint's servo gains kept about each anatomical axis
        #: (columns as the angles: pitch, roll, yaw; 1: all, 0: free, the axis driven by
        #: feed-forward alone), written in place by a controller and sent by :meth:`apply`
        self.axis_gain = np.ones((NJ, 3))
        # the anatomical axes (the Euler order's Y, X, Z) in each joint's child frame, where
        # the servo's error and MuJoCo's ball velocities live
        unit = np.eye(3)[[1, 0, 2]]
        right = np.repeat(quat_conj(athlete.joint_right)[:, None, :], 3, axis=1)
        self._axes = quat_rotate(right, np.broadcast_to(unit, (NJ, 3, 3)))
        self._sent_gain = np.ones((NJ, 3))  # what the servo has (sent only when changed)
        self._gain_changed = np.zeros((NJ, 3), dtype=bool)

    # ------------------------------------------------------------------ setup
    def reset(self, angles: F64 | None = None) -> None:
        """Servo on at :data:`SERVO_KP`, targets at ``angles`` (default: the current pose)."""
        servo = self.servo
        servo.enable(self.character, on=True)
        servo.set_gains(SERVO_KP, None, self.character)
        servo.refresh_every = SERVO_REFRESH
        now = self.current_angles() if angles is None else np.array(angles, dtype=np.float64)
        self._start[:] = now
        self._goal[:] = now
        self._t0[:] = 0.0
        self._dur[:] = 1e-9
        self._jumped = None
        self.offset[:] = 0.0
        self.axis_gain[:] = 1.0
        self._sent_gain[:] = 1.0
        servo.set_axis_gains(self.character, self._axes, self.axis_gain)
        self.support[:] = 0.0
        self.support_scale = 1.0
        self.support_dir = None
        self.support_point = None

    def release(self) -> None:
        """Give the model its joint damping back (call when the rig's rollout ends)."""
        self.world.model.dof_damping[self._dofs] = self._base_damping

    def current_angles(self) -> F64:
        """``(15, 3)`` anatomical angles of the character's current pose."""
        q = self.world.data.qpos[self.wc.ball_qpos_start : self.wc.ball_qpos_start + 4 * NJ]
        return self.athlete.joint_angles(q.reshape(NJ, 4))

    def knee_flexion(self) -> F64:
        """``(2,)`` current knee flexion (rad; left, right): the pitch part of each knee's
        anatomical rotation vector (a knee turns almost only about its pitch axis). Cheaper
        than :meth:`current_angles`, for the per-tick laws."""
        q = self.world.data.qpos[self._knee_qpos].reshape(2, 4)
        a = self.athlete
        r = quat_mul(
            quat_conj(a.joint_left[self._knees]), quat_mul(q, quat_conj(a.joint_right[self._knees]))
        )
        return quat_log(r)[:, 1]

    def set_stiffness(self, values: F64) -> None:
        """Per-joint stiffness ``(15,)`` in units of ``m g L`` (N m/rad); 0 switches a joint's
        servo off (passive)."""
        values = np.asarray(values, dtype=np.float64)
        if values.shape != (NJ,) or not np.all(np.isfinite(values)) or np.any(values < 0):
            raise ConfigError(f"stiffness must be {NJ} finite values >= 0")
        inertia = self.servo.joint_inertia(self.character)
        scale_inertia = np.einsum("nii->n", inertia) / 3.0
        on = values > 0
        scale = values * self.stiffness_unit / (SERVO_KP * scale_inertia)
        # the switches and the scales in one gain refresh (the gains are a function of both)
        self.servo.set_gain_scales(self.character, np.where(on, scale, np.nan), enabled=on)
        self._kp[:] = np.where(on, values * self.stiffness_unit / scale_inertia, 0.0)
        self.stiffness[:] = values

    def lag(self, joints: Sequence[int]) -> F64:
        """Seconds by which each of ``joints`` trails a target that moves at a steady rate
        (the trailing angle is the rate times this): the servo's ``kv / kp`` at its current
        stiffness (critical damping: ``2 / sqrt(kp)``); inf for a joint switched off."""
        kp = self._kp[np.asarray(joints)]
        return np.where(kp > 0, 2.0 / np.sqrt(np.where(kp > 0, kp, 1.0)), np.inf)

    def set_damping(self, values: F64) -> None:
        """Per-joint extra damping ``(15,)`` in units of ``m L sqrt(g L)`` (N m s/rad), added
        to the model's own joint damping (implicit in MuJoCo's integrator)."""
        values = np.asarray(values, dtype=np.float64)
        if values.shape != (NJ,) or not np.all(np.isfinite(values)) or np.any(values < 0):
            raise ConfigError(f"damping must be {NJ} finite values >= 0")
        self.world.model.dof_damping[self._dofs] = self._base_damping + np.repeat(
            values * self.damping_unit, 3
        )
        self.damping[:] = values

    # ------------------------------------------------------------------ targets
    def desired(self, t: float) -> F64:
        """``(15, 3)`` smoothed target angles at time ``t`` (without :attr:`offset`)."""
        if t == self._jumped:  # every path starts at t: s = 0 below, exactly
            # and the goal is the start: (goal - start) * 0.0 is start - start (+0.0, or
            # NaN where the start is not finite)
            return self._start + (self._start - self._start)
        x = np.minimum(np.maximum((t - self._t0) / self._dur, 0.0), 1.0)  # np.clip: 3x the cost
        s = np.where(self._accel, x * x, smoothstep(x))[:, None]
        return self._start + (self._goal - self._start) * s

    def move(
        self,
        goal: F64,
        duration: float | F64,
        t: float,
        joints: Sequence[int] | NDArray[np.bool_] | None = None,
        accelerate: bool = False,
    ) -> None:
        """Move the targets of ``joints`` (indices or a mask; default all) from where they are
        at ``t`` toward ``goal`` ``(15, 3)`` (NaN entries keep their goal) over ``duration``
        seconds (scalar or per joint); 0 jumps. The path is the Hermite curve (at rest at
        both ends), or with ``accelerate`` a constant acceleration from rest that arrives at
        full speed (a push)."""
        goal = np.asarray(goal, dtype=np.float64)
        if joints is None and isinstance(duration, (int, float)) and duration <= 0.0:
            # every joint jumps (the runner's tick): as below, without the masks
            new = np.where(np.isnan(goal), self._goal, goal)
            self._start[:] = new
            self._goal[:] = new
            self._t0[:] = t
            if self._jumped is None or self._jump_accel != accelerate:  # else as they are
                self._dur[:] = 1e-9
                self._accel[:] = accelerate
            self._jumped, self._jump_accel = t, accelerate
            return
        self._jumped = None
        sel = np.ones(NJ, dtype=bool) if joints is None else np.zeros(NJ, dtype=bool)
        if joints is not None:
            sel[np.asarray(joints)] = True
        dur = np.broadcast_to(np.asarray(duration, dtype=np.float64), (NJ,))
        new = np.where(np.isnan(goal), self._goal, goal)
        jump = sel & (dur <= 0.0)
        if not np.array_equal(jump, sel):  # where the targets are now: only for a path
            self._start[sel] = self.desired(t)[sel]
        self._start[jump] = new[jump]
        self._goal[sel] = new[sel]
        self._t0[sel] = t
        self._dur[sel] = np.maximum(dur[sel], 1e-9)
        self._accel[sel] = accelerate

    def goal(self) -> F64:
        return self._goal.copy()

    def time_left(self, t: float) -> F64:
        """``(15,)`` seconds each joint's target still takes to reach its goal at ``t``."""
        return np.maximum(self._t0 + self._dur - t, 0.0)

    def apply(self, t: float) -> None:
        """Write the servo's targets (smoothed angles plus :attr:`offset`) and feed-forward."""
        angles = self.desired(t) + self.offset
        self.servo.set_targets(self.character, self.athlete.joint_quats(angles))
        np.not_equal(self.axis_gain, self._sent_gain, out=self._gain_changed)
        if np.logical_or.reduce(self._gain_changed, axis=None):  # .any(): a Python call more
            self.servo.set_axis_gains(self.character, self._axes, self.axis_gain)
            self._sent_gain[:] = self.axis_gain
        if self.gravity_compensation:
            self._feedforward()
        else:
            self.feedforward[:] = 0.0

    def _feedforward(self) -> None:
        m, d = self.world.model, self.world.data
        # each joint holds its subtree up: (subtree com - anchor) x (weight up), child frame;
        # the same products as the arrays' operators, into buffers made once
        com, anchor, xmat = self._mj_arrays
        r, tau, other = self._r, self._tau, self._r_other
        com.take(self._child, 0, out=r)
        anchor.take(self._balls, 0, out=self._r_anchor)
        np.subtract(r, self._r_anchor, out=r)
        r.take(self._c120, 1, out=tau)
        np.multiply(tau, self._w_201, out=tau)
        r.take(self._c201, 1, out=other)
        np.multiply(other, self._w_120, out=other)
        np.subtract(tau, other, out=tau)  # r x w
        xmat.take(self._child, 0, out=self._rot)
        einsum("nji,nj->ni", self._rot3, tau, out=self.feedforward)
        flat = self.feedforward.reshape(-1)
        for k, share in enumerate(self.support.tolist()):  # two feet: floats, no flatnonzero
            if not share > 0:
                continue
            up = self._up if self.support_dir is None else self.support_dir
            if up.ndim == 2:  # one direction per foot
                up = up[k]
            force = share * self.support_scale * self._weight_n * up
            at = d.xanchor[self._ankles[k]] if self.support_point is None else self.support_point[k]
            mujoco.mj_jac(m, d, self._jacp, None, at, self._feet[k])
            cols = self._leg_cols[k]
            flat[cols - self.wc.ball_dof_start] -= self._jacp[:, cols].T @ force
