"""Running (Hodgins et al. 1995, "Running"): a state machine over the active leg's contact with
the ground (flight, loading, heel, heel and toe, toe, unloading; the legs swap roles at
lift-off), foot placement by eqs. 1-2 with ground-speed matching, a knee that acts as a passive
spring in stance and an ankle that gives the thrust, the stance hip servoing the body's
attitude (roll, pitch, yaw, with a lean into curves), the idle leg mirroring the active one
(eqs. 3-4) and shortened, the arms swinging with the opposite hip (eq. 5), and every joint
following a smooth trajectory toward its desired angle (eq. 6). The user gives a speed
(2.5-5 m/s) and a facing direction or a path (:mod:`reactmocap.athletics.paths`).

The feet: the thesis bodies' toes are merged into the feet (the engine's characters have 15
ball joints), so the paper's two-part foot is a rigid sole box here. Heel and toe contact are
told apart by which of the box's corners touch the floor: heel contact is the rear corners,
toe contact the front ones; the toe phase rolls the foot about its front edge, as the paper's
foot rolls about the ball. Design and measurements: ``docs/athletics.md``."""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco
import numpy as np

from reactmocap.athletics.balance import knee_for_length1
from reactmocap.athletics.bodies import Athlete
from reactmocap.athletics.paths import Course, Straight
from reactmocap.athletics.rig import Rig, per_joint
from reactmocap.athletics.running_body import (
    ANKLE,
    CONJ,
    ELBOW,
    F64,
    FOOT,
    HIP,
    KNEE,
    LEG_JOINTS,
    NECK,
    NJ,
    SHIN,
    SHOULDER,
    SPINE,
    THIGH,
    YawMemo,
    clamp,
    euler_yxz,
    norm,
    pitch_yxz,
    qconj1,
    qmul1,
    quat_yxz,
    qyaw,
    running_start,
)
from reactmocap.athletics.running_params import (
    SPEED_RANGE,
    TUNED_SPEEDS,
    RunLog,
    RunParams,
    check_speed,
)
from reactmocap.athletics.senses import Senses
from reactmocap.errors import ConfigError
from reactmocap.rotations import quat_conj, wrap_angle
from reactmocap.sim.bodies import SIM_BODY_INDEX, SIM_PARENTS
from reactmocap.sim.controllers.base import FunctionController
from reactmocap.sim.controllers.machine import State, StateMachine, after
from reactmocap.sim.world import World

__all__ = [
    "RUN_STATES",
    "SPEED_RANGE",
    "TUNED_SPEEDS",
    "RunLog",
    "START_SPEED",
    "RunParams",
    "Runner",
    "check_speed",
    "running_start",
]

