"""The mocap as the whole-body tracker follows a whole clip: its ground path (heading and
horizontal position) re-anchored to where the feet really are, its pelvis and centre-of-mass
targets shifted so its capture point stays inside the feet, a mocap swing foot's landing moved
by the capture point's error, capture-point balance steps, and a pushed walk's clip played
faster while the body is faster than it. The base of
:class:`~reactmocap.sim.controllers.wholebody.WholeBodyTracker`, which turns these targets into
joint torques; why each part exists: ``docs/tracking.md``."""

from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.rotations import quat_from_yaw, wrap_angle
from reactmocap.sim.controllers.stepping import (
    Step,
    clamp_to_support,
    convex_hull,
    outside_distance,
    step_target,
)
from reactmocap.sim.feet import foot_soles, sole_corners_world
from reactmocap.sim.reference import ReferencePath, sole_speed
from reactmocap.sim.world import World

__all__ = ["AnchoredReference"]

F64 = NDArray[np.float64]
# no balance step once the pelvis has tilted this far from its start (cos 35 deg), nor after it
# ever has: a body flung head over heels by a 2000 N push came round upright in the air and
# stepped with a foot 0.9 m up until the simulation blew up
_STEP_TILT_COS = float(np.cos(np.radians(35.0)))
# ``step_hold``: how far (m) the capture point may lie outside the feet before a body nearly at
# rest steps again (``end_state``'s settled margin)
_HOLD_MARGIN = 0.05
# a fall nearer a diagonal than the heading (22.5 deg) steps with the foot on its side: a
# front-right push stepped the left foot 0.43 m ahead and pitched over the right toes
_SIDE_STEP_TAN = float(np.tan(np.radians(22.5)))
# the shortest balance step's time as a fraction of ``step_time`` (``step_short``)
_SHORT_STEP_MIN = 0.4
# seconds between updates of the ground path, the balance shift and the step decision
_SLOW_PERIOD = 0.008
# a heading error's dead band is the position dead band over this lever (m)
_DEADBAND_ARM = 0.5
# a pushed walk's clip plays at most this much faster, and follows the body's speed with
# this time constant (s): within a step the centre of mass's speed swings by ~20%
_WARP_MAX = 1.8
_WARP_TAU = 0.1
# a pushed walk's clip clock catches a body ahead of it (``warp_phase``) with this time
# constant (s), at most this many times faster than real time
_PHASE_TAU = 0.3
_PHASE_MAX = 3.0
# a pushed walk's placed foot lands at most this far (m) outside its stance foot, only while
# the clip's centre of mass runs more than this fast (m/s) away from the fall's side, and only
# for a capture-point error this many times more sideways than along the walk: wider steps,
# and placements where the clip's own sway or the walk's speed carried the error, lost more
# pushes than they caught (``docs/tracking.md``)
_PLACE_WIDTH = 0.6
_PLACE_AGAINST = 0.3
_PLACE_SIDEWAYS = 3.0
# and only this long (s) after the push starts: a later swing is the clip's own step, which
# already lands out (placing it too lost a walk's pushes toward the side its clip walks from)
_PLACE_WINDOW = 0.5
# ``anchor_lag``: the ground path lags the feet only this long (s) after a walk's push starts
# (held longer, the path ahead drove bodies back up to speed past their feet: they fell
# forward), only while the centre of mass moves more than this far (cos 45 deg) off the
# clip's walk (a body slowed straight back is ``kp_root_against``'s), and by all of
# ``anchor_lag`` only at this fraction of the clip's speed or less, by none at its speed
_LAG_FOR = 0.7
_LAG_COS = float(np.cos(np.radians(45.0)))
_LAG_SLOW = 0.5
# ``anchor_lag_heading``: a body's heading counts only above this speed (m/s): a body the push
# has nearly stopped moves every way
_LAG_MOVING = 0.2
# ``step_ahead_horizon``: the capture point's velocity is smoothed with this time constant
# (s): a landing's impact moves it by metres per second for a tick (0.03 s lost 2 walking
# pushes of 42 that 0.1 s keeps)
_AHEAD_RATE_TAU = 0.1
# ``step_ahead_swing``: a swing foot's landing brought forward takes at least this long (s)
_SWING_AHEAD_MIN = 0.1


def _left_of(heading: float) -> F64:
    """The unit vector (2,) to the left of ``heading`` (rad) in the floor plane."""
    return np.array([-np.sin(heading), np.cos(heading)])


def rot2(yaw: float) -> F64:
    """The ``(2, 2)`` rotation of the floor plane by ``yaw`` (rad): the mocap's re-anchoring."""
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s], [s, c]])


