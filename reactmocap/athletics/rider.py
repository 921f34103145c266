"""The bicycle's rider (Hodgins et al. 1995, "Bicycling"): any athlete body (the thesis male by
default) whose pelvis pivots on the saddle, whose hands and feet are tied to the grips and
pedals by two-sided spring-dampers (MuJoCo soft ``connect`` equalities: toe-clips and a fixed
gear, so a leg can pull up), and the control laws of the paper's eqs. 7-11 as an engine
:class:`~reactmocap.sim.controllers.base.Controller`:

* **speed** (eqs. 7-10): a crank torque from the speed error, split between the legs by the
  crank-angle weight ``w = (1 + sin theta) / 2`` (the leg whose pedal is ahead pushes), each
  leg's pedal force turned into hip and knee torques through the leg's Jacobian (``J^T f``);
* **steering** (eq. 11): a fork angle from the roll and yaw errors and rates, its gains scheduled
  with speed (see :class:`SteerGains`), reached by placing the hands where the grips are at that
  fork angle (arm inverse kinematics) and letting the shoulder and elbow servos pull;
* **posture**: waist, back, neck and wrists held by the PD servo at a riding posture; the legs
  follow the pedals through leg inverse kinematics; the ankles follow a pedalling pattern
  (:func:`ankle_pitch`: a stated approximation of the recorded data the paper used).

All inverse kinematics is closed-form (two-link, knee and elbow poles) in the bicycle's frame,
from the *desired* posture of the pelvis and trunk: the servos then also hold that posture.
The body's geometry (posture, limb IK, ankle pattern) is in
:mod:`reactmocap.athletics.rider_kinematics`, the fit and the mount in
:mod:`reactmocap.athletics.rider_mount` (their public names re-exported here). Why the laws are
built this way and what they achieve: ``docs/athletics.md``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bicycle import Bicycle
from reactmocap.athletics.bodies import Athlete
from reactmocap.athletics.rider_kinematics import (
    SIT_OFFSET,
    Posture,
    ankle_pitch,
    minrot,
    qconj,
    qmul,
    qrot,
    quat_y,
    trunk_pose,
    two_link,
)
from reactmocap.athletics.rider_mount import (
    RIDER_WORLD,
    RiderMount,
    ball_offset,
    fit_bicycle,
    hand_offset,
)
from reactmocap.errors import ConfigError
from reactmocap.rotations import (
    cross_rows,
    quat_conj,
    quat_mul,
    quat_rotate,
    unit_rows,
    wrap_angle,
)
from reactmocap.sim.bodies import BALL_JOINTS, SIM_BODY_INDEX, SIM_PARENTS
from reactmocap.sim.world import World

__all__ = [
    "RIDER_WORLD",
    "Posture",
    "Rider",
    "RiderLog",
    "RiderMount",
    "SpeedGains",
    "SteerGains",
    "ankle_pitch",
    "fit_bicycle",
]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)


@dataclass(frozen=True)
class SpeedGains:
    """Eq. 7 with an integral term and a feed-forward, as a force at the rear contact turned
    into a crank torque through the gear (``T = F r G``, ``r`` the rear wheel's radius, ``G``
    the gear): ``F = k (v_d - v) + ki int (v_d - v) + F_ff``, ``F_ff`` the force the known
    rolling resistance and grade need at ``v_d``; the crank torque is clipped to
    ``max_torque`` (N m: a strong rider's sustained pedal force, ~1000 N on a 17 cm crank)."""

    k: float = 220.0
    ki: float = 80.0
    max_torque: float = 180.0
    integral_limit: float = 2.0


@dataclass(frozen=True)
class SteerGains:
    """Eq. 11 as a cascade, gains scheduled with the speed ``v``:

    ``fork = w' psi'_d / v - (w' / v^2) ((h wn^2 + g)(roll - roll_d) + 2 zeta wn h roll')``

    (``w' = w / cos lambda``), i.e. eq. 11's roll gains ``k_roll = (w'/v^2)(h wn^2 + g)``,
    ``k_roll' = (w'/v^2) 2 zeta wn h``; the yaw terms enter through the desired yaw rate
    ``psi'_d = psi'_ref + k_yaw (psi_ref - psi)`` toward a reference heading that turns at most
    as fast as ``max_lean`` allows, reaching that rate in ``turn_in`` s, and the
    desired roll ``roll_d = -atan(v psi'_d / g)`` (the steady-turn lean). ``h``: the height of
    the rider and bicycle's centre of mass; ``wn``, ``zeta``: the lean servo's natural
    frequency (1/s) and damping ratio."""

    height: float = 1.1
    wn: float = 5.0
    wn_per_speed: float = 1.25
    zeta: float = 0.9
    k_yaw: float = 1.0
    max_lean: float = 0.5
    turn_in: float = 0.5
    lag: float = 0.4
    k_steer: float = 8.0
    max_steer_offset: float = 0.3
    max_fork: float = math.radians(45.0)
    min_speed: float = 1.0


@dataclass
class RiderLog:
    """Per control tick: time, speed and its command, heading and its command, roll, steer and
    its command, crank torque, position ``(x, y)``."""

    rows: list[tuple[float, ...]] = field(default_factory=list)

    COLUMNS = ("t", "speed", "speed_cmd", "heading", "heading_cmd", "roll", "steer",
               "steer_cmd", "crank_torque", "x", "y", "yaw_rate")  # fmt: skip

    def arrays(self) -> dict[str, F64]:
        a = np.array(self.rows, dtype=np.float64).reshape(-1, len(self.COLUMNS))
        return {c: a[:, k] for k, c in enumerate(self.COLUMNS)}


#: limb order of the inverse kinematics: left arm, right arm, left leg, right leg; the poles
#: the elbows (out, back and down) and knees (forward) bend toward
_UPPER = np.array([SIM_BODY_INDEX[b] for b in ("l_upper_arm", "r_upper_arm", "l_thigh", "r_thigh")])
_LOWER = np.array([SIM_BODY_INDEX[b] for b in ("l_forearm", "r_forearm", "l_shin", "r_shin")])
_HANDS = np.array([SIM_BODY_INDEX["l_hand"], SIM_BODY_INDEX["r_hand"]])
_POLES = np.array([[-0.5, 0.7, -0.5], [-0.5, -0.7, -0.5], [1.0, 0.1, 0.3], [1.0, -0.1, 0.3]])


_LEG_JOINTS = np.array(
    [BALL_JOINTS.index(f"{s}_{j}") for s in "lr" for j in ("hip", "knee", "ankle")]
)


def _turn_pedals(pedals: F64, centre: F64, angle: float) -> F64:
    """Pedal points ``(2, 3)`` turned forward by ``angle`` about the crank axle (bicycle +y)
    through ``centre``."""
    c, s = math.cos(angle), math.sin(angle)
    rel = pedals - centre
    out = centre + rel
    out[:, 0] = centre[0] + c * rel[:, 0] + s * rel[:, 2]
    out[:, 2] = centre[2] - s * rel[:, 0] + c * rel[:, 2]
    return out


class Rider:
    """The rider's controller (module docstring) for character ``character`` on ``bicycle``,
    tied to it by ``mount`` (bound in ``world``).

    Commands: :attr:`speed_cmd` (m/s) and :attr:`heading_cmd` (rad), settable at any time (a
    group behaviour sets them every tick). Servo: stiffness ``kp`` (1/s^2, times each joint's
    outboard inertia), scaled by ``arm_scale`` at the shoulders, elbows and wrists (the fork
    follows the hands) and ``leg_scale`` at the hips, knees and ankles (the pedals lead the
    legs); waist and back x3."""

    def __init__(
        self,
        world: World,
        athlete: Athlete,
        bicycle: Bicycle,
        mount: RiderMount,
        character: int = 0,
        *,
        speed: float = 5.0,
        heading: float = 0.0,
        posture: Posture | None = None,
        speed_gains: SpeedGains | None = None,
        steer_gains: SteerGains | None = None,
        kp: float = 900.0,
        arm_scale: float = 4.0,
        leg_scale: float = 0.5,
        control_every: int = 4,
    ) -> None:
        if not (0 <= character < len(world.characters)):
            raise ConfigError(f"character {character} is not in the world")
        if not (kp > 0 and arm_scale > 0 and leg_scale > 0 and control_every >= 1):
            raise ConfigError("kp, arm_scale and leg_scale must be > 0, control_every >= 1")
        if not (math.isfinite(speed) and math.isfinite(heading)):
            raise ConfigError("speed and heading commands must be finite")
        self.world, self.athlete, self.bicycle, self.character = world, athlete, bicycle, character
        self.speed_cmd = float(speed)
        self.heading_cmd = float(heading)
        self.posture = posture or Posture()
        self.speed_gains = speed_gains or SpeedGains()
        self.steer_gains = steer_gains or SteerGains()
        self.kp = float(kp)
        self.arm_scale = float(arm_scale)
        self.leg_scale = float(leg_scale)
        self.control_every = int(control_every)
        self.log = RiderLog()
        m = world.model
        wc = world.characters[character]
        self.wc = wc
        self.servo = world.servo
        p = bicycle.params
        if p.drivetrain is None or p.fit is None:
            raise ConfigError("a rider's bicycle needs a drivetrain and a fit (fit_bicycle)")
        self.dt_params = p.drivetrain
        ch = athlete.character
        self._bq = ch.body_quat  # (16, 4)
        self._bpos = ch.body_pos  # (16, 3)
        self._neutral = athlete.neutral  # (16, 4)
        # the limbs' link vectors in the anatomical frame (neutral pose) and their lengths
        self._ball = np.array([ball_offset(athlete, s) for s in "lr"])  # in the foot frames
        links = []
        for up, mid, end, extra in (("l_upper_arm", "l_forearm", "l_hand", hand_offset(athlete, "l")),
                                     ("r_upper_arm", "r_forearm", "r_hand", hand_offset(athlete, "r")),
                                     ("l_thigh", "l_shin", "l_foot", None),
                                     ("r_thigh", "r_shin", "r_foot", None)):  # fmt: skip
            v1 = quat_rotate(self._neutral[SIM_BODY_INDEX[up]], self._bpos[SIM_BODY_INDEX[mid]])
            v2 = quat_rotate(self._neutral[SIM_BODY_INDEX[mid]], self._bpos[SIM_BODY_INDEX[end]])
            if extra is not None:  # the grip point beyond the (straight) wrist
                v2 = v2 + quat_rotate(self._neutral[SIM_BODY_INDEX[end]], extra)
            links.append((v1, v2))
        self._v1 = np.array([a for a, _ in links])
        self._v2 = np.array([b for _, b in links])
        self._l1 = np.linalg.norm(self._v1, axis=1)
        self._l2 = np.linalg.norm(self._v2, axis=1)
        # the bicycle frame: the rider's frame body; steer axis and head in its frame
        self._head = (p.steer_foot + p.steer_axis * (p.front.radius / p.steer_axis[2])
                      - np.array([0.0, 0.0, p.rear.radius]))  # fmt: skip
        self._axis = p.steer_axis
        fit = p.fit
        self._grip0 = np.array([[fit.grips[0], s * fit.grip_offset, fit.grips[1] - p.rear.radius]
                                for s in (1.0, -1.0)])  # fmt: skip
        self._wheelbase = p.wheelbase / math.cos(p.steer_tilt)
        self._resist = p.rolling_resistance
        self._mass = float(m.body_subtreemass[wc.body_ids[0]]) + p.mass
        # leg Jacobian columns: hip, knee and ankle (the ankle passes the pedal force's moment
        # about it on to the foot; its servo alone, scaled by a foot's inertia, would fold)
        self._leg_cols = [
            np.concatenate([wc.ball_dof_start + 3 * BALL_JOINTS.index(f"{s}_{j}") + np.arange(3)
                            for j in ("hip", "knee", "ankle")])
            for s in "lr"
        ]  # fmt: skip
        self._feet = [int(wc.body_ids[SIM_BODY_INDEX[f"{s}_foot"]]) for s in "lr"]
        self._jac = np.zeros((3, m.nv))
        self._balls = wc.ball_dof_start + np.arange(3 * NJ)
        self._ff_rows = self.servo.character_indices.index(character) * NJ
        self._d1 = unit_rows(self._v1)
        self._d2 = unit_rows(self._v2)
        self._bq_inv = qconj(self._bq[1:])
        self._foot_rows = np.array([SIM_BODY_INDEX["l_foot"], SIM_BODY_INDEX["r_foot"]])
        self._trunk_cache: tuple[Posture, F64, F64] | None = None
        self._integral = 0.0
        self._torque = 0.0
        self._fork_cmd = 0.0
        if mount.bicycle is not bicycle or mount.world is not world:
            raise ConfigError("the rider's mount must tie it to this bicycle in this world")
        self.mount = mount

    # ---------------------------------------------------------------- pose
    def _frame(self) -> tuple[F64, F64]:
        d = self.world.data
        fid = self.bicycle.frame_id
        return d.xpos[fid].copy(), d.xquat[fid].copy()

    def _trunk(self) -> tuple[F64, F64]:
        """:func:`trunk_pose` of the current posture (cached)."""
        if self._trunk_cache is None or self._trunk_cache[0] is not self.posture:
            a, bases, _ = trunk_pose(self.athlete, self.posture)
            self._trunk_cache = (self.posture, a, bases)
        return self._trunk_cache[1], self._trunk_cache[2]

    def pose(self, fork: float, pedals: F64, pelvis_pos: F64, crank: float) -> F64:
        """``(16, 4)`` desired body rotations in the bicycle frame: the posture's pelvis and
        trunk, arms reaching the grips at fork angle ``fork``, legs reaching ``pedals``
        ``(2, 3)`` (left, right; bicycle frame) with the ankle pattern at crank angle
        ``crank``; the pelvis at ``pelvis_pos`` (bicycle frame)."""
        trunk, offsets = self._trunk()
        a = trunk.copy()
        bases = pelvis_pos + offsets
        turn = np.concatenate(([math.cos(fork / 2)], math.sin(fork / 2) * self._axis))
        grips = self._head + qrot(turn, self._grip0 - self._head)
        a_foot = quat_y(ankle_pitch(np.array([crank + math.pi, crank])))  # left, right
        g_foot = qmul(a_foot, self._neutral[self._foot_rows])
        ankles = pedals - qrot(g_foot, self._ball)
        u1, u2 = two_link(bases, np.vstack([grips, ankles]), self._l1, self._l2, _POLES)
        a_up = minrot(self._d1, u1)
        a_low = qmul(minrot(qrot(a_up, self._d2), u2), a_up)
        a[_UPPER] = a_up
        a[_LOWER] = a_low
        a[_HANDS] = a_low[:2]
        a[self._foot_rows] = a_foot
        return qmul(a, self._neutral)

    def joint_quats(self, g: F64) -> F64:
        """``(15, 4)`` ball-joint quaternions of body rotations ``g`` ``(16, 4)`` (any common
        frame): ``q = bq^-1 g_parent^-1 g_child``."""
        return qmul(self._bq_inv, qmul(qconj(g[SIM_PARENTS[1:]]), g[1:]))

    def _local(self, origin: F64, quat: F64, points: F64) -> F64:
        return qrot(qconj(quat), points - origin)

    def initial_qpos(self) -> F64:
        """``(67,)`` the rider's qpos sitting on the placed bicycle: sit bones on the saddle,
        hands on the grips, feet on the pedals."""
        d = self.world.data
        o, q = self._frame()
        s = self._sites()
        seat = self._local(o, q, 0.5 * (d.site_xpos[s["l_seat"]] + d.site_xpos[s["r_seat"]]))
        g_pelvis = quat_mul(quat_y(self.posture.pelvis), self._neutral[0])
        sit = quat_rotate(quat_conj(self._neutral[0]), np.array(SIT_OFFSET) * [1.0, 0.0, 1.0])
        pelvis_pos = seat - quat_rotate(g_pelvis, sit)
        pedals = self._local(o, q, d.site_xpos[[s["l_pedal"], s["r_pedal"]]])
        g = self.pose(0.0, pedals, pelvis_pos, self.bicycle.crank_angle)
        out = np.empty(7 + 4 * NJ)
        out[:3] = o + quat_rotate(q, pelvis_pos)
        out[3:7] = quat_mul(q, g[0])
        out[7:] = self.joint_quats(g).reshape(-1)
        return out

    def _sites(self) -> dict[str, int]:
        return self.mount.sites

    def seat(self) -> None:
        """Put the rider on the placed bicycle, moving with it (run after the bicycle's
        ``place``)."""
        qv = np.zeros(6 + 3 * NJ)
        qv[:3] = self.bicycle.velocity
        self.world.set_pose(self.character, self.initial_qpos(), qv)

    # ---------------------------------------------------------------- control
    def reset(self, world: World) -> None:
        del world
        servo = self.servo
        servo.enable(self.character, on=True)
        servo.set_gains(self.kp, None, self.character)
        scale = np.ones(NJ)
        for joints, k in ((("hip", "knee", "ankle"), self.leg_scale), (("waist", "back"), 3.0),
                          (("shoulder", "elbow", "wrist"), self.arm_scale)):  # fmt: skip
            names = [j for j in BALL_JOINTS if j.removeprefix("l_").removeprefix("r_") in joints]
            servo.set_gain_scale(self.character, names, k)
            scale[[BALL_JOINTS.index(j) for j in names]] = k
        # the servo damps toward rest; its damping times the targets' own velocity goes into
        # the feed-forward, so it damps toward the pedalling and steering motion instead
        self._kv = 2.0 * math.sqrt(self.kp) * np.sqrt(scale)
        self._integral = 0.0
        self._ref = self.bicycle.yaw
        self._ref_rate = 0.0
        self._expected = self._ref
        self._steer_int = 0.0
        self.log = RiderLog()

    def fork_command(self, v: float) -> tuple[float, float]:
        """The fork angle (rad) eq. 11 asks for now, and the desired yaw rate (rad/s). The
        heading command is first shaped into a reference that turns no faster than the lean
        allows (:attr:`SteerGains.max_lean`) and speeds up and slows down over
        :attr:`SteerGains.turn_in` seconds (the time the lean takes to build), so a step in
        heading is ridden as a turn, not as a saturated error."""
        b, sg = self.bicycle, self.steer_gains
        g = 9.81
        vv = max(abs(v), sg.min_speed)
        h = self.control_every * self.world.timestep
        # as fast as the lean allows, and at low speed as the fork allows (half its range)
        max_rate = min(
            g * math.tan(sg.max_lean) / vv, vv * math.tan(0.5 * sg.max_fork) / self._wheelbase
        )
        wn = min(sg.wn, sg.wn_per_speed * vv)  # slower lean servo at low speed: gains ~ 1/v^2
        lag = sg.lag * (sg.wn / wn) ** 1.5  # the lean servo's lag grows at low speed
        accel = max_rate / max(sg.turn_in, lag)
        left = wrap_angle(self.heading_cmd - self._ref)
        # as fast as allowed, braking in time (sqrt(2 a e)); near the target a first-order
        # approach (the square root's gain is unbounded at zero: it would chatter)
        want = math.copysign(
            min(max_rate, math.sqrt(2.0 * accel * abs(left)), abs(left) / lag), left
        )
        self._ref_rate += min(max(want - self._ref_rate, -accel * h), accel * h)
        self._ref = wrap_angle(self._ref + self._ref_rate * h)
        # the heading the bicycle can have by now: the reference through the lean's lag; the
        # feedback compares with it (no wind-up while the lean builds), the feed-forward is the
        # reference's own rate (the lean starts at once)
        self._expected = wrap_angle(
            self._expected + wrap_angle(self._ref - self._expected) * min(h / lag, 1.0)
        )
        rate = self._ref_rate + sg.k_yaw * wrap_angle(self._expected - b.yaw)
        rate = min(max(rate, -max_rate), max_rate)
        roll_d = -math.atan(vv * rate / g)
        w = self._wheelbase
        k = w / vv**2
        fork = w * rate / vv - k * ((sg.height * wn**2 + g) * (b.roll - roll_d)
                                    + 2 * sg.zeta * wn * sg.height * b.roll_rate)  # fmt: skip
        return min(max(fork, -sg.max_fork), sg.max_fork), rate

    def crank_torque(self, v: float) -> float:
        """Eq. 7 (with the integral and feed-forward of :class:`SpeedGains`), N m. The integral
        stops while the torque is at its limit (no wind-up)."""
        sg, dt = self.speed_gains, self.dt_params
        err = self.speed_cmd - v
        h = self.control_every * self.world.timestep
        # resistive force at the command: rolling resistance and gravity along the slope
        slope = float(self.bicycle.rotation()[2, 0])  # sine of the climb angle
        ff = self._resist * self.speed_cmd + self._mass * 9.81 * slope
        arm = self.bicycle.params.rear.radius * dt.gear
        trial = self._integral + err * h
        trial = min(max(trial, -sg.integral_limit), sg.integral_limit)
        t = (ff + sg.k * err + sg.ki * trial) * arm
        if abs(t) <= sg.max_torque:
            self._integral = trial
        else:
            t = (ff + sg.k * err + sg.ki * self._integral) * arm
        return min(max(t, -sg.max_torque), sg.max_torque)

    def control(self, world: World, t: float) -> None:
        d = world.data
        b = self.bicycle
        s = self._sites()
        v = b.speed
        fork, rate = self.fork_command(v)
        torque = self.crank_torque(v)
        h = self.control_every * world.timestep
        # the arms give a little under the bar's load: aim the hands past the fork angle by
        # the integrated tracking error, so the fork reaches the angle eq. 11 asks for
        sg = self.steer_gains
        self._steer_int += sg.k_steer * (fork - b.steer) * h
        self._steer_int = min(max(self._steer_int, -sg.max_steer_offset), sg.max_steer_offset)
        self._torque, self._fork_cmd = torque, fork
        o, q = self._frame()
        crank = b.crank_angle
        rate = b.crank_rate
        bb = self._local(o, q, d.xpos[b.crank_id])
        pedals = self._local(o, q, d.site_xpos[[s["l_pedal"], s["r_pedal"]]])
        pelvis = self._local(o, q, d.xpos[self.wc.body_ids[0]])
        # aim a little ahead along the pedal circle (the servo's lag), and one tick further for
        # the legs' velocity: the pedalling motion is the crank's, not the feet's (feet-driven
        # velocity targets would cancel the servo's damping)
        lead = rate * 0.03
        grip = fork + self._steer_int
        now = self.pose(grip, _turn_pedals(pedals, bb, lead), pelvis, crank + lead)
        ahead = self.pose(grip, _turn_pedals(pedals, bb, lead + rate * h), pelvis,
                          crank + lead + rate * h)  # fmt: skip
        targets = self.joint_quats(now)
        self.servo.set_targets(self.character, targets)
        self._feedforward(torque, crank)
        rel = qmul(qconj(targets[_LEG_JOINTS]), self.joint_quats(ahead)[_LEG_JOINTS])
        w = 2.0 * rel[:, 1:] * np.sign(rel[:, :1]) / h
        inertia = self.servo.joint_inertia(self.character)[_LEG_JOINTS]
        ff = self.servo.feedforward[self._ff_rows : self._ff_rows + NJ]
        ff[_LEG_JOINTS] += self._kv[_LEG_JOINTS, None] * np.einsum("nij,nj->ni", inertia, w)
        yaw = b.yaw
        pos = b.position
        self.log.rows.append((t, v, self.speed_cmd, yaw, self.heading_cmd, b.roll, b.steer,
                              fork, torque, float(pos[0]), float(pos[1]), b.yaw_rate))  # fmt: skip

    def _feedforward(self, torque: float, crank: float) -> None:
        """Gravity compensation of every joint plus the legs' ``J^T f`` pedal forces (eqs. 8-10)."""
        m, d = self.world.model, self.world.data
        ff = self.servo.feedforward[self._ff_rows : self._ff_rows + NJ].reshape(-1)
        ff[:] = d.qfrc_bias[self._balls]
        arm = self.dt_params.crank_length
        w_right = 0.5 * (1.0 + math.sin(crank))
        if torque < 0:
            w_right = 1.0 - w_right
        s = self._sites()
        axis = self.bicycle.rotation()[:, 1]  # the crank axle (bicycle's left)
        centre = d.xpos[self.bicycle.crank_id]
        for k, (side, share) in enumerate((("l", 1.0 - w_right), ("r", w_right))):
            pedal = d.site_xpos[s[f"{side}_pedal"]]
            r = pedal - centre
            r = r - (r @ axis) * axis
            tangent = cross_rows(axis, r) / max(float(np.linalg.norm(r)), 1e-9)
            force = share * torque / arm * tangent  # the foot pushes the pedal with this
            mujoco.mj_jac(m, d, self._jac, None, d.site_xpos[s[f"{side}_ball"]], self._feet[k])
            cols = self._leg_cols[k]
            ff[cols - self.wc.ball_dof_start] += self._jac[:, cols].T @ force
