"""The runner's inputs and tuning (:mod:`reactmocap.athletics.running`): the speed range,
the tuning values given at three speeds and interpolated between them, and the per-tick log.
Design and measurements: ``docs/athletics.md``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.rig import per_joint
from reactmocap.errors import ConfigError

__all__ = [
    "SPEED_RANGE",
    "STEP_PARAMS",
    "TUNED_SPEEDS",
    "RunLog",
    "RunParams",
    "Speeds",
    "check_speed",
]

#: the speeds the runner is built for (m/s), the paper's range
SPEED_RANGE = (2.5, 5.0)


def check_speed(speed: float) -> float:
    """``speed`` if it lies in :data:`SPEED_RANGE`, else a ConfigError naming the range."""
    lo, hi = SPEED_RANGE
    if not (isinstance(speed, (int, float)) and math.isfinite(speed) and lo <= speed <= hi):
        raise ConfigError(
            f"running speed {speed!r} m/s is outside the supported range {lo:g}-{hi:g} m/s"
        )
    return float(speed)


#: a tuning value at 2.5, 3.5 and 5 m/s (:data:`TUNED_SPEEDS`), interpolated piecewise linearly
Speeds = tuple[float, float, float]
#: the speeds the tuning triples are given at (m/s)
TUNED_SPEEDS = (2.5, 3.5, 5.0)


@dataclass(frozen=True)
class RunParams:
    """The runner's tuning. Values given as three numbers are at 2.5, 3.5 and 5 m/s,
    interpolated piecewise linearly by speed (a single number is used at every speed). Angles in radians, joint
    stiffness in units of ``m g L`` N m/rad (body mass, leg length), leg stiffness in
    ``m g / L`` N/m, times in seconds. The defaults were found by a search over these
    parameters (``benchmarks/bench_athletics_running.py --tune``), see ``docs/athletics.md``.

    Args:
        stance_time: first estimate of the stance duration ``t_s`` (eqs. 1-2); later steps
            use the previous stance's.
        stance_blend: how far each lift-off moves ``t_s`` toward the stance just ended (1:
            all the way, eqs. 1-2's own). 0.3 at 2.5 m/s: in turns the stances varied by
            0.03 s step to step, each feeding the next placement, and the turning runner fell.
        speed_gain: ``k`` of eqs. 1-2, the velocity-error gain (s).
        speed_integral: per step, the placement's slow correction (m) per m/s of the last
            step's speed error, capped at 0.3 m/s (0: eqs. 1-2 alone). Set by hand, not by
            the search, whose 6 s runs are too short to see it: without it the runner fell
            0.3-0.5 m/s short above 3.5 m/s.
        touchdown_leg: hip-to-ankle length at touchdown (fraction of the straight leg).
        speed_matching, retract_time: ground-speed matching: how far (m) the swing foot
            reaches beyond its touchdown place and how long before touchdown it comes back.
        heel_up: foot pitch at touchdown (rad, toes up): the heel strikes first.
        step_width: lateral distance between the feet's touchdown places (m).
        leg_stiffness, leg_damping: the stance leg's spring (``m g / L`` N/m) and its
            damping ratio.
        thrust: the toe phase's extra leg force (body weights), until the body rises at
            ``takeoff_vz`` (m/s).
        thrust_drop: the thrust also stops once the body's vertical speed falls this far (m/s)
            below its peak in the push: when the toe phase began at the bottom of the stance the
            take-off speed was never reached, and the thrust, tilted forward as the leg swept
            back, pushed on to lift-off (+0.26 m/s forward, a long flight, a landing with the
            foot 0.2 m ahead: how the slow-cadence gaits fell). Off from 4 m/s (10: never
            reached), where the gaits were tuned without it.
        toe_fraction: the heel-and-toe phase ends at this fraction of the expected stance
            (the paper: 30-50% by speed).
        pitch: desired forward pitch of the trunk (rad).
        attitude_kp, attitude_kv: the stance hip's attitude servo (roll, pitch, yaw), per
            unit of the body's mass times its leg length squared (1/s^2, 1/s).
        pitch_integral: the attitude servo's integral gain on the trunk's pitch error over
            the stances (1/s^3, per unit as ``attitude_kp``; 0: none): above 3.5 m/s the
            stance hip alone left the trunk 0.1 rad forward of the desired pitch, and the
            runner tripped at 5 m/s.
        attitude_ramp: the attitude torque eases in over this long (s) after touchdown (0:
            at once): its reaction drives the stance thigh, and at once, with the trunk
            pitched forward, it drove the heel into the ground and it bounced off.
        attitude_limit: the most attitude torque (``m g L`` N m; 0: no limit), above what a
            run holding its feet needs (at most 7 at 5 m/s): after a trip the unlimited
            servo reached 30 kN m and the simulation blew up instead of reporting a fall.
        touchdown_limit: the most attitude torque (``m g L`` N m) from touchdown until the
            ball is down (the loading and heel states; 0: ``attitude_limit`` only). A touchdown with the trunk pitched
            forward after a flight that rotated it (0.3-0.4 rad) met 7-8 ``m g L`` at once;
            its reaction on the stance thigh drove the heel into the ground (12-13 body
            weights) and the foot bounced off, which is how the turning runner at 2.5 m/s
            fell. In a traced eight the touchdowns that did not bounce met 1.1-3.4.
        yaw_grip: the twisting moment a stance foot can hold, in units of its length times
            the vertical ground force (a friction coefficient times the lever).
        knee_hold, ankle_hold: stiffness of the stance knee's and ankle's own servos, which
            keep only their roll and yaw (the leg spring drives their pitch).
        push_hold: in the push (the toe and unloading states), the share (0-1) of those
            servos' stiffness and damping kept about the bending (pitch) axis, roll and yaw
            held in full (1: all, as tuned). Their damping there took about half the push
            (the knee -85 N m against the law's 179 at 2.61 m/s). The whole stance free (0
            throughout) fell within 2 s: the landing needs the servos' give.
        push_ramp: in a commanded stance's push, ``push_hold`` falls linearly with the time
            since touchdown, to ``(1 - push_ramp)`` of itself at the stance's end (0: off):
            traced, the ground force fell from 1.5 to 0.5 body weights over the push's last
            0.06 s while the law asked 2, the servos' damping growing with the leg's speed.
            0.3 lengthened the flight (lift-off 0.52 m/s upward against 0.435) but alone fell
            at 2.5 m/s (``docs/athletics.md``, the eleventh round); :data:`STEP_PARAMS` has
            0.218 with ``attitude_ramp`` (the fourteenth round).
        idle_knee, reach_knee: knee flexion of the shortened idle leg, and what it opens to
            by the end of the stance ready for touchdown (rad).
        swing_ready: thigh pitch (rad, forward < 0) the idle leg reaches by lift-off.
        step_stance: the commanded step (s; 0: off, the leg spring and thrust above): from
            :data:`~reactmocap.athletics.running.STEP_AFTER` on, each stance lasts this long,
            the leg's force making the body's vertical speed go from its touchdown value to
            ``step_takeoff`` (m/s) along a half-cosine, with ``step_gain`` (1/s) on the speed's
            error; eqs. 1-2 take ``step_placement`` times it as ``t_s``. Given at every speed or
            none (``step_until`` switches it off above a speed). The leg spring's stance is
            about 0.17 s at 2.6 m/s whatever its values; a human's (the shared run clip's)
            about 0.2 s with a flight of 0.17-0.22 s. An
            opt-in for the clip's speed (:data:`STEP_PARAMS`, with ``push_hold``): it is not
            robust (``docs/athletics.md``, the eighth to tenth rounds).
        step_until: the commanded step only up to this desired speed (m/s, within
            :data:`SPEED_RANGE`; 0: at every speed): above it ``step_stance`` is 0 and
            ``push_hold`` 1, the leg spring's push as tuned, the other values as given. One
            stance time for every speed did not run at 3.25-5 m/s (the fourteenth round).
        step_bias: at the switch into the commanded step, the placement's slow correction
            (``speed_integral``'s sum, m) starts from this, the step's steady value (-0.08 m
            at 2.5-2.7 m/s), rather than from the spring's: built up step by step it took
            6-8 s, and the step ran up to 0.4 m/s slow meanwhile. Within +-0.3 m.
        arm_gain, arm_offset: eq. 5, shoulder pitch = gain * opposite hip pitch + offset.
        elbow: elbow flexion (rad).
        turn_rate: the most the desired facing turns (rad/s), whatever the course asks.
        turn_lead: on a curve, eqs. 1-2's desired velocity is turned into it by ``turn_lead
            * v * kappa`` (s; the velocity a moment ahead): the turn's feed-forward.
        path_integral: the facing is turned by this gain times the curvature times the
            integral of the cross-track error times the curvature (m/s; 0: none),
            which takes out the steady offset a curve leaves.
        lean: how much of the curve's lean ``atan(v^2 kappa / g)`` the trunk takes.
        arm_yaw: the arms' counter-rotation (rad per rad; 0: off): each shoulder's pitch
            moved by this times the trunk's yaw past the desired facing, the left arm back
            and the right forward for a trunk turned left of it, so the arms' reaction turns
            the trunk back without the stance foot's grip. Only where the course curves
            (``ARM_CURVE``; a straight line runs without it) and from ``PATH_AFTER`` on.
            Within [0, 5].
        arm_yaw_rate: the same for the trunk's yaw rate past the desired facing's rate (s;
            0: off): each shoulder's pitch also moved by this times it, the same signs as
            ``arm_yaw``'s, where ``arm_yaw`` acts. Within [0, 1].
        yaw_momentum: how much of the attitude servo's yaw damping acts on the whole body's
            mean yaw rate (its yaw momentum about the COM over its yaw inertia, swing leg and
            arms included) instead of the chest's rate alone (0: off, the chest's; 1: the
            body's). Only where the course curves (``ARM_CURVE``) and from ``PATH_AFTER`` on.
            Within [0, 1].
        smoothing: time constant (s) of the trajectories toward the desired angles (eq. 6).
        stiffness: the servos' stiffness by joint kind outside the stance leg.
        lateral_reach: the most eqs. 1-2 place the heel to the side of the body's line, in
            touchdown leg lengths (0.3: as tuned). On 20 m loops at 4-5 m/s the placement
            asked for up to 0.6-0.8 and the velocity stopped turning with the facing. Within
            [0.3, 1].
        step_chord: the placement's slow speed correction measures each step's progress
            along the facing (0: as tuned) or, by this share, along the step's own chord,
            where the course curves (``ARM_CURVE``): at 4-5 m/s the velocity lagged the
            facing by 0.5-1 rad and the correction read a shortfall that was not there, and
            sped the runner up. Within [0, 1].
        turn_place: on a curve, each foot is placed toward the curve's outside by this
            times the leg length times ``v^2 kappa / g`` (the tangent of the turn's lean; 0:
            off): the leg's force then leans into the curve and gives the centripetal
            force. Eqs. 1-2 give it only from a velocity lagging the facing (0.35-0.5 rad at
            3.5 m/s on a 10 m circle, where the runner fell). From ``PATH_AFTER`` on (from
            the start it upset the first steps). Within [0, 3].
        grip_reserve: the twist ``yaw_grip`` lets the stance hip put along the thigh is
            figured on the vertical ground force less this times its horizontal part (0:
            off, the whole vertical force): the friction that carries the sideways and
            braking force is not there for the twist (a pyramidal cone, ``mu`` 1: 1). On the
            10 m loop at 3.5 m/s the outer foot's sole pushed 600-700 N sideways on 1.8 kN
            and spun 14-16 rad/s under the full grip. At 2.5 m/s the 10 m loops fell with it
            (the twist holds the foot there): off there by speed. From ``PATH_AFTER`` on.
            Within [0, 2].
    """

    stance_time: float | Speeds = (0.2299, 0.177, 0.1639)
    stance_blend: float | Speeds = (0.3, 1.0, 1.0)
    speed_gain: float | Speeds = (0.1914, 0.0835, 0.08567)
    speed_integral: float | Speeds = (0, 0, 0.03)
    touchdown_leg: float | Speeds = (0.93, 0.948, 0.9475)
    speed_matching: float | Speeds = (0, 0.009, 0.03712)
    retract_time: float | Speeds = 0.06
    heel_up: float | Speeds = 0.2
    step_width: float | Speeds = (0.06929, 0.065, 0.05902)
    leg_stiffness: float | Speeds = (32.11, 21.6, 21.19)
    leg_damping: float | Speeds = (0.08527, 0.04, 0.06971)
    thrust: float | Speeds = (1.683, 1.71, 1.716)
    takeoff_vz: float | Speeds = (0.5575, 0.517, 0.5806)
    thrust_drop: float | Speeds = (0.02, 0.02, 10.0)
    toe_fraction: float | Speeds = (0.3849, 0.42, 0.3199)
    pitch: float | Speeds = (0.1207, 0.013, -0.01578)
    attitude_kp: tuple[float, float, float] = (208.7, 208.7, 17.9)
    attitude_kv: tuple[float, float, float] = (14.0, 14.0, 5.42)
    pitch_integral: float | Speeds = (0, 0, 150)
    attitude_limit: float | Speeds = 8.0
    attitude_ramp: float | Speeds = (0, 0, 0.02)
    touchdown_limit: float | Speeds = (4.0, 4.0, 8.0)
    yaw_grip: float | Speeds = 0.181
    knee_hold: float | Speeds = 3.0
    ankle_hold: float | Speeds = 1.0
    push_hold: float | Speeds = 1.0
    push_ramp: float | Speeds = 0.0
    idle_knee: float | Speeds = (2.182, 1.813, 1.692)
    reach_knee: float | Speeds = (1.192, 1.066, 1.102)
    swing_ready: float | Speeds = (-0.3643, -0.369, -0.407)
    arm_gain: float | Speeds = (0.7815, 1.273, 1.336)
    arm_offset: float | Speeds = 0.05
    elbow: float | Speeds = 1.4
    step_stance: float | Speeds = 0.0
    step_takeoff: float | Speeds = 0.96
    step_gain: float | Speeds = 20.0
    step_placement: float | Speeds = 0.7
    step_bias: float | Speeds = 0.0
    step_until: float = 0.0
    turn_rate: float | Speeds = 0.35
    turn_lead: float | Speeds = (0.1, 0, 0)
    path_integral: float | Speeds = (5.0, 0, 0)
    lean: float | Speeds = 1.0
    arm_yaw: float | Speeds = 1.0
    arm_yaw_rate: float | Speeds = 0.05
    yaw_momentum: float | Speeds = 0.0
    smoothing: float | Speeds = (0.02435, 0.0202, 0.0157)
    stiffness: dict[str, float] = field(
        default_factory=lambda: {
            "waist": 4.0, "back": 4.0, "neck": 0.3, "shoulder": 0.4, "elbow": 0.2,
            "wrist": 0.05, "hip": 3.935, "knee": 0.70, "ankle": 0.4,
        }
    )  # fmt: skip
    lateral_reach: float | Speeds = 0.3
    step_chord: float | Speeds = 0.0
    turn_place: float | Speeds = 0.0
    grip_reserve: float | Speeds = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            vals = v.values() if isinstance(v, dict) else v if isinstance(v, tuple) else (v,)
            if not all(isinstance(x, (int, float)) and math.isfinite(x) for x in vals):
                raise ConfigError(f"running parameter {f.name} must be finite, got {v!r}")
            if isinstance(v, tuple) and f.name not in _AXES and len(v) != 3:
                raise ConfigError(
                    f"running parameter {f.name} takes a number or three (at {TUNED_SPEEDS} m/s)"
                )
        per_joint(self.stiffness)  # unknown joint kinds are named there
        for name, top in (
            ("push_hold", 1.0),
            ("push_ramp", 1.0),
            ("arm_yaw", 5.0),
            ("arm_yaw_rate", 1.0),
            ("yaw_momentum", 1.0),
            ("step_chord", 1.0),
            ("turn_place", 3.0),
            ("grip_reserve", 2.0),
        ):
            v = getattr(self, name)
            if not all(0.0 <= b <= top for b in (v if isinstance(v, tuple) else (v,))):
                raise ConfigError(f"{name} must be in [0, {top:g}], got {v}")
        lo, hi = SPEED_RANGE
        for speed in (lo, hi):
            r = self.at(speed)
            if not 0.5 < r["touchdown_leg"] <= 1.0:
                raise ConfigError(f"touchdown_leg must be in (0.5, 1], got {self.touchdown_leg}")
            if r["stance_time"] <= 0 or r["smoothing"] < 0 or r["leg_stiffness"] <= 0:
                raise ConfigError("stance_time and leg_stiffness must be > 0, smoothing >= 0")
            if not 0.0 < r["stance_blend"] <= 1.0:
                raise ConfigError(f"stance_blend must be in (0, 1], got {self.stance_blend}")
            if r["thrust_drop"] <= 0:
                raise ConfigError(f"thrust_drop must be > 0, got {self.thrust_drop}")
            if not 0.3 <= r["lateral_reach"] <= 1.0:
                raise ConfigError(f"lateral_reach must be in [0.3, 1], got {self.lateral_reach}")
            if r["path_integral"] < 0:
                raise ConfigError(f"path_integral must be >= 0, got {self.path_integral}")
            if not (r["step_stance"] == 0 or 0.1 <= r["step_stance"] <= 0.5):
                raise ConfigError(
                    f"step_stance must be 0 (off) or 0.1-0.5 s, got {self.step_stance}"
                )
            if not (0 < r["step_takeoff"] <= 2 and r["step_gain"] >= 0):
                raise ConfigError(
                    f"step_takeoff must be in (0, 2] m/s and step_gain >= 0, got "
                    f"{self.step_takeoff}, {self.step_gain}"
                )
            if not 0 < r["step_placement"] <= 2:
                raise ConfigError(f"step_placement must be in (0, 2], got {self.step_placement}")
            if not -0.3 <= r["step_bias"] <= 0.3:
                raise ConfigError(f"step_bias must be in [-0.3, 0.3] m, got {self.step_bias}")
        steps = self.step_stance if isinstance(self.step_stance, tuple) else (self.step_stance,)
        if 0 in steps and any(steps):
            raise ConfigError(
                f"step_stance must be given at every speed or none (0) (step_until switches it "
                f"off above a speed), got {self.step_stance}"
            )
        if self.step_until and not (any(steps) and lo <= self.step_until <= hi):
            raise ConfigError(
                f"step_until must be 0 (off) or a speed in {lo:g}-{hi:g} m/s with step_stance "
                f"given, got {self.step_until} (step_stance {self.step_stance})"
            )

    def at(self, speed: float) -> dict[str, float]:
        """Every scalar tuning value at ``speed`` (triples interpolated, clamped to the
        range; the commanded step off above ``step_until``)."""
        out = {}
        for f in fields(self):
            if f.name in _AXES or f.name == "stiffness":
                continue
            v = getattr(self, f.name)
            out[f.name] = (
                float(np.interp(speed, TUNED_SPEEDS, v)) if isinstance(v, tuple) else float(v)
            )
        if self.step_until and speed > self.step_until:
            # the step off and its push held again, as the spring was tuned: with the push let
            # through the spring fell in the start at 3.2 m/s (docs, the fifteenth round)
            out["step_stance"] = 0.0
            out["push_hold"] = 1.0
        return out


#: per-axis (roll, pitch, yaw) values, not per-speed
_AXES = ("attitude_kp", "attitude_kv")

#: an opt-in: the commanded step with the push let through and ramped out, the attitude torque
#: eased in after touchdown, for the shared run clip's speed (2.61 m/s: cadence 1.065x, stride
#: 0.939x the clip's); it held 30 s at 2.5-2.7 and 3.0 m/s and 15 of 16 moves of 4-7%; above 3
#: m/s the leg spring (``step_until``), with the step it fell from 3.25 m/s
#: (``docs/athletics.md``, the fourteenth and fifteenth rounds)
STEP_PARAMS = RunParams(
    step_stance=0.226,
    step_until=3.0,
    step_takeoff=0.835,
    step_placement=0.84,
    step_gain=27.0,
    step_bias=-0.097,
    speed_integral=(0.03, 0.0, 0.03),
    toe_fraction=(0.562, 0.42, 0.3199),
    push_hold=0.836,
    push_ramp=0.218,
    attitude_ramp=(0.073, 0.0, 0.02),
)


@dataclass
class RunLog:
    """Per control tick: time, COM, COM velocity, pelvis heading, state index, active leg,
    feet in contact (bit 0 left, bit 1 right), pelvis height, whether anything but the feet
    touched the floor, hip and knee pitch of both legs, desired heading, cross-track error, the
    trunk's (chest's) pitch (rad, forward > 0); and the touchdown and lift-off
    events (time, leg, foot position)."""

    rows: list[tuple] = field(default_factory=list)
    touchdowns: list[tuple[float, int, float, float]] = field(default_factory=list)
    liftoffs: list[tuple[float, int]] = field(default_factory=list)

    def arrays(self) -> dict[str, NDArray]:
        names = ("t", "com", "com_vel", "heading", "state", "active", "feet", "pelvis",
                 "others", "hip", "knee", "desired_heading", "cross_track", "trunk_pitch")  # fmt: skip
        if not self.rows:
            return {n: np.zeros(0) for n in names}
        cols = list(zip(*self.rows))
        return {n: np.array(c) for n, c in zip(names, cols)}