class AnchoredReference:
    """The reference ``path`` of one ``character`` of ``world`` from clip time ``start``, as
    the whole-body tracker follows it; ``dt_tick`` its control period (s). The options are
    :class:`~reactmocap.sim.controllers.wholebody.WholeBodyTracker`'s (see there)."""

    def __init__(
        self,
        world: World,
        character: int,
        path: ReferencePath,
        start: float,
        *,
        dt_tick: float,
        roll_band: float,
        anchor_tau: float,
        anchor_touch: float,
        anchor_return: float,
        anchor_deadband: float,
        balance_margin: float,
        balance_tau: float,
        stepping: bool,
        step_margin: float,
        step_time: float,
        step_height: float,
        place_gain: float,
        place_deadband: float,
        place_height: float,
        warp_gain: float = 0.0,
        warp_lead: float = 0.0,
        warp_phase: float = 0.0,
        step_leg: float = 0.0,
        step_alternate: bool = False,
        step_short: float = 0.0,
        place_pushed: float = 0.0,
        step_ease: float = 0.0,
        step_ease_in: float = 0.0,
        step_hold: float = 0.0,
        step_hold_for: float = 0.0,
        warp_for: float = 0.0,
        anchor_lag: float = 0.0,
        anchor_lag_heading: float = 0.0,
        anchor_lag_speed: float = 0.0,
        step_ahead: float = 0.0,
        step_ahead_horizon: float = 0.0,
        step_ahead_swing: float = 0.0,
        step_ahead_phase: float = 0.0,
        centre_speed_lock: float = 0.0,
        anchor_turn_rate: float = 0.0,
        centre_speed_lock_walking: float = 0.0,
    ) -> None:
        m = world.model
        wc = world.characters[character]
        self.world = world
        self.character = character
        #: the clip as this tracker follows it
        self.path = path
        self.clock = path.clock(start)
        self._clock0 = self.clock
        self.feet, self.sole, self._corners = foot_soles(world, character, "WholeBodyTracker")
        self.floor_z = float(world.data.geom_xpos[m.geom("floor").id, 2])
        self.patch = wc.patch_ids
        self.patch_half = m.geom_size[self.patch, 2].copy()
        self.patch_arm = m.geom_friction[self.patch, 2].copy()
        dt_slow = np.ceil(_SLOW_PERIOD / dt_tick - 1e-9) * dt_tick  # see update_ground()
        self._anchor_rate = min(1.0, dt_slow / anchor_tau) if anchor_tau > 0 else 0.0
        self.anchor_touch = float(anchor_touch)
        self.anchor_deadband = float(anchor_deadband)
        self._return_rate = min(1.0, dt_slow / anchor_return) if anchor_return > 0 else 0.0
        self.roll_band = float(roll_band) if roll_band > 0 else np.inf
        self._sole_half = m.geom_size[self.sole, 2][:, None].copy()
        assert self.path.com is not None and self.path.sole is not None
        assert self.path.sole_yaw is not None
        self._com: F64 = self.path.com
        dt_f = 1.0 / self.path.fps
        n = self.path.num_frames
        self._com_v = np.gradient(self._com, dt_f, axis=0) if n > 1 else 0 * self._com
        self._com_a = np.gradient(self._com_v, dt_f, axis=0) if n > 2 else 0 * self._com
        self._sole_v = np.gradient(self.path.sole, dt_f, axis=0) if n > 1 else 0 * self.path.sole
        # the stance the foot lock reads (contact rows, anchoring, pivot patch):
        # ``centre_speed_lock`` drops a foot rolling over its slow lowest corner mid-swing; the
        # balance shift, the balance steps and ``step_ahead`` keep the path's flags
        self._lock_planted, self._lock_pivoting = self.path.planted, self.path.pivoting
        # ``centre_speed_lock_walking``: on a walking clip only (its centre of mass's median
        # horizontal speed at least that): at 0.7 m/s the lock lost two fighting clips
        speed = np.hypot(self._com_v[:, 0], self._com_v[:, 1])
        if centre_speed_lock and float(np.median(speed)) >= centre_speed_lock_walking:
            slow = sole_speed(self.path.sole, self.path.fps) < centre_speed_lock
            self._lock_planted = self.path.planted & slow
            self._lock_pivoting = self.path.pivoting & slow
        # ``anchor_turn_rate``: the anchoring's largest yaw step per slow tick over the clip's
        # own soles' yaw step there (rad; inf: off)
        self._turn_step = anchor_turn_rate * dt_slow if anchor_turn_rate else np.inf
        self._sole_turn = (
            np.abs(np.gradient(self.path.sole_yaw, dt_f, axis=0)) * dt_slow
            if anchor_turn_rate and n > 1
            else np.zeros((n, 2))
        )
        self.balance_margin = float(balance_margin)
        self._balance_rate = min(1.0, dt_slow / balance_tau) if balance_tau > 0 else 0.0
        #: horizontal shift of the pelvis and centre-of-mass targets (m) keeping the mocap's
        #: capture point inside the feet (see :meth:`rebalance`)
        self.balance_shift = np.zeros(2)
        self.stepping = bool(stepping)
        self.step_margin = float(step_margin)
        self.step_time = float(step_time)
        self.step_height = float(step_height)
        self.step_leg = float(step_leg)
        self.step_alternate = bool(step_alternate)
        self.step_short = float(step_short)
        self.step_ease = float(step_ease)
        # how far (m) the pelvis target is down for a balance step (``step_ease``) and the
        # rollout time it was last moved
        self._drop, self._drop_t = 0.0, 0.0
        self.step_ease_in = float(step_ease_in)
        # the start time of the last balance step seen and whether its drop eases in
        # (``step_ease_in``: it began while the target was still coming back up)
        self._drop_step: tuple[float, bool] = (-np.inf, False)
        self._landed = (-1, -np.inf)  # the last balance step's foot and landing time
        self._gone_down = False  # the pelvis has tilted past the balance steps' limit
        self.step_hold = float(step_hold)
        self.step_hold_for = float(step_hold_for)
        self.place_gain = float(place_gain)
        self.place_deadband = float(place_deadband)
        self.place_height = float(place_height)
        #: horizontal shift of a mocap swing foot's landing (m): the capture point's error
        #: against the mocap's beyond ``place_deadband``
        self.place_shift = np.zeros(2)
        self.place_pushed = float(place_pushed)
        #: set once a walk is pushed: ``place_pushed`` then moves its swing feet's landings
        #: until ``_place_until`` (rollout time, s)
        self.placing = False
        self._place_until = -np.inf
        # per foot: a pushed walk's landing move (m), and whether it was moved and is still in
        # the air (kept on its moved landing while the mocap's stance flickers: its gliding
        # foot counts as planted)
        self._place_move = np.zeros((2, 2))
        self._place_land = np.zeros((2, 2))  # the moved landing (world, m)
        self._placed = np.zeros(2, dtype=bool)
        #: the balance step under way (None: none)
        self.step: Step | None = None
        #: rollout times of the balance steps taken
        self.steps_taken: list[float] = []
        self._step_ready = 0.0
        self._gravity = m.opt.gravity.copy()
        self._root = int(wc.body_ids[0])
        self._slow_next = 0.0
        self._z_adr = wc.qpos_slice.start + 2
        self._z0 = float(world.data.qpos[self._z_adr])
        # the pelvis's own axis that points up at the start (its rotation's last row): a real
        # skeleton's pelvis z axis lies along the floor, and reading it took a turn for a tilt
        self._root_up0 = world.data.xmat[self._root].reshape(3, 3)[2].copy()
        self._corners_at: tuple[float, bytes] = (float("nan"), b"")
        self._corners_now = np.zeros((2, 4, 3))
        #: the re-anchoring of the mocap's ground path: heading (rad) and horizontal shift (m),
        #: ``x -> Rz(yaw) x + shift``
        self.anchor_yaw = 0.0
        self.anchor_shift = np.zeros(2)
        self._turn = (0.0, rot2(0.0), quat_from_yaw(0.0))  # the anchor's yaw as matrix, quat
        self.warp_gain = float(warp_gain)
        self.warp_lead = float(warp_lead)
        self.warp_phase = float(warp_phase)
        self.warp_for = float(warp_for)
        #: rollout time after which a pushed walk's clip plays back at rate 1 (``warp_for``)
        self.warp_until = np.inf
        self.anchor_lag = float(anchor_lag)
        #: rollout time until which a pushed walk's ground path lags its feet along the walk
        #: (``anchor_lag``; -inf: not pushed)
        self.lag_until = -np.inf
        self.anchor_lag_heading = float(anchor_lag_heading)
        self._lag_end_cos = float(np.cos(np.radians(self.anchor_lag_heading)))
        self._lag_acted = False  # the path has lagged the feet since the push
        # ``anchor_lag_speed``: the lag acts only below this fraction of the clip's speed
        self._lag_speed = float(anchor_lag_speed) if anchor_lag_speed else np.inf
        self._catching = False  # the clip's clock catching a body ahead (``warp_phase``)
        # ``step_ahead``: the capture point's largest lead past the front foot in the clip's
        # own double supports (m), and whether a walk's push has armed the step
        self.step_ahead = float(step_ahead)
        self._ahead_margin = self._clip_ahead_margin() if self.step_ahead else np.inf
        self._ahead_armed = False
        # ``step_ahead_horizon``: the lead predicted this far ahead (s) by the capture point's
        # smoothed velocity (2,), from its last slow tick's time and position
        self.step_ahead_horizon = float(step_ahead_horizon)
        # against the clip's own lead grown the same way: a walk's capture point runs ahead
        # at its speed in every double support
        self._grown_margin = (
            self._clip_ahead_margin(self.step_ahead_horizon) if self.step_ahead_horizon else np.inf
        )
        self._xi_rate = np.zeros(2)
        self._xi_last: tuple[float, F64] = (-np.inf, np.zeros(2))
        # ``step_ahead_swing``: the clip's swing foot's landing brought forward in its single
        # supports, the swing taking this fraction of the clip's time left to its landing;
        # the clip's stance without its one-frame double supports (a swing foot touching
        # between two frames of swing)
        self.step_ahead_swing = float(step_ahead_swing)
        self._firm = self.path.planted.copy()
        if self.step_ahead_swing:
            pl = self.path.planted
            self._firm[1:-1] &= pl[:-2] | pl[2:]
        # per frame and foot, the first frame from it on where the foot is planted (len: never)
        n = len(self._firm)
        idx = np.where(self._firm, np.arange(n)[:, None], n)
        self._next_planted = np.minimum.accumulate(idx[::-1], axis=0)[::-1]
        # ``step_ahead_swing``'s limit per frame: ``step_ahead`` times the clip's own largest
        # lead predicted past its landings (0.49-0.57 m on the walks, set where the stance
        # flags a foot still swinging as landed: docs/tracking.md, ``step_ahead_phase``), or
        # with ``step_ahead_phase`` the clip's own lead at that frame plus that margin (m;
        # frames without a lead keep the largest)
        self._swing_limit = np.full(n, np.inf)
        if self.step_ahead_swing:
            leads = self._clip_swing_leads()
            largest = float(max(0.0, leads.max()))
            if step_ahead_phase:
                self._swing_limit = np.where(np.isfinite(leads), leads, largest) + float(
                    step_ahead_phase
                )
            else:
                self._swing_limit[:] = largest * self.step_ahead
        self._dt_slow = float(dt_slow)
        #: set once a walk is pushed: the clip's rate then follows the body's speed
        self.warping = False
        #: set after a sideways walk's push: the rate then also follows the capture point's
        #: lead along the walk (``warp_lead``)
        self.leading = False
        #: the clip's playing rate (1: as captured)
        self.rate = 1.0

    def reference(self, t: float) -> tuple[F64, F64, F64, NDArray[np.bool_]]:
        """The mocap at rollout time ``t``: ``qpos`` (67,), ``qvel`` (51,), ``qacc`` (51,) and
        the planted feet (2,) as the foot lock reads them (:meth:`planted_now`)."""
        q, v, a, _ = self.path.sample(self.clock.frame(t), self.clock.coast(t))
        planted = self.planted_now(t, lock=True)
        if self.anchor_yaw or self.anchor_shift.any():
            if self._turn[0] != self.anchor_yaw:  # it moves every few ticks only
                self._turn = (
                    self.anchor_yaw,
                    rot2(self.anchor_yaw),
                    quat_from_yaw(self.anchor_yaw),
                )
            _, rot, turn = self._turn
            q[:2] = rot @ q[:2] + self.anchor_shift
            mujoco.mju_mulQuat(q[3:7], turn, q[3:7].copy())
            v[:2] = rot @ v[:2]  # free-joint angular velocity is local: unchanged
            a[:2] = rot @ a[:2]
        q[:2] += self.balance_shift
        drop = self._eased_drop(t, q[2]) if self.step_ease and self.step_leg else 0.0
        if self.step_ease and self.step_leg and (self.step is not None or drop):
            q[2] -= drop
        elif self.step is not None and self.step_leg:
            q[2] = min(q[2], self._step_pelvis_z(self.step.target[:2]))
        elif self.step_leg and self._place_move.any():
            # a pushed walk's foot placed further out reaches the floor the same way
            f = int(np.argmax(np.abs(self._place_move).sum(axis=1)))
            q[2] = min(q[2], self._step_pelvis_z(self._place_land[f]))
        if self.rate != 1.0:  # the clip played faster (see :meth:`_warp`)
            v *= self.rate
            a *= self.rate * self.rate
        return q, v, a, planted

    def _step_pelvis_z(self, target: F64) -> float:
        """The pelvis height from which a leg ``step_leg`` times the pelvis's starting height
        reaches a step's ``target`` (2,) from where the pelvis is (at most 0.4 of that height
        lower): at the standing height a long step's foot hovered short of the floor."""
        leg = self.step_leg * (self._z0 - self.floor_z)
        gap = target - self.world.data.qpos[self._z_adr - 2 : self._z_adr]
        reach = float(np.sqrt(max(leg * leg - float(gap @ gap), 0.0)))
        return self.floor_z + max(reach, 0.6 * (self._z0 - self.floor_z))

    def _eased_drop(self, t: float, z: float) -> float:
        """How far (m) the pelvis target is below the mocap's height ``z`` at ``t`` for
        balance steps: :meth:`_step_pelvis_z`'s drop while a step is under way, and after it
        lands back up to 0 with time constant ``step_ease`` s. Jumping back up as the step
        landed, the plan asked the ground for 11 kN for a tick, the foot that had just caught
        the fall rolled onto an edge and the next step, starting 0.05 s later, dropped the
        target 0.2 m again in one tick (no ground force asked while it lifted off)."""
        want = 0.0
        if self.step is not None:
            want = max(0.0, z - self._step_pelvis_z(self.step.target[:2]))
            if self.step_ease_in and self.step.t0 != self._drop_step[0]:
                self._drop_step = (self.step.t0, self._drop > 1e-3)
        easing_in = self.step is not None and self._drop_step[1]
        if t > self._drop_t:
            down = easing_in and want > self._drop
            tau = self.step_ease_in if down else self.step_ease
            rate = min(1.0, (t - self._drop_t) / tau)
            self._drop += rate * (want - self._drop)
            self._drop_t = t
        if not easing_in:
            self._drop = max(self._drop, want)  # down at once: the step must reach the floor
        return self._drop

    def sole_corners(self) -> F64:
        """``(2, 4, 3)`` the sole corners now (computed once per simulation time)."""
        d = self.world.data
        key = (float(d.time), d.geom_xpos[self.sole].tobytes())
        if self._corners_at != key:
            self._corners_now = sole_corners_world(d, self.sole, self._corners)
            self._corners_at = key
        return self._corners_now

    def planted_now(self, t: float, lock: bool = False) -> NDArray[np.bool_]:
        """``(2,)`` the feet the tracker stands on at ``t``: those planted in the mocap (as the
        foot lock reads them with ``lock``, ``centre_speed_lock``), but for the foot of a
        balance step under way."""
        flags = self._lock_planted if lock else self.path.planted
        planted = flags[self.clock.nearest(t)].copy()
        if self.step is not None:
            planted[self.step.foot] = False
        return planted

    def com_reference(self, t: float) -> tuple[F64, F64, F64]:
        """The mocap's centre of mass at ``t``: position, velocity, acceleration (world, as
        re-anchored)."""
        x = self.clock.frame(t)
        i0 = int(x)
        i1 = min(i0 + 1, self.path.num_frames - 1)
        w = x - i0
        c = (1 - w) * self._com[i0] + w * self._com[i1]
        v = (1 - w) * self._com_v[i0] + w * self._com_v[i1]
        a = (1 - w) * self._com_a[i0] + w * self._com_a[i1]
        coast = self.clock.coast(t)
        if coast > 0:
            c = c + coast * v
            a = np.zeros(3)
        rot = rot2(self.anchor_yaw)
        c[:2] = rot @ c[:2] + self.anchor_shift + self.balance_shift
        v[:2] = rot @ v[:2]
        a[:2] = rot @ a[:2]
        if self.rate != 1.0:  # the clip played faster (see :meth:`_warp`)
            v *= self.rate
            a *= self.rate * self.rate
        return c, v, a

    def _footprint(self, t: float) -> list[F64]:
        """Per foot planted in the mocap, the ground points ``(k, 2)`` it can push through now:
        its sole corners within ``anchor_touch`` of the floor, or its ball patch's
        centre-of-pressure range; empty for a foot in the air."""
        d = self.world.data
        planted = self.planted_now(t)
        corners = self.sole_corners()
        patch_on = self.world.foot_patch_on(self.character)
        out: list[F64] = []
        for f in range(2):  # two feet
            if not planted[f]:
                out.append(np.zeros((0, 2)))
            elif patch_on[f]:
                rot = d.geom_xmat[self.patch[f]].reshape(3, 3)
                p = d.geom_xpos[self.patch[f]] - rot[:, 2] * self.patch_half[f]
                if p[2] - self.floor_z >= self.anchor_touch:
                    out.append(np.zeros((0, 2)))
                    continue
                axes = rot[:2, :2].T * self.patch_arm[f]
                out.append(p[:2] + np.array([axes[0], -axes[0], axes[1], -axes[1]]))
            else:
                down = corners[f, :, 2] - self.floor_z < self.anchor_touch
                out.append(corners[f, down, :2])
        return out

    def capture_point(self) -> tuple[F64, float]:
        """The simulated body's capture point ``c + v / omega`` (2,) and ``omega`` (1/s), the
        natural frequency of its centre of mass as an inverted pendulum."""
        d = self.world.data
        mujoco.mj_subtreeVel(self.world.model, d)
        c = d.subtree_com[self._root]
        omega = float(np.sqrt(-self._gravity[2] / max(c[2] - self.floor_z, 0.3)))
        return c[:2] + d.subtree_linvel[self._root][:2] / omega, omega

    def _swing_targets(self, t: float) -> dict[int, tuple[F64, F64, F64, F64 | None]]:
        """Per foot stepping for balance: its sole centre's target position, velocity and
        acceleration, and its sole's target normal (``None``: free; a placement moves only
        the foot's horizontal position): a balance step's path, or a mocap swing foot whose
        landing the capture point's error moves (see :attr:`place_shift`)."""
        out: dict[int, tuple[F64, F64, F64, F64 | None]] = {}
        if self.step is not None:
            p, v, a = self.step.at(t)
            out[self.step.foot] = (p, v, a, np.array([0.0, 0.0, 1.0]))
        if not (self.place_shift.any() or self._place_move.any()):
            return out
        for f in range(2):  # two feet
            if f in out or not (self.place_shift.any() or self._place_move[f].any()):
                continue
            sole = self._mocap_swing(t, f)
            if sole is None:
                continue
            p, v = sole
            p[:2] += self.place_shift + self._place_move[f]
            # a pushed walk's foot also comes down level where it lands (lateral rows alone
            # left it hanging 0.2-0.4 m up, short of the landing)
            out[f] = (p, v, np.zeros(3), np.array([0.0, 0.0, 1.0]) if self.placing else None)
        return out

    def _mocap_swing(self, t: float, f: int) -> tuple[F64, F64] | None:
        """The mocap's sole centre of foot ``f`` at ``t`` (position, velocity; world, as
        re-anchored) while it swings (a pushed walk's placed foot: until it lands), else
        ``None``."""
        assert self.path.sole is not None
        x = self.clock.frame(t)
        i0 = int(x)
        i1 = min(i0 + 1, self.path.num_frames - 1)
        w = x - i0
        if self.path.planted[self.clock.nearest(t), f] and not self._placed[f]:
            return None
        p = (1 - w) * self.path.sole[i0, f] + w * self.path.sole[i1, f]
        if p[2] - self.floor_z < self.place_height and not self._placed[f]:
            return None
        v = (1 - w) * self._sole_v[i0, f] + w * self._sole_v[i1, f]
        rot = rot2(self.anchor_yaw)
        p[:2] = rot @ p[:2] + self.anchor_shift
        v[:2] = rot @ v[:2]
        return p, v

    def sole_heading(self) -> float:
        """The simulated soles' mean yaw (rad)."""
        rot = self.world.data.geom_xmat[self.sole].reshape(2, 3, 3)
        return float(np.arctan2(rot[:, 1, 0].sum(), rot[:, 0, 0].sum()))

    def _start_placing(self, placing: bool, t: float) -> None:
        """A walk pushed at ``t``: ``place_pushed`` moves its swing feet's landings (when
        ``placing``) for ``_PLACE_WINDOW`` s."""
        self.placing = placing
        self._place_until = t + _PLACE_WINDOW
        if self.anchor_lag:
            # ``anchor_lag_heading``: until the body is back on its way, however long that takes
            self.lag_until = np.inf if self.anchor_lag_heading else t + _LAG_FOR
            self._lag_acted = False

    def _place_walk(self, t: float) -> None:
        """After a sideways walk's push (``place_pushed``): a swinging foot lands where the
        simulated capture point will be when the mocap's foot comes down (pivoting over the
        other foot, a linear inverted pendulum), when that is further out than the mocap's
        landing: ``place_pushed`` times the sideways gap out (at most ``_PLACE_WIDTH`` outside
        the stance foot), kept until the foot is down. Only sideways (the clip played faster,
        ``warp_gain``, takes the speed along the walk), only outward and only with the capture
        point past the stance foot (no crossing step), only while the clip walks away from
        the fall's side, and only for ``_PLACE_WINDOW`` s after the push starts
        (``docs/tracking.md``)."""
        low = self.sole_corners()[:, :, 2].min(axis=1) - self.floor_z
        self._placed &= low >= self.anchor_touch  # landed
        self._place_move[:] = 0.0
        if t > self._place_until:
            return
        assert self.path.sole is not None
        xi, omega = self.capture_point()
        c_ref, v_ref, _ = self.com_reference(t)
        # the push's part only: a walk's own capture point runs ahead of its stance foot
        miss = xi - c_ref[:2] - v_ref[:2] / omega
        left = _left_of(self.sole_heading())
        i = self.clock.nearest(t)
        ahead = self.path.sole[i : i + round(0.5 * self.path.fps), :, 2] - self.floor_z
        centre = self._sole_centres()
        for f in range(2):  # two feet
            if low[f] < self.anchor_touch or self._mocap_swing(t, f) is None:
                continue
            k = int(np.argmax(ahead[:, f] < self.place_height))  # the mocap's landing
            land = rot2(self.anchor_yaw) @ self.path.sole[i + k, f, :2] + self.anchor_shift
            out = left if f == 0 else -left
            side = float(miss @ out)
            along = abs(float(miss @ np.array([left[1], -left[0]])))
            gap = side * np.exp(omega * k / (self.path.fps * self.rate))
            # the clip walks away from the fall's side, and the capture point is past the
            # stance foot on this foot's side (no crossing step)
            against = float(v_ref[:2] @ out) < -_PLACE_AGAINST
            past = float((xi - centre[1 - f, :2]) @ out) > 0
            if against and past and side > _PLACE_SIDEWAYS * along and gap > self.place_deadband:
                width = _PLACE_WIDTH - float((land - centre[1 - f, :2]) @ out)
                self._place_move[f] = max(0.0, min(self.place_pushed * gap, width)) * out
                self._place_land[f] = land + self._place_move[f]
                self._placed[f] = True

    def _update_step(self, t: float) -> None:
        """End a balance step that has landed; start one when the capture point has left both
        feet's support by ``step_margin`` while the mocap keeps both feet planted; update
        nothing else."""
        d = self.world.data
        self.place_shift = np.zeros(2)
        if self.placing:
            self._place_walk(t)
        if self.place_gain and not self.path.planted[self.clock.nearest(t)].all():
            xi, omega = self.capture_point()
            c_ref, cv_ref, _ = self.com_reference(t)
            miss = xi - c_ref[:2] - cv_ref[:2] / omega
            n = float(np.linalg.norm(miss))
            if n > self.place_deadband:
                # beyond the dead band a walk's own capture-point error never reaches
                self.place_shift = self.place_gain * miss * min(1.0, 0.4 / n)
        if self.step is not None:
            s = self.step
            corners = self.sole_corners()
            down = corners[s.foot, :, 2].min() - self.floor_z < self.anchor_touch
            if (s.phase(t) >= 0.6 and down) or t > s.t0 + 1.5 * s.duration:
                self.step = None
                self._step_ready = t + 0.05
                self._landed = (s.foot, t)
        if self._ahead_armed and self.step_ahead_horizon:
            self._track_capture_rate(t)
        if self._ahead_armed and self.step is None and t >= self._step_ready:
            self._step_ahead(t)
        if self.step is not None or not self.stepping or t < self._step_ready:
            return
        i = self.clock.nearest(t)
        if self._going_down():
            return  # a step would only flail
        ahead = self.path.planted[i : i + max(1, round(self.step_time * self.path.fps))]
        feet = self._footprint(t)
        down = [len(f) > 0 for f in feet]
        if not (ahead.all() and (all(down) or (self.step_alternate and any(down)))):
            return
        xi, omega = self.capture_point()
        support = np.concatenate(feet)
        margin = self.step_margin
        if self.step_hold and self._landed[0] >= 0:
            speed = float(np.linalg.norm(d.subtree_linvel[self._root][:2]))
            # ``step_hold_for``: a body left at the edge longer after a landing drifts out and
            # the later, longer step started a new chain
            soon = not self.step_hold_for or t - self._landed[1] <= self.step_hold_for
            if speed < self.step_hold and soon:
                # a body nearly at rest after a step: a capture point at the edge is the
                # ankles' and hips' to bring back; a further step lifted a foot and
                # relaunched it
                margin = max(margin, _HOLD_MARGIN)
        if outside_distance(xi, support) <= margin:
            return
        centre = self._sole_centres()
        left = _left_of(self.sole_heading())
        fall = xi - convex_hull(support).mean(axis=0)
        side = float(fall @ left)
        if abs(side) > _SIDE_STEP_TAN * abs(float(fall @ np.array([left[1], -left[0]]))):
            foot = 0 if side > 0 else 1  # a side or diagonal step with the foot on that side
        else:  # the trailing foot
            foot = int(np.argmax(np.linalg.norm(centre[:, :2] - xi, axis=1)))
        if not all(down):
            # a foot the body has lifted off the floor (after a step, the mocap's leg pose
            # lifts the foot left behind) is the one free to catch it
            foot = down.index(False)
        elif self.step_alternate and t - self._landed[1] < 0.5:
            # the foot that just landed carries the body: stepping it again pivoted the body
            # over the foot left behind
            foot = 1 - self._landed[0]
        self._start_step(t, foot, centre, xi, omega, left, shorten=True)

    def _start_step(
        self, t: float, foot: int, centre: F64, xi: F64, omega: float, left: F64,
        shorten: bool, duration: float = 0.0,
    ) -> None:  # fmt: skip
        """Start a balance step of ``foot`` (sole centres ``centre``, ``(2, 3)``) to
        :func:`step_target` for capture point ``xi``; ``left`` is the soles' unit left
        vector. ``shorten``: after a landed step, a short step (``step_short``) takes less
        than the whole step time; ``duration`` (s, 0: ``step_time``) a swing foot's shortened
        swing (``step_ahead_swing``). The one step start of the step triggers."""
        duration = duration or self.step_time
        target = step_target(
            xi, centre[1 - foot, :2], centre[foot, :2], omega, duration, beyond=0.05,
            max_length=0.6, min_width=0.12, lateral=left if foot == 0 else -left,
        )  # fmt: skip
        if shorten and self.step_short and self._landed[0] >= 0:
            # after a step has landed, a short one (a foot put back down) need not take the
            # whole step time
            short = float(np.linalg.norm(target - centre[foot, :2])) / self.step_short
            duration *= min(1.0, max(_SHORT_STEP_MIN, short))
        self.step = Step(foot, t, duration, centre[foot].copy(),
                         np.r_[target, self.floor_z], self.step_height)  # fmt: skip
        self.steps_taken.append(t)

    def _sole_centres(self) -> F64:
        """The simulated soles' centres, ``(2, 3)`` (m)."""
        d = self.world.data
        rot = d.geom_xmat[self.sole].reshape(2, 3, 3)
        return d.geom_xpos[self.sole] - rot[:, :, 2] * self._sole_half

    def _going_down(self) -> bool:
        """The pelvis has tilted past the balance steps' limit (now or before) or sunk below
        0.75 of its starting height: the body is already going down."""
        d = self.world.data
        up_z = d.xmat[self._root].reshape(3, 3)[2] @ self._root_up0  # that axis's height
        self._gone_down |= bool(up_z < _STEP_TILT_COS)
        return self._gone_down or bool(d.qpos[self._z_adr] < 0.75 * self._z0)

    def _clip_ahead_margin(self, horizon: float = 0.0) -> float:
        """``step_ahead``'s base: the clip's own capture point's largest lead (m) past its
        front foot along its walk over the frames where both feet are planted and it walks
        (0.2 m/s or faster), grown by its velocity over ``horizon`` s (``step_ahead_horizon``);
        0 for a clip that never does."""
        assert self.path.sole is not None
        c, v, a = self._com, self._com_v, self._com_a
        speed = np.hypot(v[:, 0], v[:, 1])
        both = self.path.planted.all(axis=1) & (speed > 0.2)
        if not both.any():
            return 0.0
        u = v[both, :2] / speed[both, None]
        omega = np.sqrt(-self._gravity[2] / np.maximum(c[both, 2] - self.floor_z, 0.3))
        xi = c[both, :2] + v[both, :2] / omega[:, None]
        if horizon:  # and its velocity, v + a / omega, over the horizon
            xi += horizon * (v[both, :2] + a[both, :2] / omega[:, None])
        sole = self.path.sole[both, :, :2]
        front = np.einsum("kfi,ki->kf", sole, u).max(axis=1)
        return float(max(0.0, (np.einsum("ki,ki->k", xi, u) - front).max()))

    def _clip_swing_leads(self) -> F64:
        """``step_ahead_swing``'s base, per frame ``(n,)``: in the clip's single supports
        where it walks (0.2 m/s or faster), its own capture point's lead (m) along its walk
        past its swing foot's landing, predicted to that landing pivoting over the stance
        foot (as :meth:`_swing_ahead` predicts the body's); -inf in the other frames."""
        assert self.path.sole is not None
        c, v = self._com, self._com_v
        speed = np.hypot(v[:, 0], v[:, 1])
        land = self._next_planted
        rows = np.arange(len(land))
        swing = np.argmin(self._firm, axis=1)
        k = land[rows, swing]
        one = (self._firm.sum(axis=1) == 1) & (speed > 0.2) & (k < len(land))
        out = np.full(len(land), -np.inf)
        if not one.any():
            return out
        i, f, k = rows[one], swing[one], k[one]
        u = v[i, :2] / speed[i, None]
        omega = np.sqrt(-self._gravity[2] / np.maximum(c[i, 2] - self.floor_z, 0.3))
        xi = c[i, :2] + v[i, :2] / omega[:, None]
        stance = self.path.sole[i, 1 - f, :2]
        pred = stance + (xi - stance) * np.exp(omega * (k - i) / self.path.fps)[:, None]
        out[one] = np.einsum("ki,ki->k", pred - self.path.sole[k, f, :2], u)
        return out

    def _walk_direction(self, t: float) -> F64 | None:
        """The clip's walking direction at ``t``, a unit vector ``(2,)`` on the floor, from
        its centre of mass's velocity; ``None`` where the clip is not walking (slower than
        0.2 m/s). The walk-only steps' one gate."""
        _, v, _ = self.com_reference(t)
        ref = float(np.hypot(v[0], v[1]))
        if ref < 0.2:  # not walking
            return None
        return v[:2] / ref

    def _step_ahead(self, t: float) -> None:
        """After a walk's push (``step_ahead``): while the clip holds both feet planted and
        both are on the floor, a capture point more than the clip's own largest lead
        (:meth:`_clip_ahead_margin`) times ``step_ahead`` past the front foot along the
        clip's walk starts a balance step of the rear foot (:func:`step_target`), and so
        does a lead grown over ``step_ahead_horizon`` s past the clip's own grown the same
        way; the clip plays on as it would (its clock moved on to that foot's own step lost
        more pushes).
        A body that ran past its feet in a double support of the clip's got its next step
        too late (``docs/tracking.md``)."""
        i = self.clock.nearest(t)
        if not self._firm[i].all():
            if self.step_ahead_swing and self._firm[i].any():
                self._swing_ahead(t, i)
            return
        feet = self._footprint(t)
        if not all(len(f) for f in feet):
            return
        if self._going_down():
            return
        u = self._walk_direction(t)
        if u is None:
            return
        xi, omega = self.capture_point()
        centre = self._sole_centres()
        front = int(np.argmax(centre[:, :2] @ u))
        lead = float((xi - centre[front, :2]) @ u)
        limit = self._ahead_margin * self.step_ahead
        # ``step_ahead_horizon``: the lead as its growth will have it a short time ahead
        grown = lead + self.step_ahead_horizon * float(self._xi_rate @ u)
        if lead <= limit and grown <= self._grown_margin * self.step_ahead:
            return
        self._start_step(t, 1 - front, centre, xi, omega, _left_of(self.sole_heading()),
                         shorten=False)  # fmt: skip

    def _swing_ahead(self, t: float, i: int) -> None:
        """``step_ahead_swing``: in the clip's single support at frame ``i`` (its one-frame
        double supports counted as swing), with the swing foot in the air and the stance
        foot on the floor, the capture point predicted (pivoting over the stance foot) to
        the clip's landing of the swing foot and past that landing along the clip's walk by
        more than the limit at that frame (``step_ahead`` times the clip's own largest such
        lead, :meth:`_clip_swing_leads`, or with ``step_ahead_phase`` its own lead there plus
        that margin) brings the landing forward: a balance step of the swing foot to
        :func:`step_target`, taking ``step_ahead_swing`` of the clip's time left to its
        landing. A step from double support only came after the body had run past its feet
        in the single support before it (``docs/tracking.md``)."""
        assert self.path.sole is not None
        f = int(np.argmin(self._firm[i]))  # the clip's swing foot
        low = self.sole_corners()[:, :, 2].min(axis=1) - self.floor_z
        if low[f] < self.anchor_touch or not len(self._footprint(t)[1 - f]):
            return
        if self._going_down():
            return
        k = int(self._next_planted[i, f])  # its landing
        if k >= len(self._next_planted):
            return  # the clip ends before the foot lands
        left_s = (k - self.clock.frame(t)) / (self.path.fps * self.rate)
        if left_s <= 0.0:
            return
        u = self._walk_direction(t)
        if u is None:
            return
        xi, omega = self.capture_point()
        centre = self._sole_centres()
        stance = centre[1 - f, :2]
        pred = stance + (xi - stance) * np.exp(omega * left_s)
        land = rot2(self.anchor_yaw) @ self.path.sole[k, f, :2] + self.anchor_shift
        if float((pred - land) @ u) <= self._swing_limit[i]:
            return
        duration = max(_SWING_AHEAD_MIN, self.step_ahead_swing * left_s)
        self._start_step(t, f, centre, xi, omega, _left_of(self.sole_heading()),
                         shorten=False, duration=min(duration, self.step_time))  # fmt: skip

    def _track_capture_rate(self, t: float) -> None:
        """``step_ahead_horizon``: the simulated capture point's velocity (2,), from its
        change since the last slow tick, smoothed (``_AHEAD_RATE_TAU``); restarted after a
        gap."""
        xi, _ = self.capture_point()
        t0, xi0 = self._xi_last
        dt = t - t0
        if 0 < dt <= 2.5 * self._dt_slow:
            k = min(1.0, dt / _AHEAD_RATE_TAU)
            self._xi_rate += k * ((xi - xi0) / dt - self._xi_rate)
        self._xi_last = (t, xi.copy())

    def rebalance(self, t: float) -> None:
        """Move :attr:`balance_shift` a step (``balance_tau``) toward what brings the mocap's
        capture point ``balance_margin`` inside both feet's soles on the floor (zero unless
        both feet support: a walk's capture point leaves the stance foot on purpose)."""
        if not self._balance_rate:
            return
        target = np.zeros(2)
        feet = self._footprint(t)
        if all(len(f) for f in feet):
            c, v, _ = self.com_reference(t)
            omega = np.sqrt(-self._gravity[2] / max(c[2] - self.floor_z, 0.3))
            xi = c[:2] - self.balance_shift + v[:2] / omega
            target = clamp_to_support(xi, np.concatenate(feet), self.balance_margin) - xi
        self.balance_shift += self._balance_rate * (target - self.balance_shift)

    def _held(self, t: float) -> NDArray[np.bool_]:
        """``(2, 4)`` the sole corners the mocap keeps on the ground at ``t`` (within
        ``roll_band`` of its foot's lowest corner)."""
        assert self.path.corners is not None
        z = self.path.corners[self.clock.nearest(t), :, :, 2]
        return z - z.min(axis=1, keepdims=True) < self.roll_band

    def reanchor(self, t: float) -> None:
        """Move the mocap's ground path a step (``anchor_tau``) toward the supporting feet:
        their mean heading error is turned about their centre and their mean position error
        shifted away. Without a foot both planted in the mocap and on the floor, no change."""
        if not self._anchor_rate:
            return
        d = self.world.data
        i = self.clock.nearest(t)
        corners = self.sole_corners()
        low = corners[:, :, 2].min(axis=1) - self.floor_z
        on = self.planted_now(t, lock=True) & (low < self.anchor_touch)
        if not on.any():
            return
        rot = d.geom_xmat[self.sole].reshape(2, 3, 3)
        sim = (d.geom_xpos[self.sole] - rot[:, :, 2] * self._sole_half)[on, :2]
        ref, ref_yaw = self.path.sole_at(self.clock.frame(t))
        ref = ref[on, :2] @ rot2(self.anchor_yaw).T + self.anchor_shift
        centre = sim.mean(axis=0)
        err = centre - ref.mean(axis=0)
        if t <= self.lag_until:
            err = self._lag(t, err)
        turn = on & ~self._lock_pivoting[i]  # a pivoting foot's heading is the clip's own turn
        dyaw = 0.0
        if turn.any():
            yaw = np.arctan2(rot[turn, 1, 0], rot[turn, 0, 0]) - ref_yaw[turn] - self.anchor_yaw
            dyaw = float(np.mean(wrap_angle(yaw)))
        # only what is beyond the dead band: a small offset is the tracking's own to correct
        db = self.anchor_deadband
        n = float(np.linalg.norm(err))
        err = err * max(0.0, 1.0 - db / n) if n > 0 else err
        dyaw = float(np.sign(dyaw) * max(0.0, abs(dyaw) - db / _DEADBAND_ARM))
        k = self._anchor_rate
        # a foot down early turns the path at most as its clip's soles turn, plus the bound
        dyaw = k * dyaw
        if self._turn_step < np.inf and turn.any():
            most = self._turn_step + float(self._sole_turn[i, turn].mean())
            dyaw = min(max(dyaw, -most), most)
        self.anchor_yaw += dyaw
        self.anchor_shift = rot2(dyaw) @ (self.anchor_shift + k * err - centre) + centre
        # and slowly back toward the captured path, which the gait then follows step by step
        self.anchor_yaw -= self._return_rate * self.anchor_yaw
        self.anchor_shift -= self._return_rate * self.anchor_shift

    def _lag(self, t: float, err: F64) -> F64:
        """After a walk's push (``anchor_lag``): the feet's position error ``err`` (2,) less
        up to ``anchor_lag`` m of their lag behind the path along the clip's walk. A body the
        push had slowed and turned off the walk dragged the path after its feet (1-3 m in 2 s),
        so the clip's pelvis never asked it back to the clip's speed and way; the path held
        ahead does (``docs/tracking.md``)."""
        _, v, _ = self.com_reference(t)
        ref = float(np.hypot(v[0], v[1]))
        if ref < 0.2:  # not walking
            return err
        u = v[:2] / ref
        along = float(err @ u)
        if not self.warping:
            mujoco.mj_subtreeVel(self.world.model, self.world.data)
        # else the velocity ``_warp`` computed at the last slow tick (8 ms old at most): enough
        # for a gate over 0.7 s, and the swept figures are with it
        body = self.world.data.subtree_linvel[self._root][:2]
        ahead = float(body @ u)
        speed = float(np.hypot(body[0], body[1]))
        if self.anchor_lag_heading and self._lag_acted and speed > _LAG_MOVING:
            if ahead >= self._lag_end_cos * speed:
                # back on its way: held further, the path ahead drove the body past its feet
                self.lag_until = t
                return err
        if along >= 0.0 or ahead > _LAG_COS * speed or speed > self._lag_speed * ref:
            return err
        self._lag_acted = True
        lag = self.anchor_lag * min(1.0, max(0.0, (1.0 - ahead / ref) / _LAG_SLOW))
        return err + (min(0.0, along + lag) - along) * u

    def update_ground(self, t: float) -> None:
        """The slow part of a control tick: the balance step decision, the ground path and
        the balance shift move slowly, so every ``_SLOW_PERIOD`` is enough (run every tick
        they cost ~35% of one)."""
        if t >= self._slow_next - 1e-9:
            self._slow_next = t + _SLOW_PERIOD
            self._update_step(t)
            self.reanchor(t)
            self.rebalance(t)
            if self.warping:
                self._warp(t)
                if self.warp_phase:
                    self._catch_phase(t)

    def _warp(self, t: float) -> None:
        """After a walk's push: the clip plays at a rate ``warp_gain`` of the way from 1 to
        the body's horizontal speed over the mocap's (centre of mass), so the steps come as
        fast as the pushed body needs them and the rate returns to 1 as the body slows to the
        reference (which is always a little slower); plus ``warp_lead`` per m the capture
        point runs ahead of the mocap's along the walk (a body drifting ahead of its steps)."""
        c, v, _ = self.com_reference(t)
        v_ref = v[:2] / self.rate
        n2 = float(v_ref @ v_ref)
        if n2 < 0.04:  # under 0.2 m/s: not walking
            return
        ref = float(np.sqrt(n2))
        mujoco.mj_subtreeVel(self.world.model, self.world.data)
        # the whole speed, not its part along the walk: a sideways push is caught sooner by
        # quicker steps too (the part along the walk drops then, and a clip slowed with it
        # lost the right pushes it survived: the rate never goes below 1)
        speed = float(np.linalg.norm(self.world.data.subtree_linvel[self._root][:2])) / ref
        target = 1.0 + self.warp_gain * (speed - 1.0)
        if self.leading:
            # the speed ratio forgets a position lead: after a caught sideways fall the body
            # ran 0.2-0.4 m ahead at the clip's speed, its steps short, and fell forward
            xi, omega = self.capture_point()
            lead = float((xi - c[:2] - v[:2] / omega) @ v_ref) / ref
            target += self.warp_lead * lead
        if t > self.warp_until:
            # a body the push slowed, speeding up again 1-2 s later, drove the rate up with
            # it, the faster clip drove the body faster, and it ran ahead of its feet and fell
            target = 1.0
        target = min(max(target, 1.0), _WARP_MAX)
        self.rate += min(1.0, self._dt_slow / _WARP_TAU) * (target - self.rate)
        self.clock = replace(self.clock, start=self.clock.start + (self.rate - 1.0) * self._dt_slow)

    def _catch_phase(self, t: float) -> None:
        """After a walk's push (``warp_phase``): once the body's centre of mass is
        ``warp_phase`` m ahead of the mocap's along the mocap's walk and until it no longer
        is, the clip's clock moves on by the clip time that closes the lead (time constant
        ``_PHASE_TAU``). After a foot landed behind the clip's landing, the balance shift and
        the re-anchoring toward it moved the clip's centre of mass back behind the body (0.49
        m in 0.13 s), and the next step then landed 0.7 m behind the capture point: the clip's
        phase is re-anchored to where the body is, its ground path still to the feet. Never
        back: a lagging body is the rate's (:meth:`_warp`)."""
        c, v, _ = self.com_reference(t)
        v_ref = v[:2] / self.rate
        ref = float(np.linalg.norm(v_ref))
        if ref < 0.2:  # not walking
            return
        lead = float((self.world.data.subtree_com[self._root][:2] - c[:2]) @ (v_ref / ref))
        if lead <= 0:
            self._catching = False
            return
        # only a large lead: catching every lead after a push lost pushes the clip's own
        # steps caught (``docs/tracking.md``)
        if not (self._catching or lead >= self.warp_phase):
            return
        self._catching = True
        k = min(1.0, self._dt_slow / _PHASE_TAU)
        ahead = min(k * lead / ref, _PHASE_MAX * self._dt_slow)
        self.clock = replace(self.clock, start=self.clock.start + ahead)

    def reset_ground(self, world: World) -> None:
        """Back to the captured path, no shift, no step (a rollout's start)."""
        self.anchor_yaw = 0.0
        self.anchor_shift = np.zeros(2)
        self.balance_shift = np.zeros(2)
        self.place_shift = np.zeros(2)
        self.placing, self._place_until = False, -np.inf
        self._place_move[:] = 0.0
        self._placed[:] = False
        self.step = None
        self.steps_taken = []
        self._step_ready = 0.0
        self._landed = (-1, -np.inf)
        self._gone_down = False
        self._drop, self._drop_t = 0.0, 0.0
        self._drop_step = (-np.inf, False)
        self._slow_next = 0.0
        self.clock = replace(self._clock0, until=self.clock.until)
        self.rate, self.warping, self.leading = 1.0, False, False
        self.warp_until = np.inf
        self.lag_until = -np.inf
        self._lag_acted = False
        self._catching = False
        self._ahead_armed = False
        self._xi_rate = np.zeros(2)
        self._xi_last = (-np.inf, np.zeros(2))
        self._z0 = float(world.data.qpos[self._z_adr])
        self._root_up0 = world.data.xmat[self._root].reshape(3, 3)[2].copy()

    def hold(self, t: float) -> None:
        """From rollout time ``t`` on, follow the reference's pose at ``t``."""
        self.clock = self.clock.held_from(t)

    def memory(self) -> tuple[object, ...]:
        """What the tracker carries from tick to tick (the ground path's anchoring, the
        balance shift, a step under way), for :meth:`restore` after a look ahead."""
        return (self.anchor_yaw, self.anchor_shift.copy(), self.balance_shift.copy(),
                self.place_shift.copy(), self.step, len(self.steps_taken), self._step_ready,
                self._slow_next, self.clock, self.rate, self.warping, self._landed,
                self.placing, self._place_until, self._place_move.copy(),
                self._placed.copy(), self._gone_down, self.leading, self._drop,
                self._drop_t, self._catching, self._drop_step, self.warp_until,
                self.lag_until, self._lag_acted, self._ahead_armed, self._xi_rate.copy(),
                self._xi_last)  # fmt: skip

    def restore(self, memory: tuple[object, ...]) -> None:
        """Back to a :meth:`memory`."""
        (yaw, shift, bal, place, step, taken, ready, slow, clock, rate, warping, landed, placing,
         until, place_move, placed, gone_down, leading, drop, drop_t,
         catching, drop_step, warp_until, lag_until, lag_acted, ahead_armed, xi_rate,
         xi_last) = memory  # fmt: skip
        self.anchor_yaw = float(yaw)  # type: ignore[arg-type]
        self.anchor_shift = np.array(shift)
        self.balance_shift = np.array(bal)
        self.place_shift = np.array(place)
        self.step = step  # type: ignore[assignment]
        del self.steps_taken[int(taken) :]  # type: ignore[call-overload]
        self._step_ready = float(ready)  # type: ignore[arg-type]
        self._slow_next = float(slow)  # type: ignore[arg-type]
        self.clock = clock  # type: ignore[assignment]
        self.rate, self.warping = float(rate), bool(warping)  # type: ignore[arg-type]
        self._landed = landed  # type: ignore[assignment]
        self.placing = bool(placing)
        self._place_until = float(until)  # type: ignore[arg-type]
        self._place_move[:] = place_move  # type: ignore[call-overload]
        self._placed[:] = placed  # type: ignore[call-overload]
        self._gone_down = bool(gone_down)
        self.leading = bool(leading)
        self._drop, self._drop_t = float(drop), float(drop_t)  # type: ignore[arg-type]
        self._catching = bool(catching)
        self._drop_step = drop_step  # type: ignore[assignment]
        self.warp_until = float(warp_until)  # type: ignore[arg-type]
        self.lag_until = float(lag_until)  # type: ignore[arg-type]
        self._lag_acted = bool(lag_acted)
        self._ahead_armed = bool(ahead_armed)
        self._xi_rate = np.array(xi_rate)
        self._xi_last = xi_last  # type: ignore[assignment]