#: the flat positions in the ``(NJ, 3)`` goals of the upper body's rows, in
#: :meth:`Runner._upper`'s order, and of each idle leg's (hip, knee, ankle) rows (index
#: arrays: a tuple index is converted at every use; a flat tuple of floats converts at a
#: fraction of the cost of a nested one)
_UPPER = (3 * np.array((*SHOULDER, *ELBOW, *SPINE, NECK))[:, None] + np.arange(3)).reshape(-1)
_LEG_ROWS = tuple(
    (3 * np.array((HIP[i], KNEE[i], ANKLE[i]))[:, None] + np.arange(3)).reshape(-1)
    for i in range(2)
)
#: the states of the active leg (Fig. 3)
RUN_STATES = ("flight", "loading", "heel", "heel_toe", "toe", "unloading")
#: a sole corner closer than this to the floor (m) counts as touching
CORNER_TOUCH = 0.004
#: the placement's slow correction integrates from this time on (s)
INTEGRATE_AFTER = 1.0
#: the most of a step's speed error (m/s) that correction integrates
ERROR_CAP = 0.3
#: the fastest a run starts at (m/s): faster runs start at it and the desired speed ramps up
#: at :data:`ACCEL` (m/s^2); from a set pose at 5 m/s the first stance lost 1.6 m/s and the
#: runner fell recovering it
START_SPEED = 3.5
ACCEL = 1.5
#: the most the pitch error's integral holds (rad s)
PITCH_SUM = 0.1
#: the most leg force (body weights) of the commanded step
STEP_FORCE = 4.0
#: the commanded step takes over from the leg spring at the first touchdown after this (s)
STEP_AFTER = 2.0
#: the path correction integrates from this time on (s; the start from the set pose strays)
PATH_AFTER = 3.0
#: the most the path correction's integral (cross-track times curvature) holds (s)
PATH_SUM = 5.0
#: the arms' yaw terms act only where the course curves more than this (1/m): a straight
#: line (curvature 0) runs without them, as they slowed its strides
ARM_CURVE = 1e-6


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
        if not (isinstance(control_every, int) and control_every >= 1):
            raise ConfigError(f"control_every must be an int >= 1, got {control_every!r}")
        self.world = world
        self.athlete = athlete
        #: the speed asked for; ``speed`` is the desired speed now, which starts at most at
        #: :data:`START_SPEED` and ramps up to it
        self.target = check_speed(speed)
        self.speed = min(self.target, START_SPEED)
        self.course = course or Straight(0.0)
        self.params = params or RunParams()
        self.k = self.params.at(self.speed)
        self.accel = ACCEL
        self.character = character
        self.control_every = control_every
        self.p_frame = True
        self.rig = Rig(world, athlete, character)
        self.senses = Senses(world, athlete, character)
        self.log = RunLog()
        wc = world.characters[character]
        self.wc = wc
        m = world.model
        self.mass = self.rig.mass
        self.g = float(np.linalg.norm(m.opt.gravity))
        self._leg_length = athlete.leg_length  # a property: a mean at every read
        self.inertia_unit = self.mass * self._leg_length**2
        self._hips = [m.joint(wc.prefix + f"{s}_hip").id for s in "lr"]
        self._knees = [m.joint(wc.prefix + f"{s}_knee").id for s in "lr"]
        self._ankles = [m.joint(wc.prefix + f"{s}_ankle").id for s in "lr"]
        self._root = int(wc.body_ids[0])
        self._chest = int(wc.body_ids[SIM_BODY_INDEX["chest"]])
        self._thighs = wc.body_ids[list(THIGH)]
        self._shins = wc.body_ids[list(SHIN)]
        self._feet = wc.body_ids[list(FOOT)]
        self._neutral = athlete.neutral
        self._neutral_conj = quat_conj(athlete.neutral)
        self._bodies = np.asarray(wc.body_ids)
        self._jacp = np.zeros((3, m.nv))
        # the legs' joint pitches at every tick (_leg_pitches): each body a leg joint joins
        # (pelvis, thighs, shins, feet) and the chest turned into its anatomical frame once a
        # tick, into buffers made here, for the laws' pitches too (_tick_pitch); the
        # pitch-only column of the angles the laws read stays 0 elsewhere
        child = [j + 1 for j in LEG_JOINTS]
        parent = [int(SIM_PARENTS[c]) for c in child]
        # the parents first: their conjugates in one product
        parents = sorted(set(parent))
        parts = parents + sorted((set(child) - set(parents)) | {SIM_BODY_INDEX["chest"]})
        # rows of MjData's and the buffer's arrays as views made once (indexing per tick
        # cost as much as the products); the World keeps one MjData for its life
        self._anat_buf = anat = np.empty((len(parts), 4))
        self._xquat = xquat = world.data.xquat
        self._anat_rows = [(anat[k], xquat[int(wc.body_ids[b])], self._neutral_conj[b])
                           for k, b in enumerate(parts)]  # fmt: skip
        #: the tick's anatomical rotations by MuJoCo body id (rows of the buffer)
        self._anat_now = {int(wc.body_ids[b]): anat[k] for k, b in enumerate(parts)}
        self._parents_anat = anat[: len(parents)]
        self._parents_inv = inv = np.empty((len(parents), 4))
        self._leg_pairs = [(j, inv[parents.index(p)], anat[parts.index(c)])
                           for j, p, c in zip(LEG_JOINTS, parent, child)]  # fmt: skip
        self._q_rel = np.empty(4)
        # the tick's yaws of the facing (the heading frame's and its inverse), made once
        self._yaw_inv, self._yaw_fwd = YawMemo(), YawMemo()
        self._root_inv = inv[parents.index(0)]  # the pelvis's conjugate, this tick
        self._thigh_len, self._shin_len = athlete.thigh.tolist(), athlete.shin.tolist()
        # the attitude servo's last desired rotation and its inputs (_attitude_torque)
        self._want = np.array([1.0, 0.0, 0.0, 0.0])
        self._want_key: tuple[float, ...] = (math.nan,)
        self._want_signs: tuple[float, ...] = ()
        self._att_err = np.empty(3)
        self._att_axes = np.eye(3)
        self._att_axes_flat = self._att_axes.reshape(-1)
        self._iz = np.empty(len(self._bodies))  # the bodies' yaw inertias (yaw_momentum)
        self._angles = np.zeros((NJ, 3))
        self._hip_rows = np.array(HIP)
        self._knee_rows = np.array(KNEE)
        self._attitude_kp = np.asarray(self.params.attitude_kp)
        self._attitude_kv = np.asarray(self.params.attitude_kv)
        b = wc.ball_dof_start
        # the knee's and ankle's dofs of each leg
        self._leg_cols = [
            np.r_[b + 3 * KNEE[k] : b + 3 * KNEE[k] + 3, b + 3 * ANKLE[k] : b + 3 * ANKLE[k] + 3]
            for k in range(2)
        ]
        # heel-to-ball length l_f of eqs. 1-2: the sole box's length
        self.foot_length = 2.0 * float(m.geom_size[wc.sole_ids[0], 0])
        # read once: World.timestep reads the model's options anew at every call
        self._timestep = world.timestep
        self._base_stiffness = per_joint(self.params.stiffness)
        self.machine = StateMachine(self._states(), "flight", control_every)
        self._reset_state()

    # ------------------------------------------------------------------ state
    def _reset_state(self) -> None:
        self.speed = min(self.target, START_SPEED)
        self.k = k = self.params.at(self.speed)
        self.active = 0  # the leg on the ground or being placed (0 left, 1 right)
        self.t_touchdown = 0.0
        self.t_heel_toe = 0.0
        self.stance_estimate = k["stance_time"]
        self.vz_touchdown = 0.0
        #: the stance the commanded step lasts (s; 0: the leg spring's stance)
        self.step_stance = 0.0
        self.targets = np.zeros((NJ, 3))
        self.goal = np.zeros((NJ, 3))
        self.heel = np.zeros(2, dtype=bool)
        self.toe = np.zeros(2, dtype=bool)
        self.heading_d = 0.0
        self.facing_rate = 0.0  # the desired facing's turn per second, this tick
        self._steered = False
        self.curvature = 0.0
        self.cross_track = math.nan
        self.knee_td = 0.3
        self.leg_rest = 0.0
        self.leg_prev = 0.0
        self.leg_force = 0.0
        self.lo_pitch = [0.0, 0.0]
        self.td_pitch = 0.0
        self.pitch_sum = 0.0
        self.path_sum = 0.0
        self.speed_bias = 0.0
        self.step_start: tuple[float, F64] | None = None
        self.thrust_force = k["thrust"] * self.mass * self.g
        self.released = False
        self.vz_peak = -math.inf
        self.steps = 0

    def reset(self, world: World) -> None:
        del world
        self._reset_state()
        self.rig.reset()
        self.senses.time = -1.0
        angles = self._leg_pitches()
        self.targets[:] = angles
        self.goal[:] = angles
        self.machine.reset(self.world)
        self.rig.set_stiffness(self._base_stiffness)
        self.rig.gravity_compensation = True

    # ------------------------------------------------------------------ geometry
    def heading(self) -> float:
        """The pelvis's heading (rad about +Z)."""
        return self.senses.heading()

    def _anat(self, body: int, neutral: int) -> F64:
        """A body's anatomical world rotation."""
        return qmul1(self._xquat[body], self._neutral_conj[neutral])

    def _pitch(self, body: int, neutral: int, heading: float) -> float:
        """Anatomical pitch (rad) of a body in the heading frame (thigh forward < 0)."""
        return pitch_yxz(qmul1(qyaw(-heading), self._anat(body, neutral)))

    def _joint_pitch(self, joint: int) -> float:
        """Anatomical pitch (rad) of a ball joint: its child's rotation relative to its
        parent's, both in their anatomical frames (as ``Athlete.joint_angles``)."""
        child = joint + 1
        parent = int(SIM_PARENTS[child])
        rel = qmul1(qconj1(self._anat(self._bodies[parent], parent)),
                    self._anat(self._bodies[child], child))  # fmt: skip
        return pitch_yxz(rel)

    def _leg_pitches(self) -> F64:
        """The pitch of the legs' joints (the only joint angles the laws read) in column 0
        of the ``(NJ, 3)`` angles (a buffer reused every tick), as :meth:`_joint_pitch`:
        MuJoCo's quaternion product on one quaternion at a time, since numpy's
        vectorised products and arctan2 differ from it in the last bits. Also the tick's
        anatomical rotations of the legs' bodies and the chest (:attr:`_anat_now`)."""
        for out, q, conj in self._anat_rows:
            mujoco.mju_mulQuat(out, q, conj)
        # the parents' conjugates (mju_negQuat's sign flips) in one product
        np.multiply(self._parents_anat, CONJ, out=self._parents_inv)
        rel, angles = self._q_rel, self._angles
        for j, inv, c in self._leg_pairs:
            mujoco.mju_mulQuat(rel, inv, c)
            angles[j, 0] = pitch_yxz(rel)
        return angles

    def _tick_pitch(self, body: int, heading: float) -> float:
        """:meth:`_pitch` of a body of :attr:`_anat_now` within the tick (its rotation made
        once by :meth:`_leg_pitches` at the tick's start)."""
        return pitch_yxz(qmul1(self._yaw_inv(-heading), self._anat_now[body]))

    def trunk_euler(self) -> tuple[float, float, float]:
        """Chest pitch, roll and yaw (anatomical, heading frame, rad)."""
        chest = SIM_BODY_INDEX["chest"]
        return euler_yxz(qmul1(qyaw(-self.heading()), self._anat(self._chest, chest)))

    def _contacts(self) -> None:
        """Which feet touch with their heel (rear corners) and toe (front corners)."""
        s = self.senses
        floor = float(self.world.data.geom_xpos[s.floor][2])
        # floats: eight corners' numpy calls cost more than the comparisons
        for k, (corners, touch) in enumerate(zip(s.sole_corners()[..., 2].tolist(),
                                                 s.foot_contact.tolist())):  # fmt: skip
            near = [z - floor < CORNER_TOUCH for z in corners]
            toe = touch and (near[0] or near[1])
            heel = touch and (near[2] or near[3])
            self.toe[k] = toe
            self.heel[k] = heel or (touch and not toe)  # touching by an edge only

    # ------------------------------------------------------------------ control laws
    def _placement(self, leg: int, heading: float) -> None:
        """Eqs. 1-2 and the inverse kinematics of ``leg``: hip and knee goals that put the
        heel at the placement point with the touchdown leg length, ankle goal for a heel
        strike, and ground-speed matching."""
        k = self.k
        d = self.world.data
        s = self.senses
        v = s.com_vel[:2].tolist()  # floats: the same roundings as numpy's scalars, faster
        hd = self.heading_d
        # on a curve the desired velocity is the one a moment ahead, turned into the curve
        # (the centripetal acceleration's feed-forward): without it the velocity lagged the
        # facing by up to 0.1 rad and the stances were irregular
        lead = hd + k["turn_lead"] * self.speed * self.curvature
        vd = (self.speed * math.cos(lead), self.speed * math.sin(lead))
        ts, lf = self.stance_estimate, self.foot_length
        x_hh = 0.5 * (ts * v[0] - math.cos(heading) * lf) + k["speed_gain"] * (v[0] - vd[0])
        y_hh = 0.5 * (ts * v[1] - math.sin(heading) * lf) + k["speed_gain"] * (v[1] - vd[1])
        # the slow part of the speed error (the strides' losses, which the proportional gain
        # alone leaves as a steady error) moves the placement along the desired direction
        x_hh += self.speed_bias * math.cos(hd)
        y_hh += self.speed_bias * math.sin(hd)
        # eqs. 1-2 place the heel relative to the body's centre line (the COM), a step width
        # apart, rather than under the hip joint 8 cm to the side (runners land near the
        # midline); the hip-to-heel vector follows from where the hip is now
        c, sn = math.cos(heading), math.sin(heading)
        hip = d.xanchor[self._hips[leg]].tolist()
        com = s.com.tolist()
        off = (x_hh + com[0] - hip[0], y_hh + com[1] - hip[1])
        fwd = c * off[0] + sn * off[1]
        lat = -sn * off[0] + c * off[1] + (0.5 if leg == 0 else -0.5) * k["step_width"]
        if k["turn_place"] > 0 and self.world.data.time >= PATH_AFTER:
            # toward the curve's outside by the turn's lean: the leg's force then gives the
            # centripetal force (eqs. 1-2 make it only from a velocity lagging the facing);
            # not over the start, whose first steps it upset (falls within 1-2.4 s)
            lat -= k["turn_place"] * self._leg_length * self.speed**2 * self.curvature / self.g
        # ground-speed matching: the foot reaches further forward while it is high and comes
        # back over the last moments before touchdown (predicted from the lowest sole corner
        # and the body's vertical speed), so it meets the ground moving back under the body
        vz = float(s.com_vel[2])
        low = float(np.minimum.reduce(s.sole_corners()[leg, :, 2]))  # .min(): a Python call more
        to_go = low / -vz if vz < -1e-3 else np.inf
        fwd += k["speed_matching"] * clamp(to_go / k["retract_time"], 0.0, 1.0)
        fwd += 0.3 * lf  # the heel sits behind the ankle
        ul, ll = self._thigh_len[leg], self._shin_len[leg]  # floats: numpy's values
        length = k["touchdown_leg"] * (ul + ll)
        fwd = clamp(fwd, -0.5 * length, 0.75 * length)
        reach = k["lateral_reach"] * length
        lat = clamp(lat, -reach, reach)
        down = math.sqrt(max(length * length - fwd * fwd - lat * lat, 0.04))
        swing = math.atan2(fwd, down)  # forward angle of the hip-ankle line
        roll = math.atan2(lat, math.hypot(fwd, down))
        knee, geom = knee_for_length1(ul, ll, length)
        thigh = qmul1(self._yaw_fwd(heading), quat_yxz(-swing + geom, roll, 0.0))
        # the pelvis's conjugate: made by _leg_pitches this tick, as qconj1 makes it
        hip_pitch, hip_roll, _ = euler_yxz(qmul1(self._root_inv, thigh))
        self.knee_td = knee
        shin = self._tick_pitch(self._shins[leg], heading)
        ankle = clamp(-k["heel_up"] - shin, -0.5, 0.9)
        # the leg's hip, knee and ankle rows in one write
        self.goal.reshape(-1)[_LEG_ROWS[leg]] = (hip_pitch, hip_roll, 0.0, self.knee_td, 0.0,
                                                 0.0, ankle, 0.0, 0.0)  # fmt: skip

    def _idle(self, t: float, heading: float) -> None:
        """The idle leg. In flight, eqs. 3-4: the idle thigh mirrors the active one's travel
        since lift-off (pitches in the heading frame), so their reactions on the body
        cancel. In stance it swings forward with the stance's progress (time since touchdown
        over the expected stance) to where the next touchdown needs it: at lift-off it is
        forward and moving, and its momentum cancels the stance leg's. The knee is bent
        (shortened leg) and opens late in the stance; the ankle is flexed (toes up)."""
        k = self.k
        a, i = self.active, 1 - self.active
        knee = k["idle_knee"]
        if self.machine.current.name == "flight":
            act = self._tick_pitch(self._thighs[a], heading)
            want = self.lo_pitch[i] - (act - self.lo_pitch[a])
        else:
            prog = (t - self.t_touchdown) / max(self.stance_estimate, 0.05)
            sm = clamp(prog, 0.0, 1.0)
            want = self.td_pitch + (k["swing_ready"] - self.td_pitch) * sm * sm * (3.0 - 2.0 * sm)
            late = clamp(2.0 * prog - 1.0, 0.0, 1.0)
            knee += (k["reach_knee"] - k["idle_knee"]) * late * late * (3.0 - 2.0 * late)
        hip = clamp(want, -1.1, 0.7) - self._tick_pitch(self._root, heading)
        # one write for the leg's three rows (each row's write cost as much as its law)
        self.goal.reshape(-1)[_LEG_ROWS[i]] = (hip, 0.03 * (1 - 2 * i), 0.0, knee, 0.0, 0.0,
                                               -0.15, 0.0, 0.0)  # fmt: skip

    def _upper(self, hips: F64) -> None:
        """Eq. 5 (arms with the opposite hip), elbows bent, spine and neck held."""
        k = self.k
        arm = (k["arm_gain"] * hips[::-1] + k["arm_offset"]).tolist()  # each opposite hip's
        if ((k["arm_yaw"] > 0 or k["arm_yaw_rate"] > 0) and abs(self.curvature) > ARM_CURVE
                and self.world.data.time >= PATH_AFTER):  # fmt: skip
            # the arms counter-rotate against the trunk's yaw past the facing (``arm_yaw``):
            # their reaction turns the trunk without the stance foot's grip
            chest = self._anat(self._chest, SIM_BODY_INDEX["chest"])
            spin = k["arm_yaw"] * euler_yxz(qmul1(qyaw(-self.heading_d), chest))[2]
            if k["arm_yaw_rate"] > 0:
                # and against its yaw rate past the facing's (``arm_yaw_rate``): the rate
                # leads the angle, within the stance that makes the yaw momentum
                wz = float(self.world.data.cvel[self._chest, 2])
                spin += k["arm_yaw_rate"] * (wz - self.facing_rate)
            arm = [arm[0] + spin, arm[1] - spin]  # left back, right forward for a trunk ahead
        elbow = -k["elbow"]
        # one write for the seven rows (each row's write cost as much as its law)
        self.goal.reshape(-1)[_UPPER] = (arm[0], 0.15, 0.0, arm[1], -0.15, 0.0, elbow, 0.0, 0.0,
                                         elbow, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                                         -0.1, 0.0, 0.0)  # fmt: skip

    def _attitude_torque(self, heading: float) -> F64:
        """World torque on the trunk that servos its attitude toward the desired roll (a
        lean into the curve), pitch (slightly forward) and yaw (the desired facing)."""
        k = self.k
        lean = k["lean"] * math.atan(self.speed**2 * self.curvature / self.g)
        # the same inputs (zeros' signs too: they sign the quaternion's zeros) as the last
        # tick's, on a straight stretch most ticks: the same quaternion
        key = (self.heading_d, k["pitch"], lean)
        sign = math.copysign
        signs = (sign(1.0, key[0]), sign(1.0, key[1]), sign(1.0, key[2]))
        if key != self._want_key or signs != self._want_signs:
            self._want = qmul1(qyaw(self.heading_d), quat_yxz(k["pitch"], -lean, 0.0))
            self._want_key, self._want_signs = key, signs
        want = self._want
        # the chest's attitude and rate: the pelvis alone is light and sits between two
        # servoed joints, and damping its rate explicitly at the control rate rings
        d = self.world.data
        now = self._anat_now[self._chest]
        err = self._att_err
        mujoco.mju_quat2Vel(err, qmul1(want, qconj1(now)), 1.0)  # world rotation vector
        c, s = math.cos(heading), math.sin(heading)
        # rows roll, pitch, yaw: [[c, s, 0], [-s, c, 0], [0, 0, 1]] (its entries written
        # into a buffer, as a nested list converted at four times the cost)
        axes, flat = self._att_axes, self._att_axes_flat
        flat[0], flat[1], flat[3], flat[4] = c, s, -s, c
        local = axes @ err
        rate = axes @ d.cvel[self._chest, :3]
        if (k["yaw_momentum"] > 0 and abs(self.curvature) > ARM_CURVE
                and d.time >= PATH_AFTER):  # fmt: skip
            # the yaw damped on the whole body's mean rate (``yaw_momentum``): the swing leg
            # and arms carry yaw momentum the chest's rate misses, and at a reversal it
            # carried the chest past the facing in flight (mj_subtreeVel has run: Senses;
            # cinert's and subtree_angmom's origin is the same, the body's COM)
            iz = np.take(d.cinert[:, 2], self._bodies, out=self._iz).sum()
            body = float(d.subtree_angmom[self._root, 2]) / max(float(iz), 1e-9)
            rate[2] += k["yaw_momentum"] * (body - rate[2])
        gain = self.inertia_unit * (self._attitude_kp * local - self._attitude_kv * rate)
        if k["pitch_integral"] > 0:
            dt = self.control_every * self._timestep
            self.pitch_sum = clamp(self.pitch_sum + local[1] * dt, -PITCH_SUM, PITCH_SUM)
            gain[1] += self.inertia_unit * k["pitch_integral"] * self.pitch_sum
        torque = axes.T @ gain
        if k["attitude_ramp"] > 0:
            # eased in after touchdown: the torque's reaction drives the thigh, and at once
            # it drove the heel into the ground (11-13 body weights) and it bounced off
            ease = clamp((self.world.data.time - self.t_touchdown) / k["attitude_ramp"], 0, 1)
            torque *= ease * ease * (3.0 - 2.0 * ease)
        limit = k["attitude_limit"]
        if k["touchdown_limit"] > 0 and self.machine.current.name in ("loading", "heel"):
            # until the ball is down: at once a large torque drove the heel into the ground
            # and the foot bounced off (the turning runner's falls at 2.5 m/s)
            limit = min(limit, k["touchdown_limit"]) if limit > 0 else k["touchdown_limit"]
        if limit > 0:
            top = limit * self.mass * self.g * self._leg_length
            size = norm(torque)
            if size > top:
                torque *= top / size
        # the part about the stance thigh's long axis only twists the leg against the foot's
        # grip on the ground: it stays within what the foot can hold, or the leg spins
        leg = self.active
        axis = d.xanchor[self._knees[leg]] - d.xanchor[self._hips[leg]]
        axis /= max(norm(axis), 1e-9)
        along = float(torque @ axis)
        grf = self.senses.grf
        load = float(grf[2])
        if k["grip_reserve"] > 0 and d.time >= PATH_AFTER:
            # less the friction the horizontal force takes: at the full grip the outer foot
            # on a tight loop spun in its push (``grip_reserve``)
            load -= k["grip_reserve"] * math.hypot(float(grf[0]), float(grf[1]))
        limit = k["yaw_grip"] * self.foot_length * max(load, 0.0)
        return torque - (along - clamp(along, -limit, limit)) * axis

    def _support_point(self, t: float) -> F64:
        """Where the stance foot bears on the ground (world): the heel until the ball is
        down, then rolling toward the ball by the expected end of the heel-and-toe phase,
        then the ball (the paper's heel-to-metatarsus travel)."""
        corners = self.senses.sole_corners()[self.active]
        state = self.machine.current.name
        # each of the heel and the ball only where the phase reads it
        if state in ("loading", "heel"):
            return 0.5 * (corners[2] + corners[3])  # the heel
        ball = 0.5 * (corners[0] + corners[1])
        if state == "heel_toe":
            heel = 0.5 * (corners[2] + corners[3])
            end = self.t_touchdown + self.k["toe_fraction"] * self.stance_estimate
            span = max(end - self.t_heel_toe, 1e-3)
            frac = clamp((t - self.t_heel_toe) / span, 0.0, 1.0)
            return heel + frac * (ball - heel)
        return ball

    def _step_force(self, t: float, up: float) -> float:
        """The leg force (N, along the leg; ``up`` its vertical share) of the commanded step:
        the body's vertical speed follows a half-cosine from its touchdown value to
        ``step_takeoff`` over ``step_stance``, then the leg lets go."""
        k = self.k
        ts = self.step_stance
        s = t - self.t_touchdown
        if s >= ts or not self.senses.foot_contact[self.active]:
            # pushing with the foot off the ground only swings the leg (the law wound up and
            # the leg kicked the body over)
            return 0.0
        dv = k["step_takeoff"] - self.vz_touchdown
        phase = math.pi * s / ts
        want = self.vz_touchdown + 0.5 * dv * (1.0 - math.cos(phase))
        acc = 0.5 * dv * math.pi / ts * math.sin(phase)
        vz = float(self.senses.com_vel[2])
        fz = self.mass * (self.g + acc + k["step_gain"] * (want - vz))
        return min(fz / max(up, 0.5), STEP_FORCE * self.mass * self.g)

    def _leg_spring(self, t: float, dt: float, angles: F64) -> None:
        """The stance knee as a spring and the ankle as the thrust: the leg's length is the
        hip-to-ankle distance (what the knee's bend sets), ``L0`` the planned touchdown
        length, and the force ``k (L0 - L) - c dL/dt`` (plus the thrust in the toe phase)
        acts along the line from the support point to the hip, made by the knee's and
        ankle's torques ``-J^T f`` (their columns of the support point's Jacobian). The force
        passes through the hip, which stays free for the attitude servo; the knee carries
        the spring and the ankle the lever to the ball. While only the heel touches the
        ankle is left free, so the forefoot comes down. The knee's and ankle's own servos
        hold only their roll and yaw."""
        leg = self.active
        k = self.k
        d = self.world.data
        hip = d.xanchor[self._hips[leg]]
        length = norm(hip - d.xanchor[self._ankles[leg]])
        point = self._support_point(t)
        line = hip - point
        u = line / max(norm(line), 1e-6)
        rate = (length - self.leg_prev) / dt if self.leg_prev > 0 else 0.0
        self.leg_prev = length
        stiff = k["leg_stiffness"] * self.mass * self.g / self._leg_length
        damp = 2.0 * k["leg_damping"] * math.sqrt(stiff * self.mass)
        state = self.machine.current.name
        if self.step_stance:
            force = self._step_force(t, float(u[2]))
        else:
            force = stiff * (self.leg_rest - length) - damp * rate
            if state in ("toe", "unloading") and not self.released:
                force += self.thrust_force
        force = max(force, 0.0)
        self.leg_force = force
        mujoco.mj_jac(self.world.model, d, self._jacp, None, point, self._feet[leg])
        tau = -self._jacp[:, self._leg_cols[leg]].T @ (force * u)
        ff = self.rig.feedforward
        ff[KNEE[leg]] += tau[0:3]
        if state not in ("loading", "heel"):
            ff[ANKLE[leg]] += tau[3:6]
        # the knee's and ankle's servos keep no pitch stiffness of their own
        for j in (KNEE[leg], ANKLE[leg]):
            self.targets[j, 0] = self.goal[j, 0] = angles[j, 0]

    # ------------------------------------------------------------------ states
    def _states(self) -> list[State]:
        every = self.control_every

        def law(fn: Callable[[World, float], None]) -> FunctionController:
            return FunctionController(fn, every)

        def touching(_w: World, _t: float, _ti: float) -> bool:
            return bool(self.senses.foot_contact[self.active])

        def knee_bends(_w: World, _t: float, t_in: float) -> bool:
            return t_in >= 0.008

        def ball_down(_w: World, _t: float, _ti: float) -> bool:
            return bool(self.toe[self.active])

        def stance_fraction(_w: World, t: float, _ti: float) -> bool:
            return t - self.t_touchdown >= self.k["toe_fraction"] * self.stance_estimate

        def knee_extended(_w: World, t: float, t_in: float) -> bool:
            if self.step_stance:  # the commanded step lets go at its stance time
                return t - self.t_touchdown >= self.step_stance
            knee = self._angles[KNEE[self.active], 0]  # _joint_pitch's, made this tick
            return t_in > 0.02 and knee <= self.knee_td + 0.05

        def left_ground(_w: World, _t: float, _ti: float) -> bool:
            return not bool(self.senses.foot_contact[self.active])

        return [
            State("flight", law(self._flight), self._enter_flight, ((touching, "loading"),)),
            State("loading", law(self._stance), self._enter_loading,
                  ((ball_down, "heel_toe"), (knee_bends, "heel"))),
            State("heel", law(self._stance), None,
                  ((ball_down, "heel_toe"), (after(0.12), "heel_toe"))),
            State("heel_toe", law(self._stance), self._enter_heel_toe,
                  ((stance_fraction, "toe"),)),
            State("toe", law(self._stance), None,
                  ((knee_extended, "unloading"), (left_ground, "flight"),
                   (after(0.3), "unloading"))),
            State("unloading", law(self._stance), None,
                  ((left_ground, "flight"), (after(0.08), "flight"))),
        ]  # fmt: skip

    def _set_stiffness(self, stance: bool) -> None:
        """The base stiffness; in stance the active hip's servo is off (the attitude torque
        only) and its knee and ankle servos hold roll and yaw."""
        stiff = self._base_stiffness.copy()
        self.rig.axis_gain[:, 0] = 1.0
        if stance:
            a = self.active
            stiff[HIP[a]] = 0.0
            stiff[KNEE[a]] = self.k["knee_hold"]
            stiff[ANKLE[a]] = self.k["ankle_hold"]
        self.rig.set_stiffness(stiff)

    def _enter_flight(self, world: World, t: float) -> None:
        del world
        if self.machine.transitions:  # lift-off (not the first tick): swap the legs
            # smoothed: in turns the stance varies step to step and feeds the next placement
            last = clamp(t - self.t_touchdown, 0.12, 0.4)
            blend = self.k["stance_blend"]
            if blend < 1:
                last = self.stance_estimate + blend * (last - self.stance_estimate)
            self.stance_estimate = self.step_stance * self.k["step_placement"] or last
            self.log.liftoffs.append((t, self.active))
            self.active = 1 - self.active
        h = self.heading()
        self.lo_pitch = [self._tick_pitch(self._thighs[j], h) for j in range(2)]
        self._set_stiffness(False)

    def _enter_loading(self, world: World, t: float) -> None:
        del world
        self.t_touchdown = t
        self.released = False
        self.vz_peak = -math.inf
        self.vz_touchdown = float(self.senses.com_vel[2])
        # the start runs on the leg spring: from the set pose the commanded step fell
        switch = not self.step_stance and t >= STEP_AFTER and self.k["step_stance"] > 0
        self.step_stance = self.k["step_stance"] if t >= STEP_AFTER else 0.0
        leg = self.active
        d = self.world.data
        self.td_pitch = self._tick_pitch(self._thighs[1 - leg], self.heading())
        foot = d.xpos[self._feet[leg]]
        self.log.touchdowns.append((t, leg, float(foot[0]), float(foot[1])))
        self.steps += 1
        # the placement's slow correction from the last step's speed (distance along the
        # desired direction over its duration)
        com = self.senses.com[:2].copy()
        if self.step_start is not None and t > self.step_start[0] + 0.05:
            h = self.heading_d
            dx, dy = (com - self.step_start[1]).tolist()
            dist = dx * math.cos(h) + dy * math.sin(h)
            if self.k["step_chord"] > 0 and abs(self.curvature) > ARM_CURVE:
                # on a curve the velocity lags the facing: along the step's own chord
                chord = math.hypot(dx, dy)
                dist += self.k["step_chord"] * (chord - dist)
            err = dist / (t - self.step_start[0]) - self.speed
            # not over the start (its first steps lose up to 1 m/s, which the proportional
            # gain recovers and the slow part would wind up on) nor while the speed ramps up
            if t >= INTEGRATE_AFTER and self.speed >= self.target:
                # a step's error counts at most ERROR_CAP: a bias that grew 5 cm a step moved
                # the feet back faster than the legs could follow, and the runner sank
                cap = ERROR_CAP
                bias = self.speed_bias + self.k["speed_integral"] * clamp(err, -cap, cap)
                self.speed_bias = clamp(bias, -0.3, 0.3)
        if switch:
            # the commanded step's correction starts at its steady value: built up from the
            # spring's, it took 6-8 s and the step ran up to 0.4 m/s slow meanwhile
            self.speed_bias = self.k["step_bias"]
        self.step_start = (t, com)
        # the spring's rest length: the hip-to-ankle length at touchdown as planned, or as
        # it landed if longer
        now = float(np.linalg.norm(d.xanchor[self._hips[leg]] - d.xanchor[self._ankles[leg]]))
        planned = self.k["touchdown_leg"] * (self.athlete.thigh[leg] + self.athlete.shin[leg])
        self.leg_rest = max(now, planned)
        self.leg_prev = 0.0
        self._set_stiffness(True)

    def _enter_heel_toe(self, world: World, t: float) -> None:
        del world
        self.t_heel_toe = t

    def _flight(self, world: World, t: float) -> None:
        del world, t
        self._placement(self.active, self.heading_d if self.p_frame else self.heading())

    def _stance(self, world: World, t: float) -> None:
        del world
        # in the push the stance knee's and ankle's servos keep only a share of their gains
        # about bending (roll and yaw held): their damping there took half the leg law's push
        state = self.machine.current.name
        hold = 1.0
        if state in ("toe", "unloading"):
            hold = self.k["push_hold"]
            if self.step_stance and self.k["push_ramp"] > 0:
                # eased out over the push, as the leg's speed (and the servos' damping) grows
                done = clamp((t - self.t_touchdown) / self.step_stance, 0.0, 1.0)
                hold *= 1.0 - self.k["push_ramp"] * done
        a = self.active
        self.rig.axis_gain[KNEE[a], 0] = self.rig.axis_gain[ANKLE[a], 0] = hold
        if not self.released and state in ("toe", "unloading"):
            # the thrust stops once the body rises at the take-off speed wanted, or once its
            # rise slows (the take-off speed out of reach: pushing on to lift-off drove the
            # body forward into a long flight and a hard landing far ahead)
            vz = float(self.senses.com_vel[2])
            self.released = vz >= self.k["takeoff_vz"] or vz < self.vz_peak - self.k["thrust_drop"]
            self.vz_peak = max(self.vz_peak, vz)

    # ------------------------------------------------------------------ tick
    def control(self, world: World, t: float) -> None:
        s = self.senses
        s.update(t)
        # the joints' pitches and the bodies' anatomical rotations, before the laws read them
        angles = self._leg_pitches()
        self._contacts()
        want, self.curvature, self.cross_track = self.course.steer(s.com[:2], t)
        if self.k["path_integral"] > 0 and math.isfinite(self.cross_track) and t >= PATH_AFTER:
            # the steady offset a curve leaves (pure pursuit's chord, the feed-forward's lead)
            # grows with the curvature and flips with it: integrated and applied in proportion
            # to the curvature, it carries over a figure eight's reversal (a plain integral
            # of the error was wrong-signed there and the runner fell)
            dt = self.control_every * self._timestep
            kap = self.curvature
            self.path_sum = clamp(self.path_sum + self.cross_track * kap * dt, -PATH_SUM, PATH_SUM)
            want -= self.k["path_integral"] * self.path_sum * kap
        # the facing turns at a limited rate whatever the course asks (an abrupt change of
        # facing throws the runner down)
        if self._steered:
            step = wrap_angle(want - self.heading_d)
            limit = self.k["turn_rate"] * self.control_every * self._timestep
            turn = clamp(step, -limit, limit)
            self.heading_d += turn
            self.facing_rate = turn / (self.control_every * self._timestep)
        else:
            self.heading_d, self._steered = want, True
        if self.speed < self.target:
            # the desired speed ramps up from the start's, and the tuning with it
            self.speed = min(
                self.target, self.speed + self.accel * self.control_every * self._timestep
            )
            self.k = self.params.at(self.speed)
            self.thrust_force = self.k["thrust"] * self.mass * self.g
        self.machine.control(world, t)
        # the frame the legs are placed and swung in: the desired facing, not the pelvis's
        # (which yaws back and forth with every stride)
        heading = self.heading_d if self.p_frame else self.heading()
        self._idle(t, heading)
        hips = angles[self._hip_rows, 0]
        self._upper(hips)
        # eq. 6: the targets move smoothly toward the goals (first order, time constant)
        dt = self.control_every * self._timestep
        smoothing = self.k["smoothing"]
        self.targets += min(1.0, dt / smoothing if smoothing > 0 else 1.0) * (
            self.goal - self.targets
        )
        rig = self.rig
        rig.move(self.targets, 0.0, t)
        rig.apply(t)
        if self.machine.current.name != "flight":
            # the stance hip makes the attitude torque on the trunk (its reaction is on the
            # thigh); then the leg spring adds the knee's and ankle's torques
            rot = world.data.xmat[self._thighs[self.active]].reshape(3, 3)
            rig.feedforward[HIP[self.active]] = -rot.T @ self._attitude_torque(heading)
            self._leg_spring(t, dt, angles)
        self._log(t, angles, hips)

    def _log(self, t: float, angles: F64, hips: F64) -> None:
        s = self.senses
        feet = int(s.foot_contact[0]) | (int(s.foot_contact[1]) << 1)
        h = s.heading()
        self.log.rows.append((
            t, s.com.copy(), s.com_vel.copy(), h,
            RUN_STATES.index(self.machine.current.name), self.active, feet,
            float(self.world.data.xpos[self._root][2]), bool(s.other_contact),
            hips, angles[self._knee_rows, 0], self.heading_d, self.cross_track,
            # trunk_euler's pitch (the pelvis's heading: not the tick's made-once yaw)
            pitch_yxz(qmul1(qyaw(-h), self._anat_now[self._chest])),
        ))  # fmt: skip
