"""Running (Hodgins et al. 1995, "Running"): a state machine over the active leg's contact with
the ground (flight, loading, heel, heel and toe, toe, unloading; the legs swap roles at
lift-off), foot placement by eqs. 1-2 with ground-speed matching, a knee that acts as a passive
spring in stance and an ankle that gives the thrust, the stance hip servoing the body's
attitude (roll, pitch, yaw, with a lean into curves), the idle leg mirroring the active one
(eqs. 3-4) and shortened, the arms swinging with the opposite hip (eq. 5), and every joint
following a smooth trajectory toward its desired angle (eq. 6). The user gives a speed
(2.5-5 m/s) and a facing direction or a path (:mod:`reactmocap.athletics.course`).

The feet: the thesis bodies' toes are merged into the feet (the engine's characters have 15
ball joints), so the paper's two-part foot is a rigid sole box here. Heel and toe contact are
told apart by which of the box's corners touch the floor: heel contact is the rear corners,
toe contact the front ones; the toe phase rolls the foot about its front edge, as the paper's
foot rolls about the ball. Design and measurements: ``docs/athletics.md``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.balance import knee_for_length
from reactmocap.athletics.bodies import EULER_ORDER, Athlete
from reactmocap.athletics.course import Course, Straight
from reactmocap.athletics.rig import Rig, joint_index, per_joint
from reactmocap.athletics.senses import Senses
from reactmocap.errors import ConfigError
from reactmocap.rotations import (
    quat_conj,
    quat_from_euler,
    quat_from_yaw,
    quat_log,
    quat_mul,
    quat_to_euler,
)
from reactmocap.sim.bodies import BALL_JOINTS, SIM_BODIES
from reactmocap.sim.controllers.base import FunctionController
from reactmocap.sim.controllers.machine import State, StateMachine
from reactmocap.sim.world import World

__all__ = [
    "RUN_STATES",
    "SPEED_RANGE",
    "RunLog",
    "RunParams",
    "Runner",
    "check_speed",
]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)
#: the speeds the runner is built for (m/s), the paper's range
SPEED_RANGE = (2.5, 5.0)
#: the states of the active leg (Fig. 3)
RUN_STATES = ("flight", "loading", "heel", "heel_toe", "toe", "unloading")
_HIP = (joint_index("l_hip"), joint_index("r_hip"))
_KNEE = (joint_index("l_knee"), joint_index("r_knee"))
_ANKLE = (joint_index("l_ankle"), joint_index("r_ankle"))
_SHOULDER = (joint_index("l_shoulder"), joint_index("r_shoulder"))
_ELBOW = (joint_index("l_elbow"), joint_index("r_elbow"))
_SPINE = (joint_index("waist"), joint_index("back"))
_BODY = {b: i for i, b in enumerate(SIM_BODIES)}
_THIGH = (_BODY["l_thigh"], _BODY["r_thigh"])
_SHIN = (_BODY["l_shin"], _BODY["r_shin"])
_FOOT = (_BODY["l_foot"], _BODY["r_foot"])
#: a sole corner closer than this to the floor (m) counts as touching
CORNER_TOUCH = 0.004


def check_speed(speed: float) -> float:
    """``speed`` if it lies in :data:`SPEED_RANGE`, else a ConfigError naming the range."""
    lo, hi = SPEED_RANGE
    if not (isinstance(speed, (int, float)) and math.isfinite(speed) and lo <= speed <= hi):
        raise ConfigError(
            f"running speed {speed!r} m/s is outside the supported range {lo:g}-{hi:g} m/s"
        )
    return float(speed)


@dataclass(frozen=True)
class RunParams:
    """The runner's tuning. Angles in radians, stiffness in units of ``m g L`` N m/rad (body
    mass, leg length), damping in ``m L sqrt(g L)`` N m s/rad, times in seconds.

    Args:
        stance_time: first estimate of the stance duration ``t_s`` (eqs. 1-2); later steps
            use the previous stance's.
        speed_gain: ``k`` of eqs. 1-2, the velocity-error gain (s).
        touchdown_leg: hip-to-ankle length at touchdown (fraction of the straight leg).
        speed_matching: how far ahead (m) the swing foot is carried during flight and
            brought back just before touchdown (ground-speed matching).
        heel_up: foot pitch at touchdown (rad, toes up), so the heel strikes first.
        knee_spring: stance knee stiffness (its "passive spring").
        ankle_heel: stance ankle stiffness while only the heel touches.
        ankle_push: stance ankle stiffness in the toe phase (the thrust).
        push_angle: ankle extension the toe phase drives toward (rad).
        toe_fraction: the heel-and-toe phase ends at this fraction of the expected stance
            (0.3-0.5 by speed): a pair (at 2.5 m/s, at 5 m/s) interpolated.
        pitch: desired forward pitch of the pelvis (rad).
        attitude_kp, attitude_kv: the stance hip's attitude servo, per unit of the body's
            mass times the squared leg length (1/s^2, 1/s), roll, pitch, yaw.
        idle_knee: knee flexion of the shortened idle leg (rad).
        arm_gain, arm_offset: eq. 5, shoulder pitch = gain * opposite hip pitch + offset.
        elbow: elbow flexion (rad).
        smoothing: time constant (s) of the trajectories toward the desired angles (eq. 6).
        height_gain: thrust adaptation per metre of flight-apex error (per step).
        flight_height: desired rise of the COM during flight (m) at 2.5 and 5 m/s.
    """

    stance_time: float = 0.22
    speed_gain: float = 0.06
    touchdown_leg: float = 0.96
    speed_matching: float = 0.15
    retract_time: float = 0.06
    heel_up: float = 0.2
    knee_spring: float = 3.0
    leg_stiffness: float = 18.0
    leg_damping: float = 0.1
    thrust: float = 0.6
    ankle_heel: float = 1.0
    ankle_flat: float = 0.8
    ankle_push: float = 1.2
    push_angle: float = 0.6
    toe_fraction: tuple[float, float] = (0.5, 0.3)
    pitch: float = 0.08
    attitude_kp: tuple[float, float, float] = (40.0, 40.0, 15.0)
    attitude_kv: tuple[float, float, float] = (5.0, 5.0, 3.0)
    idle_knee: float = 1.6
    swing_ready: float = -0.45
    yaw_grip: float = 0.25
    reach_knee: float = 0.8
    arm_gain: float = 0.9
    arm_offset: float = 0.05
    elbow: float = 1.4
    smoothing: float = 0.015
    step_width: float = 0.06
    support: float = 0.0
    height_gain: float = 2.0
    flight_height: tuple[float, float] = (0.02, 0.04)
    takeoff_vz: tuple[float, float] = (0.45, 0.7)
    stiffness: dict[str, float] = field(
        default_factory=lambda: {
            "waist": 4.0, "back": 4.0, "neck": 0.3, "shoulder": 0.4, "elbow": 0.2,
            "wrist": 0.05, "hip": 3.0, "knee": 1.0, "ankle": 0.4,
        }
    )  # fmt: skip

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            vals = v.values() if isinstance(v, dict) else v if isinstance(v, tuple) else (v,)
            if not all(isinstance(x, (int, float)) and math.isfinite(x) for x in vals):
                raise ConfigError(f"running parameter {f.name} must be finite, got {v!r}")
        if not 0.5 < self.touchdown_leg <= 1.0:
            raise ConfigError(f"touchdown_leg must be in (0.5, 1], got {self.touchdown_leg}")
        if self.stance_time <= 0 or self.smoothing < 0:
            raise ConfigError("stance_time must be > 0 and smoothing >= 0")


@dataclass
class RunLog:
    """Per control tick: time, COM, COM velocity, pelvis heading, state index, active leg,
    feet in contact (bit 0 left, bit 1 right), pelvis height, whether anything but the feet
    touched the floor, hip and knee pitch of both legs; and the touchdown and lift-off
    events (time, leg, foot position)."""

    rows: list[tuple] = field(default_factory=list)
    touchdowns: list[tuple[float, int, float, float]] = field(default_factory=list)
    liftoffs: list[tuple[float, int]] = field(default_factory=list)

    def arrays(self) -> dict[str, NDArray]:
        names = ("t", "com", "com_vel", "heading", "state", "active", "feet", "pelvis",
                 "others", "hip", "knee", "desired_heading", "cross_track", "trunk")  # fmt: skip
        if not self.rows:
            return {n: np.zeros(0) for n in names}
        cols = list(zip(*self.rows))
        return {n: np.array(c) for n, c in zip(names, cols)}


class Runner:
    """The running controller for one athlete in a world (an engine controller).

    Args:
        world: the world (the athlete is character ``character``).
        athlete: the athlete's anatomical frames.
        speed: desired speed (m/s, within :data:`SPEED_RANGE`).
        course: facing direction or path to follow (default: straight ahead along +X).
        params: tuning.
        control_every: physics steps per control tick.
    """

    def __init__(
        self,
        world: World,
        athlete: Athlete,
        speed: float,
        course: Course | None = None,
        params: RunParams | None = None,
        character: int = 0,
        control_every: int = 8,
    ) -> None:
        self.world = world
        self.athlete = athlete
        self.speed = check_speed(speed)
        self.course = course or Straight(0.0)
        self.p = params or RunParams()
        self.character = character
        if not (isinstance(control_every, int) and control_every >= 1):
            raise ConfigError(f"control_every must be an int >= 1, got {control_every!r}")
        self.control_every = control_every
        self.rig = Rig(world, athlete, character)
        self.senses = Senses(world, athlete, character)
        self.log = RunLog()
        wc = world.characters[character]
        self.wc = wc
        m = world.model
        self.mass = self.rig.mass
        self.g = float(np.linalg.norm(m.opt.gravity))
        L = athlete.leg_length
        self.inertia_unit = self.mass * L * L
        self._hips = [m.joint(wc.prefix + f"{s}_hip").id for s in "lr"]
        self._ankles = [m.joint(wc.prefix + f"{s}_ankle").id for s in "lr"]
        self._knees = [m.joint(wc.prefix + f"{s}_knee").id for s in "lr"]
        self._root = int(wc.body_ids[0])
        self._chest = int(wc.body_ids[_BODY["chest"]])
        self._thighs = wc.body_ids[list(_THIGH)]
        self._shins = wc.body_ids[list(_SHIN)]
        self._feet = wc.body_ids[list(_FOOT)]
        self._neutral = athlete.neutral
        self._hip_dofs = [wc.ball_dof_start + 3 * j for j in _HIP]
        self._jacp = np.zeros((3, m.nv))
        # the knee's and ankle's dofs of each leg
        self._leg_cols = [
            np.r_[wc.ball_dof_start + 3 * _KNEE[k] : wc.ball_dof_start + 3 * _KNEE[k] + 3,
                  wc.ball_dof_start + 3 * _ANKLE[k] : wc.ball_dof_start + 3 * _ANKLE[k] + 3]
            for k in range(2)
        ]  # fmt: skip
        lo, hi = SPEED_RANGE
        self._s = (self.speed - lo) / (hi - lo)
        # heel-to-ball length l_f: the sole box's length; heel behind the ankle
        sole = wc.sole_ids[0]
        self.foot_length = 2.0 * float(m.geom_size[sole, 0])
        # the planned touchdown length hip -> heel: hip-ankle at the touchdown fraction plus
        # the heel's offset below and behind the ankle (reference pose)
        d0 = mujoco.MjData(m)
        mujoco.mj_kinematics(m, d0)
        self.rest_length = np.zeros(2)
        for k in range(2):
            rot = d0.geom_xmat[wc.sole_ids[k]].reshape(3, 3)
            half = m.geom_size[wc.sole_ids[k]]
            heel = d0.geom_xpos[wc.sole_ids[k]] + rot @ np.array([-half[0], 0.0, -half[2]])
            off = heel - d0.xanchor[self._ankles[k]]
            hip_ankle = self.p.touchdown_leg * (athlete.thigh[k] + athlete.shin[k])
            self.rest_length[k] = float(np.hypot(hip_ankle - off[2], np.hypot(off[0], off[1])))
        self.machine = StateMachine(self._states(), "flight", control_every)
        self._reset_state()

    # ------------------------------------------------------------------ state
    def _reset_state(self) -> None:
        self.active = 0  # the leg on the ground or being placed (0 left, 1 right)
        self.t_touchdown = 0.0
        self.t_liftoff = 0.0
        self.stance_estimate = self.p.stance_time
        self.thrust = 1.0
        self.apex = -np.inf
        self.lo_hip = np.zeros((2, 3))  # hip angles at the previous lift-off
        self.targets = np.zeros((NJ, 3))
        self.goal = np.zeros((NJ, 3))
        self.heel = np.zeros(2, dtype=bool)
        self.toe = np.zeros(2, dtype=bool)
        self.heading_d = 0.0
        self.curvature = 0.0
        self.cross_track = 0.0
        self.knee_td = 0.3
        self.leg_rest = 0.0
        self.leg_prev = 0.0
        self.leg_force = 0.0
        self.lo_pitch = [0.0, 0.0]
        self.td_pitch = 0.0
        self.t_heel_toe = 0.0
        self.thrust_force = self.p.thrust * self.mass * self.g
        self.steps = 0
        self.released = False
        lo, hi = self.p.takeoff_vz
        self.takeoff_vz = lo + (hi - lo) * self._s

    def reset(self, world: World) -> None:
        del world
        self._reset_state()
        self.rig.reset()
        self.senses.time = -1.0
        angles = self.rig.current_angles()
        self.targets[:] = angles
        self.goal[:] = angles
        self.lo_hip[:] = angles[list(_HIP)]
        self.machine.reset(self.world)
        self.rig.set_stiffness(per_joint(self.p.stiffness))
        self.rig.gravity_compensation = True

    # ------------------------------------------------------------------ geometry
    def _anat(self, bodies: NDArray[np.int64], neutral: list[int]) -> F64:
        """Anatomical world rotations of some bodies."""
        return quat_mul(self.world.data.xquat[bodies], quat_conj(self._neutral[neutral]))

    def pelvis_anat(self) -> F64:
        return quat_mul(self.world.data.xquat[self._root], quat_conj(self._neutral[0]))

    def trunk_euler(self) -> F64:
        """Chest pitch, roll and yaw (anatomical, rad)."""
        d = self.world.data
        now = quat_mul(d.xquat[self._chest], quat_conj(self._neutral[_BODY["chest"]]))
        return quat_to_euler(quat_mul(quat_conj(quat_from_yaw(self.heading())), now), EULER_ORDER)

    def heading(self) -> float:
        return self.senses.heading()

    def _contacts(self) -> None:
        """Which feet touch with their heel (rear corners) and toe (front corners)."""
        s = self.senses
        corners = s.sole_corners()
        z = corners[..., 2] - self.world.data.geom_xpos[s.floor][2]
        near = z < CORNER_TOUCH
        touch = s.foot_contact
        self.toe[:] = touch & near[:, :2].any(axis=1)
        self.heel[:] = touch & near[:, 2:].any(axis=1)
        # a foot in contact but with no corner within reach still touches (its edge)
        lone = touch & ~(self.toe | self.heel)
        self.heel[lone] = True

    # ------------------------------------------------------------------ control laws
    def _placement(self, k: int, t: float) -> None:
        """Eqs. 1-2 and the inverse kinematics of leg ``k``: hip and knee goals that put the
        heel at the placement point with the touchdown leg length; ankle goal for a heel
        strike. Ground-speed matching carries the foot further forward while it is high."""
        p = self.p
        d = self.world.data
        s = self.senses
        v = s.com_vel[:2]
        psi = self.heading()
        vd = self.speed * np.array([math.cos(self.heading_d), math.sin(self.heading_d)])
        ts = self.stance_estimate
        lf = self.foot_length
        x_hh = 0.5 * (ts * v[0] - math.cos(psi) * lf) + p.speed_gain * (v[0] - vd[0])
        y_hh = 0.5 * (ts * v[1] - math.sin(psi) * lf) + p.speed_gain * (v[1] - vd[1])
        # eqs. 1-2 place the heel relative to the body's centre line (the COM), a step width
        # apart, rather than under the hip joint 8 cm to the side (runners land near the
        # midline); the hip-to-heel vector follows from where the hip is now
        c, sn = math.cos(psi), math.sin(psi)
        side = 1.0 if k == 0 else -1.0
        hip = d.xanchor[self._hips[k]]
        rel = s.com[:2] - hip[:2]
        off = np.array([x_hh, y_hh]) + rel
        fwd = c * off[0] + sn * off[1]
        lat = -sn * off[0] + c * off[1] + side * 0.5 * p.step_width
        # ground-speed matching: the foot reaches further forward while it is high and comes
        # back over the last moments before touchdown (predicted from the lowest sole corner
        # and the body's vertical speed), so it meets the ground moving back under the body
        vz = float(s.com_vel[2])
        low = float(s.sole_corners()[k, :, 2].min())
        to_go = low / -vz if vz < -1e-3 else np.inf
        fwd += p.speed_matching * float(np.clip(to_go / p.retract_time, 0.0, 1.0))
        # the heel sits behind the ankle: the ankle goes that much further forward
        fwd += 0.3 * lf
        length = p.touchdown_leg * (self.athlete.thigh[k] + self.athlete.shin[k])
        fwd = float(np.clip(fwd, -0.5 * length, 0.75 * length))
        lat = float(np.clip(lat, -0.3 * length, 0.3 * length))
        down = math.sqrt(max(length * length - fwd * fwd - lat * lat, 0.04))
        swing = math.atan2(fwd, down)  # forward angle of the hip-ankle line
        roll = math.atan2(lat, math.hypot(fwd, down))
        knee, geom = knee_for_length(self.athlete.thigh[k], self.athlete.shin[k], length)
        thigh = quat_mul(
            quat_from_yaw(psi), quat_from_euler([-swing + float(geom), roll, 0.0], EULER_ORDER)
        )
        hip = quat_to_euler(quat_mul(quat_conj(self.pelvis_anat()), thigh), EULER_ORDER)
        self.goal[_HIP[k]] = (hip[0], hip[1], 0.0)
        self.goal[_KNEE[k]] = (float(knee), 0.0, 0.0)
        self.knee_td = float(knee)
        self.goal[_ANKLE[k]] = (self._ankle_for_foot(k, -p.heel_up), 0.0, 0.0)

    def _ankle_for_foot(self, k: int, foot_pitch: float) -> float:
        """Ankle pitch that gives foot ``k`` the world pitch ``foot_pitch`` (toes down > 0)
        given where its shin is now."""
        shin = self._anat(self._shins[k : k + 1], [_SHIN[k]])[0]
        pitch = float(quat_to_euler(quat_mul(quat_conj(quat_from_yaw(self.heading())), shin),
                                    EULER_ORDER)[0])  # fmt: skip
        return float(np.clip(foot_pitch - pitch, -0.5, 0.9))

    def _pitch(self, body: int, neutral: int) -> float:
        """Anatomical pitch (rad) of a body in the heading frame (thigh forward < 0)."""
        q = quat_mul(self.world.data.xquat[body], quat_conj(self._neutral[neutral]))
        q = quat_mul(quat_conj(quat_from_yaw(self.heading())), q)
        return float(quat_to_euler(q, EULER_ORDER)[0])

    def _idle(self, t: float) -> None:
        """The idle leg. In flight, eqs. 3-4: the idle thigh mirrors the active one's travel
        since lift-off (pitches in the heading frame), so their reactions on the body
        cancel. In stance it swings forward with the stance's progress (time since touchdown
        over the expected stance) to where the next touchdown needs it, so that at lift-off
        it is already forward and moving: its forward momentum then cancels the stance leg's
        backward momentum. The knee is bent (shortened leg), the ankle flexed (toes up)."""
        a, i = self.active, 1 - self.active
        p = self.p
        if self.machine.current.name == "flight":
            act = self._pitch(self._thighs[a], _THIGH[a])
            want = self.lo_pitch[i] - (act - self.lo_pitch[a])
        else:
            prog = (t - self.t_touchdown) / max(self.stance_estimate, 0.05)
            sm = float(np.clip(prog, 0.0, 1.0))
            sm = sm * sm * (3.0 - 2.0 * sm)
            want = self.td_pitch + (p.swing_ready - self.td_pitch) * sm
        want = float(np.clip(want, -1.1, 0.7))
        hip = want - self._pitch(self._root, 0)
        self.goal[_HIP[i]] = (hip, 0.03 * (1 - 2 * i), 0.0)
        knee = p.idle_knee
        if self.machine.current.name != "flight":
            # the knee opens over the stance's second half, ready to reach for touchdown
            late = float(np.clip(2.0 * prog - 1.0, 0.0, 1.0))
            knee += (p.reach_knee - p.idle_knee) * late * late * (3.0 - 2.0 * late)
        self.goal[_KNEE[i]] = (knee, 0.0, 0.0)
        self.goal[_ANKLE[i]] = (-0.15, 0.0, 0.0)

    def _upper(self) -> None:
        """Eq. 5 (arms with the opposite hip), elbows bent, spine and neck held."""
        p = self.p
        hips = self.rig.current_angles()[list(_HIP), 0]
        for k in range(2):
            self.goal[_SHOULDER[k]] = (p.arm_gain * hips[1 - k] + p.arm_offset,
                                       0.15 * (1 - 2 * k), 0.0)  # fmt: skip
            self.goal[_ELBOW[k]] = (-p.elbow, 0.0, 0.0)
        for j in _SPINE:
            self.goal[j] = 0.0
        self.goal[joint_index("neck")] = (-0.1, 0.0, 0.0)

    def _attitude_torque(self) -> F64:
        """World torque on the pelvis that servos its attitude toward the desired roll
        (lean into the curve), pitch (slightly forward) and yaw (the desired facing)."""
        p = self.p
        v = self.speed
        lean = math.atan(v * v * self.curvature / self.g)
        want = quat_mul(quat_from_yaw(self.heading_d),
                        quat_from_euler([p.pitch, -lean, 0.0], EULER_ORDER))  # fmt: skip
        # the trunk's attitude and rate: the pelvis alone is light and sits between two
        # servoed joints, and damping its rate explicitly at the control rate rings
        d = self.world.data
        now = quat_mul(d.xquat[self._chest], quat_conj(self._neutral[_BODY["chest"]]))
        err = quat_log(quat_mul(want, quat_conj(now)))  # world rotation vector
        omega = d.cvel[self._chest, :3]
        # gains about the heading frame's axes (roll, pitch, yaw)
        h = self.heading()
        c, s = math.cos(h), math.sin(h)
        axes = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
        e_h = axes @ err
        w_h = axes @ omega
        kp = np.asarray(p.attitude_kp)
        kv = np.asarray(p.attitude_kv)
        torque = axes.T @ (self.inertia_unit * (kp * e_h - kv * w_h))
        # the part about the stance thigh's long axis only twists the leg against the foot's
        # grip on the ground: it stays within what the foot can hold (mu N times a quarter
        # of its length), or the leg spins about its axis
        k = self.active
        a = d.xanchor[self._knees[k]] - d.xanchor[self._hips[k]]
        a /= max(float(np.linalg.norm(a)), 1e-9)
        along = float(torque @ a)
        limit = self.p.yaw_grip * self.foot_length * max(float(self.senses.grf[2]), 0.0)
        torque -= (along - float(np.clip(along, -limit, limit))) * a
        return torque

    # ------------------------------------------------------------------ states
    def _states(self) -> list[State]:
        every = self.control_every

        def lawf(fn) -> FunctionController:  # type: ignore[no-untyped-def]
            return FunctionController(fn, every)

        def touching(_w: World, _t: float, _ti: float) -> bool:
            return bool(self.senses.foot_contact[self.active])

        def knee_bends(_w: World, _t: float, t_in: float) -> bool:
            return t_in >= 0.008

        def ball_down(_w: World, _t: float, _ti: float) -> bool:
            return bool(self.toe[self.active])

        def stance_fraction(_w: World, t: float, _ti: float) -> bool:
            lo, hi = self.p.toe_fraction
            frac = lo + (hi - lo) * self._s
            return t - self.t_touchdown >= frac * self.stance_estimate

        def knee_extended(_w: World, _t: float, t_in: float) -> bool:
            k = self.active
            knee = self.rig.current_angles()[_KNEE[k], 0]
            return t_in > 0.02 and knee <= self.knee_td + 0.05

        def left_ground(_w: World, _t: float, _ti: float) -> bool:
            return not bool(self.senses.foot_contact[self.active])

        def timeout(sec: float):  # type: ignore[no-untyped-def]
            return lambda _w, _t, t_in: t_in >= sec

        return [
            State("flight", lawf(self._flight), self._enter_flight,
                  ((touching, "loading"),)),
            State("loading", lawf(self._stance), self._enter_loading,
                  ((ball_down, "heel_toe"), (knee_bends, "heel"))),
            State("heel", lawf(self._stance), self._enter_heel,
                  ((ball_down, "heel_toe"), (timeout(0.12), "heel_toe"))),
            State("heel_toe", lawf(self._stance), self._enter_heel_toe,
                  ((stance_fraction, "toe"),)),
            State("toe", lawf(self._stance), self._enter_toe,
                  ((knee_extended, "unloading"), (left_ground, "flight"),
                   (timeout(0.3), "unloading"))),
            State("unloading", lawf(self._stance), self._enter_unloading,
                  ((left_ground, "flight"), (timeout(0.08), "flight"))),
        ]  # fmt: skip

    def _stiffness(self, stance: dict[str, float] | None) -> None:
        """The base stiffness with the active leg's stance values (``hip`` 0: the attitude
        torque only)."""
        stiff = per_joint(self.p.stiffness)
        if stance:
            a = self.active
            for name, v in stance.items():
                stiff[joint_index(f"{'lr'[a]}_{name}")] = v
        self.rig.set_stiffness(stiff)

    def _enter_flight(self, world: World, t: float) -> None:
        del world
        if self.machine.transitions:  # lift-off (not the first tick): swap the legs
            self.stance_estimate = float(np.clip(t - self.t_touchdown, 0.12, 0.4))
            self.log.liftoffs.append((t, self.active))
            self.active = 1 - self.active
            self.t_liftoff = t
            self.apex = -np.inf
        self.lo_hip[:] = self.rig.current_angles()[list(_HIP)]
        self.lo_pitch = [self._pitch(self._thighs[j], _THIGH[j]) for j in range(2)]
        self._stiffness(None)
        self.rig.support[:] = 0.0

    def _enter_loading(self, world: World, t: float) -> None:
        del world
        self.t_touchdown = t
        self.released = False
        k = self.active
        self.td_pitch = self._pitch(self._thighs[1 - k], _THIGH[1 - k])
        foot = self.world.data.xpos[self._feet[k]]
        self.log.touchdowns.append((t, k, float(foot[0]), float(foot[1])))
        self.steps += 1
        # adapt the thrust to the flight apex reached
        lo, hi = self.p.flight_height
        want = lo + (hi - lo) * self._s
        if np.isfinite(self.apex) and self.steps > 1:
            err = want - (self.apex - self.z_liftoff)
            self.thrust = float(np.clip(self.thrust + self.p.height_gain * err, 0.5, 2.0))
        self.goal[_KNEE[k]] = (self.knee_td, 0.0, 0.0)
        # the spring's rest length: the leg's length at touchdown as planned (hip to heel
        # with the knee at its touchdown angle), or as it landed if longer
        now = float(np.linalg.norm(self.world.data.xanchor[self._hips[k]] - self._support_point(t)))
        self.leg_rest = max(now, self.rest_length[k])
        self.leg_prev = 0.0
        self._stiffness({"hip": 0.0, "knee": self.p.knee_spring, "ankle": self.p.ankle_heel})
        self.rig.support[:] = 0.0
        self.rig.support[k] = self.p.support

    def _enter_heel(self, world: World, t: float) -> None:
        del world, t

    def _enter_heel_toe(self, world: World, t: float) -> None:
        del world
        self.t_heel_toe = t

    def _enter_toe(self, world: World, t: float) -> None:
        del world, t

    def _enter_unloading(self, world: World, t: float) -> None:
        del world, t
        self.z_liftoff = float(self.senses.com[2])

    def _flight(self, world: World, t: float) -> None:
        del world
        self.apex = max(self.apex, float(self.senses.com[2]))
        self._placement(self.active, t)

    def _stance(self, world: World, t: float) -> None:
        del world, t
        self.z_liftoff = float(self.senses.com[2])
        state = self.machine.current.name
        if state in ("toe", "unloading") and not self.released:
            # the thrust stops once the body rises at the take-off speed wanted
            vz = float(self.senses.com_vel[2])
            if vz >= self.takeoff_vz:
                self.released = True

    # ------------------------------------------------------------------ tick
    def control(self, world: World, t: float) -> None:
        s = self.senses
        s.update(t)
        self._contacts()
        pos = s.com[:2]
        self.heading_d, self.curvature, self.cross_track = self.course.steer(pos, t)
        self.machine.control(world, t)
        self._idle(t)
        self._upper()
        # eq. 6: targets move smoothly toward the goals (first-order, time constant)
        dt = self.control_every * world.timestep
        a = 1.0 if self.p.smoothing <= 0 else min(1.0, dt / self.p.smoothing)
        self.targets += a * (self.goal - self.targets)
        rig = self.rig
        rig.move(self.targets, 0.0, t)
        rig.apply(t)
        stance = self.machine.current.name != "flight"
        if stance:
            self._stance_hip_torque()
            self._leg_spring(t, dt)
        self._log(t)

    def _leg_length(self, k: int) -> float:
        d = self.world.data
        return float(np.linalg.norm(d.xanchor[self._hips[k]] - d.xanchor[self._ankles[k]]))

    def _support_point(self, t: float) -> F64:
        """Where the stance foot bears on the ground (world): the heel until the ball is
        down, then rolling toward the ball by the expected end of the heel-and-toe phase,
        then the ball (the paper's heel-to-metatarsus travel)."""
        k = self.active
        corners = self.senses.sole_corners()[k]
        ball = 0.5 * (corners[0] + corners[1])
        heel = 0.5 * (corners[2] + corners[3])
        state = self.machine.current.name
        if state in ("loading", "heel"):
            frac = 0.0
        elif state == "heel_toe":
            lo, hi = self.p.toe_fraction
            end = self.t_touchdown + (lo + (hi - lo) * self._s) * self.stance_estimate
            frac = float(np.clip((t - self.t_heel_toe) / max(end - self.t_heel_toe, 1e-3), 0, 1))
        else:
            frac = 1.0
        return heel + frac * (ball - heel)

    def _leg_spring(self, t: float, dt: float) -> None:
        """The stance leg as a spring between the hip and the support point: the knee and
        ankle torques (``-J^T f``, their columns of the support point's Jacobian) that make the
        force ``k (L0 - L) - c dL/dt`` along that line, ``L0`` its length at touchdown, plus
        the thrust in the toe phase. The force passes through the hip, so the hip stays free
        for the attitude servo; the knee carries the spring, the ankle the lever to the ball
        (the thrust). The knee's and ankle's own servos hold only roll and yaw."""
        k = self.active
        d = self.world.data
        point = self._support_point(t)
        line = d.xanchor[self._hips[k]] - point
        length = float(np.linalg.norm(line))
        u = line / max(length, 1e-6)
        rate = (length - self.leg_prev) / dt if self.leg_prev > 0 else 0.0
        self.leg_prev = length
        m, g = self.mass, self.g
        stiff = self.p.leg_stiffness * m * g / self.athlete.leg_length
        damp = 2.0 * self.p.leg_damping * math.sqrt(stiff * m)
        force = stiff * (self.leg_rest - length) - damp * rate
        if self.machine.current.name in ("toe", "unloading") and not self.released:
            force += self.thrust_force
        force = max(force, 0.0)
        self.leg_force = force
        mujoco.mj_jac(self.world.model, d, self._jacp, None, point, self._feet[k])
        cols = self._leg_cols[k]
        tau = -self._jacp[:, cols].T @ (force * u)
        ff = self.rig._ff
        ff[_KNEE[k]] += tau[0:3]
        ff[_ANKLE[k]] += tau[3:6]
        # the knee's and ankle's servos keep no pitch stiffness of their own
        ang = self.rig.current_angles()
        for j in (_KNEE[k], _ANKLE[k]):
            self.targets[j, 0] = ang[j, 0]
            self.goal[j, 0] = ang[j, 0]

    def _stance_hip_torque(self) -> None:
        """The stance hip makes the attitude torque on the pelvis, less what the idle hip's
        torque already does to it (the idle hip's reaction)."""
        d = self.world.data
        a, i = self.active, 1 - self.active
        want = self._attitude_torque()
        ff = self.rig._ff
        idle = np.zeros(3)
        del i
        rot_a = d.xmat[self._thighs[a]].reshape(3, 3)
        ff[_HIP[a]] = rot_a.T @ (-want - idle)

    def _log(self, t: float) -> None:
        s = self.senses
        d = self.world.data
        ang = self.rig.current_angles()
        feet = int(s.foot_contact[0]) | (int(s.foot_contact[1]) << 1)
        self.log.rows.append((
            t, s.com.copy(), s.com_vel.copy(), self.heading(),
            RUN_STATES.index(self.machine.current.name), self.active, feet,
            float(d.xpos[self._root][2]), bool(s.other_contact),
            ang[list(_HIP), 0].copy(), ang[list(_KNEE), 0].copy(), self.heading_d,
            self.cross_track, self.trunk_euler(),
        ))  # fmt: skip


def running_start(athlete: Athlete, speed: float, heading: float = 0.0) -> tuple[F64, F64]:
    """qpos and qvel of the runner in flight at ``speed`` along ``heading``: the left leg
    reaching forward for touchdown, the right trailing with its knee bent."""
    angles = np.zeros((NJ, 3))
    angles[_HIP[0]] = (-0.45, 0.0, 0.0)
    angles[_KNEE[0]] = (0.25, 0.0, 0.0)
    angles[_ANKLE[0]] = (-0.05, 0.0, 0.0)
    angles[_HIP[1]] = (0.25, 0.0, 0.0)
    angles[_KNEE[1]] = (1.2, 0.0, 0.0)
    angles[_ANKLE[1]] = (0.2, 0.0, 0.0)
    for k in range(2):
        angles[_SHOULDER[k]] = (0.9 * angles[_HIP[1 - k], 0] + 0.05, 0.15 * (1 - 2 * k), 0.0)
        angles[_ELBOW[k]] = (-1.4, 0.0, 0.0)
    q = athlete.standing_qpos(angles, pitch=0.08, clearance=0.05)
    if heading:
        q[3:7] = quat_mul(quat_from_yaw(heading), q[3:7])
        c, s = math.cos(heading), math.sin(heading)
        q[0], q[1] = c * q[0] - s * q[1], s * q[0] + c * q[1]
    v = np.zeros(6 + 3 * NJ)
    v[0] = speed * math.cos(heading)
    v[1] = speed * math.sin(heading)
    v[2] = 0.0
    return q, v
