"""Whole-body mocap tracking by inverse dynamics with optimised ground forces (Macchietto et al.
2009, Lee et al. 2010, Muico et al. 2009): each tick a small least-squares program for every
DOF's acceleration (the pelvis moved only by ground forces at the sole corners in contact,
inside friction pyramids), realised as joint torques. Only joint torques act: the result is
physical. A foot pivoting in the mocap touches through its ball-of-foot patch. For whole clips
the mocap's ground path is re-anchored to the feet, the targets keep its capture point inside
them, and a capture-point step catches the body when it leaves them. The program, and why:
``docs/design.md`` and ``docs/tracking.md``."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray
from scipy.linalg.blas import dtrsm
from scipy.linalg.lapack import dposv, dpotrf, dpotrs
from scipy.optimize import nnls

from reactmocap.errors import ConfigError, SimulationError
from reactmocap.library.motion import Motion
from reactmocap.sim.character import BALL_JOINTS, SIM_BODIES
from reactmocap.sim.controllers.anchoring import AnchoredReference, rot2
from reactmocap.sim.controllers.base import check_character, check_params
from reactmocap.sim.controllers.stepping import outside_distance
from reactmocap.sim.reference import ReferencePath, reference_path, with_soles
from reactmocap.sim.servo import critical_kv
from reactmocap.sim.world import World

__all__ = ["WholeBodyPlan", "WholeBodyTracker"]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)
NV = 6 + 3 * NJ
# friction pyramid edge directions per unit of mu (world x+, x-, y+, y-)
_PYRAMID = np.array([[1, 0], [-1, 0], [0, 1], [0, -1]], dtype=np.float64)
_UP = np.array([[0.0], [0.0], [1.0]])
# largest acceleration a swinging foot's rows ask for (m/s^2, and rad/s^2 for its tilt)
_SWING_ACC = 100.0
_ZERO3 = np.zeros(3)
# a walk's push within this angle of sideways (tan 30 deg) places its swing feet
_PLACE_SIDE_TAN = float(np.tan(np.radians(30.0)))
# a walk's push within this angle of straight against the walk is one ``kp_root_against``
# answers (back alone of the push benchmark's eight directions: with back-left and
# back-right too it lost more pushes than it caught)
_AGAINST_COS = float(np.cos(np.radians(30.0)))
# the patch's centre-of-pressure corners along the foot's (x, y) axes
# r @ _LEVI_CIVITA, reshaped (3, 3), is -[r]x (the cross-product matrix's negative)
_LEVI_CIVITA = np.array(
    [[0, 0, 0, 0, 0, 1, 0, -1, 0], [0, 0, -1, 0, 0, 0, 1, 0, 0], [0, 1, 0, -1, 0, 0, 0, 0, 0]],
    dtype=np.float64,
)
_PATCH_SIGNS = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
# a patch's five points: its centre (a pyramid's 4 edges), then its 4 corners (straight up)
_PATCH_OWNER = np.array([0, 0, 0, 0, 1, 2, 3, 4])


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
    nrows: tuple[int, ...] = ()  # per foot in ``feet``, its rows in ``rows``


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


class WholeBodyTracker(AnchoredReference):
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
        trunk_weight: weight of three rows holding the chest's world angular acceleration
            to what the pelvis, waist and back targets together ask (0: none). While the
            pelvis targets ask more than the feet can give, the program otherwise bends the
            waist to hold the pelvis (a hip strategy that never comes back): on whole clips
            the waist drifted ~1 rad in the 0.5-1 s before most falls (``docs/tracking.md``).
        trunk_give, trunk_band: while the mocap stands (both feet planted for
            ``step_time``), the trunk rows are off while an external force acts on the
            character (``xfrc_applied``, e.g. a push) and, after one, while the simulated
            capture point is more than ``trunk_band`` m from the mocap's; they come back
            linearly over ``trunk_give`` s after (0: they never give). Held, they kept the chest still where
            a standing body needs the hip strategy (a guard stance fell under 150 N
            sideways); a walk keeps them (it fell under smaller pushes without them).
        kp_root_pushed: with ``trunk_give``, a push that starts while the mocap does not stand
            sets ``kp_root`` to this for the rest of the rollout (0: unchanged).
        kp_root_against: with ``kp_root_pushed``, a walk's push within 30 deg of straight
            against the walk sets ``kp_root`` to this instead (0: ``kp_root_pushed``): slowed
            by the softer servo, such a walk trailed its clip for 1-2 s, its steps landing on
            its capture point (``docs/tracking.md``).
        hip_weight, hip_gain, hip_free, hip_margin, hip_back, hip_tilt: a hip strategy after
            a push while the mocap stands (0: off): while the simulated capture point is
            within ``hip_margin`` m of the feet's edge or beyond, rows of weight ``hip_weight``
            ask the ground forces for the centre-of-mass acceleration that brings it back to
            the mocap's (critically damped at ``hip_gain`` times omega), and the pelvis rows
            and the waist, back and hip joint rows drop to ``hip_free`` of their weight, so
            the trunk's turn about the hips lets the ground push the body back further than
            the feet's centre of pressure could. It fades as the trunk turns ``hip_tilt`` rad
            (the pelvis, waist and back rotation errors summed) and, once the capture point is
            back inside, over ``hip_back`` s.
        hip_tilt_step: ``hip_tilt`` while balance steps are on (0: ``hip_tilt``): a step then
            takes over from a hip strategy that cannot hold before the trunk has folded far
            (straightening a trunk folded 1.3 rad threw the body forward as the step began).
        contact_weight, contact_kv: ``w_c`` and ``k_c`` of the no-slip term.
        friction: fraction of the floor's friction coefficient the plan may use.
        reach: a foot is planted in the mocap when its sole is within ``reach`` m of the
            floor; a sole corner supports when it is below ``floor + touch`` in the
            simulation (0: exactly MuJoCo's contact set; 3 mm keeps a foot that rests on
            two corners from standing on a line).
        force_reg: ``lam``, the regulariser on the pyramid coefficients (relative).
        pivot_rate: a planted foot pivots (touches through its ball patch) while the mocap
            foot's yaw rate is above this (rad/s); ``None``: feet never pivot. With a
            :class:`ReferencePath` given, its own ``planted`` and ``pivoting`` are used.
        slide_speed: a foot near the floor is planted only while its lowest corner moves
            slower than this (m/s) or it pivots (0: any speed).
        centre_speed: and only while its sole's centre moves slower than this (m/s; 0: any
            speed): a swinging foot rolling over its lowest corner keeps that corner slow.
        roll_band: a sole corner carries force only while the mocap holds it within this of
            its foot's lowest corner (m): a heel the actor raises is let go (0: every
            touching corner).
        anchor_tau, anchor_touch, anchor_return: the mocap's ground path (heading and
            horizontal position) is moved, with time constant ``anchor_tau`` (s; 0: never),
            toward where the feet that are planted and within ``anchor_touch`` m of the floor
            really are, and back toward the captured path with ``anchor_return`` (s; 0:
            never). Only the feet's error beyond ``anchor_deadband`` m (heading: that over
            0.5 m, in rad) moves it.
        balance_margin, balance_tau: while both feet support, the pelvis and centre-of-mass
            targets shift (time constant ``balance_tau``, 0: never) so the mocap's capture
            point stays ``balance_margin`` m inside the feet on the floor.
        stepping, step_margin, step_time, step_height: with ``stepping``, a balance step
            (lasting ``step_time`` s, lifting ``step_height`` m) starts when the simulated
            capture point is ``step_margin`` m outside both feet while the mocap stands and
            the body is still up. Off by default: ``push`` turns it on (tracking a whole clip,
            the steps it took in fighting stances sometimes ended in a blow-up).
        step_pushed: a push while the mocap stands turns ``stepping`` on for the rest of the
            rollout (an unpushed clip never steps).
        step_leg: during a balance step the pelvis target drops to where a leg ``step_leg``
            times the pelvis's starting height reaches the step's target (at most 0.4 of that
            height lower) and the stance leg's joint rows to 0.3, so the stance knee bends
            (0: off; at the standing height a long step's foot hovered short of the floor).
        step_alternate: a balance step within 0.5 s of one landing is by the other foot, and a
            foot the body has lifted off the floor (the mocap's leg pose lifts the one left
            behind) steps when the capture point leaves the other.
        step_short: after a balance step has landed, a step shorter than ``step_short`` m
            swings in proportionally less time (at least 0.4 of ``step_time``; 0: off):
            putting back down a foot that the wide stance after a step had lifted took the
            whole step time while the body fell toward it.
        step_ease: with ``step_leg``, the pelvis target lowered for a balance step comes
            back up after the step lands with this time constant (s; 0: in one tick, as
            before), and the next step lowers it from there: the jump back up asked the
            ground for 11 kN for a tick as the step landed and rolled the foot that had caught
            the fall onto an edge (``docs/tracking.md``).
        step_ease_in: with ``step_ease``, a balance step that starts while the target is
            still coming back up lowers it with this time constant (s; 0: at once, as before);
            a first step's drop stays instant (easing every drop lost directions at Wooten's
            figure): a second step's one-tick drop left the plan asking no ground force.
        step_hold: after a balance step has landed, a body whose centre of mass is slower
            than ``step_hold`` m/s (0: off) steps again only when its capture point is more
            than 5 cm outside the feet (not ``step_margin``): the steps started at the edge
            from near rest each lifted a foot and relaunched the body (``docs/tracking.md``).
        step_hold_for: with ``step_hold``, hold such a body only for ``step_hold_for`` s after
            the last landing (0: any time): held longer, a capture point drifting out ended in
            a longer step that started a new chain (``docs/tracking.md``).
        step_soft, step_soft_reg: for ``step_soft`` s after a balance step lands (0: off),
            the landed foot's no-slip rows come in linearly from a tick's share and the
            ground forces' regulariser is ``step_soft_reg`` instead of ``force_reg`` (a soft
            touchdown): a landing asked the ground for 11-14 kN over 20 ms
            (``docs/tracking.md``).
        swing_weight, kp_swing: weight and stiffness (critically damped) of a stepping
            foot's position and tilt rows.
        place_gain, place_deadband, place_height: while a foot swings in the mocap (its sole
            above ``place_height``) and the simulated capture point is more than
            ``place_deadband`` m from the mocap's, the foot lands ``place_gain`` times that
            error (at most 0.4 m) from the mocap's landing (0: off; see ``docs/tracking.md``).
        warp_gain: a push that starts while the mocap does not stand (a walk) makes the clip
            play faster for the rest of the rollout: at a rate ``warp_gain`` of the way from 1
            to the body's horizontal speed over the mocap's (centre of mass; at most 1.8, never
            slower than 1), so the steps come as fast as the pushed body needs
            and, the clip a little slower than the body, the body sheds the extra speed and the
            rate comes back to 1 (0: off; ``docs/tracking.md``).
        warp_lead: with ``warp_gain``, after a sideways walk's push (within 30 deg of the
            side), the clip's rate also rises by ``warp_lead`` per m that the simulated capture
            point runs ahead of the mocap's along the mocap's walk (falls by as much behind,
            never below 1), so a body that drifts ahead after its sideways fall is caught gets
            its next steps sooner (0: off; ``docs/tracking.md``).
        warp_for: with ``warp_gain``, the clip's rate follows the body only this long (s)
            after the walk's push starts, then goes back to 1 (0: for the rest of the
            rollout; ``docs/tracking.md``).
        warp_phase: with ``warp_gain``, after a walk's push (any direction), once the body's
            centre of mass is ``warp_phase`` m ahead of the mocap's along the mocap's walk and
            until it no longer is, the clip's clock moves on by the clip time that closes that
            lead (time constant 0.3 s, never back), so the clip's phase follows the body as
            its ground path follows the feet (0: off; ``docs/tracking.md``).
        place_pushed: after a sideways walk's push (within 30 deg of the side), a swinging
            foot on the side the body falls to lands ``place_pushed`` times the sideways gap
            between the simulated and the mocap's capture point, grown to the mocap's landing
            (a linear inverted pendulum), further out (at most 0.6 m outside the stance foot;
            only past ``place_deadband``, while the clip walks away from that side and the
            capture point is past the stance foot, and only in the 0.5 s after the push
            starts; the pelvis lowered so the leg reaches; 0: off; ``docs/tracking.md``).
        anchor_lag: for 0.7 s after a walk's push starts, while the body's centre of mass
            moves more than 45 deg off the clip's walk, the mocap's ground path follows the
            feet only where they lag it along the walk by more than this (m; all of it at half
            the clip's speed or slower, none at its speed; 0: off), so the clip's pelvis pulls
            the body back to the clip's speed and way: re-anchored to the feet, the path of a
            body slowed and turned off its walk was dragged after them (``docs/tracking.md``).
        anchor_lag_heading: with ``anchor_lag``, the path lags the feet not for 0.7 s but
            until the body's centre of mass, having moved more than 45 deg off the clip's walk,
            moves within this many deg of it again (above 0.2 m/s; 0: the fixed 0.7 s;
            ``docs/tracking.md``).
        anchor_lag_speed: with ``anchor_lag``, the path lags the feet only while the body's
            centre of mass moves slower than this fraction of the clip's speed (0: at any
            speed): a body slowed less, its path held ahead, was pulled back up to speed past
            its feet and fell (``docs/tracking.md``).
        step_ahead: after a walk's push within 60 deg of straight back, while the clip
            holds both feet planted, a capture point past the front foot along the clip's walk
            by more than ``step_ahead`` times the clip's own largest such lead in its double
            supports starts a balance step of the rear foot
            (:func:`~reactmocap.sim.controllers.stepping.step_target`; 0: off): a body that
            ran past its feet in a double support of the clip's stepped too late
            (``docs/tracking.md``).
        step_ahead_horizon: with ``step_ahead``, the step also starts when the lead grown
            by the capture point's present velocity over this many s passes the clip's own
            largest lead in its double supports grown the same way (0: the lead now only),
            so a lead growing fast starts it earlier (``docs/tracking.md``).
        step_ahead_swing: with ``step_ahead``, also in the clip's single supports (its
            one-frame double supports counted as swing, then also for the step from double
            support): a capture point predicted (pivoting over the stance foot) to the clip's
            landing of its swing foot past that landing by more than ``step_ahead`` times the
            clip's own largest such lead brings the landing forward, a balance
            step of the swing foot taking this fraction of the clip's time left to its
            landing (in (0, 1]; 0: off) (``docs/tracking.md``).
        step_ahead_phase: with ``step_ahead_swing``, the swing step's limit matched to the
            swing's phase: the clip's own predicted lead at the same frame plus this margin
            (m, at most 0.5), in place of ``step_ahead`` times its largest such lead (0: off)
            (``docs/tracking.md``).
        centre_speed_lock: the foot lock (contact rows, the ground path's anchoring, the
            pivot patch) reads a foot as planted only while its sole centre also moves slower
            than this (m/s; 0: off), while the balance shift, the balance steps and
            ``step_ahead`` keep the clip's flags (``centre_speed`` filters them all)
            (``docs/tracking.md``, issue 16).
        centre_speed_lock_walking: ``centre_speed_lock`` only on a walking clip, one whose
            centre of mass's median horizontal speed is at least this (m/s; 0: every clip;
            needs ``centre_speed_lock``): the walks 1.0-1.6 m/s, the fighting clips 0.05-0.42
            (``docs/tracking.md``, issue 16).
        anchor_turn_rate: the ground path's heading (``anchor_tau``) turns at most this much
            faster (rad/s) than the clip's own soles that set it (their mean yaw rate): with
            ``centre_speed`` 2.5 a foot down early took a walk's path 13 deg round in 0.1 s
            (0: unbounded; needs ``anchor_tau``) (``docs/tracking.md``, issue 16).
        step_ahead_servo: with ``step_ahead``, the pelvis position servo's gain while one of
            its steps is under way (1/s^2, at most 100; 0: off): the clip's pelvis, at the
            clip's speed, pulled the body on past its feet (``docs/tracking.md``, issue 16).
        torque_limit: the largest joint torque the plan may apply (N m, the norm of each ball
            joint's torque; 0: none). The plan's torques come as feed-forward, which the
            servo's own ``torque_limit`` does not clip; a hit body whose plan asked for 41 kN m
            at a hip blew up (the bow kicked, ``docs/benchmarks.md``).
        flat_weight, flat_band: a foot planted in the mocap that supports on at most two
            sole corners, its sole more than ``flat_band`` rad off the mocap's, gets two rows
            of weight ``flat_weight`` (as ``swing_weight``; 0: off) turning its sole toward the
            mocap's (``kp_swing``, critically damped): a foot loaded on its edge while the
            mocap's was flat stayed on it and the capture point left the line of the edges
            (``docs/tracking.md``, issue 16).
        flat_toe: with ``flat_weight``, no flat rows in a clip whose planted soles' median
            toe-down pitch is past this (rad; 0: off): it stands on the balls of its feet on
            purpose, which the box foot's toe edge cannot do; every rule per foot and tick
            tried still felled such a clip (``docs/tracking.md``, issue 16).
        servo_kv: the servo's damping (1/s).
        hold_balance: once the simulated capture point leaves the feet on the floor (a hit
            the ankles cannot take), the pelvis and leg rows keep their gains for the rest of
            the rollout, whatever :meth:`scale_gains` asks: the body gives way above the hips
            and keeps its balance (the response's physical mode; a lighter hit yields whole;
            ``docs/benchmarks.md``).

    The constructor's defaults are the short-window tracker (the captured world path, every
    touching corner, any foot near the floor; chosen on the benchmark's 1 s windows);
    :data:`~reactmocap.sim.controllers.registry.WHOLE_CLIP` holds the options ``track`` and
    ``push`` add for whole clips (``docs/tracking.md``).
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
        trunk_weight: float = 0.0,
        trunk_give: float = 0.0,
        trunk_band: float = 0.1,
        kp_root_pushed: float = 0.0,
        kp_root_against: float = 0.0,
        hip_weight: float = 0.0,
        hip_gain: float = 2.0,
        hip_free: float = 0.3,
        hip_margin: float = 0.03,
        hip_back: float = 0.5,
        hip_tilt: float = 1.6,
        hip_tilt_step: float = 0.0,
        contact_weight: float = 1e4,
        contact_kv: float = 20.0,
        friction: float = 0.7,
        reach: float = 0.05,
        touch: float = 0.0,
        force_reg: float = 1e-6,
        pivot_rate: float | None = 2.0,
        slide_speed: float = 0.0,
        centre_speed: float = 0.0,
        roll_band: float = 0.0,
        anchor_tau: float = 0.0,
        anchor_touch: float = 0.01,
        anchor_return: float = 5.0,
        anchor_deadband: float = 0.1,
        balance_margin: float = 0.03,
        balance_tau: float = 0.0,
        stepping: bool = False,
        step_margin: float = 0.02,
        step_time: float = 0.35,
        step_height: float = 0.06,
        step_leg: float = 0.0,
        step_pushed: bool = False,
        step_alternate: bool = False,
        step_short: float = 0.0,
        step_ease: float = 0.0,
        step_ease_in: float = 0.0,
        step_hold: float = 0.0,
        step_hold_for: float = 0.0,
        step_soft: float = 0.0,
        step_soft_reg: float = 1e-2,
        swing_weight: float = 10.0,
        kp_swing: float = 400.0,
        place_gain: float = 0.0,
        place_deadband: float = 0.15,
        place_height: float = 0.03,
        warp_gain: float = 0.0,
        warp_lead: float = 0.0,
        warp_phase: float = 0.0,
        warp_for: float = 0.0,
        place_pushed: float = 0.0,
        anchor_lag: float = 0.0,
        anchor_lag_heading: float = 0.0,
        anchor_lag_speed: float = 0.0,
        step_ahead: float = 0.0,
        step_ahead_horizon: float = 0.0,
        step_ahead_swing: float = 0.0,
        step_ahead_phase: float = 0.0,
        centre_speed_lock: float = 0.0,
        centre_speed_lock_walking: float = 0.0,
        anchor_turn_rate: float = 0.0,
        step_ahead_servo: float = 0.0,
        hold_balance: bool = False,
        torque_limit: float = 0.0,
        flat_weight: float = 0.0,
        flat_band: float = 0.07,
        flat_toe: float = 0.0,
        servo_kv: float,
        control_every: int,
    ) -> None:
        check_character(world, character)
        if not (isinstance(control_every, int) and control_every >= 1):
            raise ConfigError(f"control_every must be an int >= 1, got {control_every!r}")
        check_params(
            {
                "kp_root": kp_root, "kp_rot": kp_rot, "kp_joint": kp_joint,
                "root_weight": root_weight, "trunk_weight": trunk_weight, "contact_weight": contact_weight,
                "trunk_give": trunk_give, "trunk_band": trunk_band,
                "kp_root_pushed": kp_root_pushed, "kp_root_against": kp_root_against, "hip_weight": hip_weight, "hip_gain": hip_gain,
                "hip_free": hip_free, "hip_margin": hip_margin, "hip_back": hip_back,
                "hip_tilt": hip_tilt, "hip_tilt_step": hip_tilt_step,
                "contact_kv": contact_kv, "friction": friction, "reach": reach, "touch": touch,
                "force_reg": force_reg, "pivot_rate": pivot_rate, "servo_kv": servo_kv,
                "slide_speed": slide_speed, "centre_speed": centre_speed, "roll_band": roll_band, "anchor_tau": anchor_tau,
                "anchor_touch": anchor_touch,
                "anchor_return": anchor_return, "anchor_deadband": anchor_deadband, "balance_margin": balance_margin,
                "balance_tau": balance_tau, "stepping": stepping, "step_margin": step_margin, "step_time": step_time,
                "step_height": step_height, "step_leg": step_leg,
                "step_pushed": step_pushed, "step_alternate": step_alternate,
                "step_short": step_short, "step_ease": step_ease, "step_ease_in": step_ease_in,
                "step_hold": step_hold, "step_hold_for": step_hold_for,
                "step_soft": step_soft, "step_soft_reg": step_soft_reg,
                "swing_weight": swing_weight, "kp_swing": kp_swing,
                "place_gain": place_gain, "place_deadband": place_deadband,
                "place_height": place_height, "warp_gain": warp_gain, "warp_lead": warp_lead,
                "warp_phase": warp_phase, "warp_for": warp_for, "place_pushed": place_pushed,
                "anchor_lag": anchor_lag, "anchor_lag_heading": anchor_lag_heading,
                "anchor_lag_speed": anchor_lag_speed, "step_ahead": step_ahead,
                "step_ahead_horizon": step_ahead_horizon, "step_ahead_swing": step_ahead_swing,
                "step_ahead_phase": step_ahead_phase, "centre_speed_lock": centre_speed_lock,
                "centre_speed_lock_walking": centre_speed_lock_walking,
                "anchor_turn_rate": anchor_turn_rate, "torque_limit": torque_limit,
                "step_ahead_servo": step_ahead_servo,
                "kv_root": kv_root, "kv_rot": kv_rot, "kv_joint": kv_joint, "hold_balance": hold_balance,
                "flat_weight": flat_weight, "flat_band": flat_band, "flat_toe": flat_toe,
            },
        )  # fmt: skip
        if not 0.0 < hip_free <= 1.0 or (hip_weight and not (hip_back and hip_tilt)):
            raise ConfigError(
                f"hip_free must be in (0, 1], hip_back and hip_tilt > 0 with hip_weight, got "
                f"hip_free {hip_free!r}, hip_back {hip_back!r}, hip_tilt {hip_tilt!r}"
            )
        if step_leg and not 0.5 <= step_leg <= 1.5:
            raise ConfigError(
                f"step_leg must be 0 (off) or in [0.5, 1.5] (a leg over the pelvis's height), "
                f"got {step_leg!r}"
            )
        if centre_speed_lock_walking and not centre_speed_lock:
            raise ConfigError(
                f"centre_speed_lock_walking ({centre_speed_lock_walking!r}) gates the foot lock: "
                f"it needs centre_speed_lock > 0"
            )
        if anchor_turn_rate and not anchor_tau:
            raise ConfigError(
                f"anchor_turn_rate ({anchor_turn_rate!r}) bounds the anchoring's turn: it needs "
                f"anchor_tau > 0"
            )
        if step_ahead_horizon and not step_ahead:
            raise ConfigError(
                f"step_ahead_horizon ({step_ahead_horizon!r}) only extends step_ahead's "
                f"trigger: it needs step_ahead > 0"
            )
        if step_ahead_swing and not (step_ahead and 0.0 < step_ahead_swing <= 1.0):
            raise ConfigError(
                f"step_ahead_swing ({step_ahead_swing!r}) is a fraction in (0, 1] of the "
                f"clip's swing left, and extends step_ahead's trigger: it needs step_ahead > 0"
            )
        if step_ahead_phase and not (step_ahead_swing and 0.0 < step_ahead_phase <= 0.5):
            raise ConfigError(
                f"step_ahead_phase ({step_ahead_phase!r}) is a margin in (0, 0.5] m over the "
                f"clip's own lead, and sets step_ahead_swing's limit: it needs step_ahead_swing"
            )
        if step_ahead_servo and not (step_ahead and step_ahead_servo <= 100.0):
            raise ConfigError(
                f"step_ahead_servo ({step_ahead_servo!r}) is the pelvis servo's gain during "
                f"step_ahead's steps, in (0, 100] 1/s^2: it needs step_ahead > 0"
            )
        if not 0.0 < flat_band < np.pi / 2 or (flat_weight and not swing_weight):
            # the rows are the swing task's tilt rows, rescaled from ``swing_weight``
            raise ConfigError(
                f"flat_band must be in (0, pi/2) rad and flat_weight needs swing_weight > 0, "
                f"got flat_band {flat_band!r}, flat_weight {flat_weight!r}, "
                f"swing_weight {swing_weight!r}"
            )
        if flat_toe and not (flat_weight and flat_toe < np.pi / 2):
            raise ConfigError(
                f"flat_toe ({flat_toe!r}) is a toe-down pitch in (0, pi/2) rad past which "
                f"a clip gets no flat_weight rows: it needs flat_weight > 0"
            )
        servo = world.servo
        m = world.model
        if np.any(m.opt.gravity[:2]):
            raise ConfigError("WholeBodyTracker assumes vertical gravity")
        self.servo = servo
        self.servo_kv = float(servo_kv)
        self.control_every = int(control_every)
        self.torque_limit = float(torque_limit)
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
        self._w_root = float(root_weight)
        self._root_rows = np.eye(6, NV) * self._w_root
        self._free = np.zeros(0, dtype=bool)  # the last NNLS solution's positive coefficients
        self._wj = np.ones(3 * NJ)
        self._w_trunk = float(trunk_weight)
        self._give = float(trunk_give)
        self._give_band = float(trunk_band)
        self._kp_root_pushed = float(kp_root_pushed)
        self._kp_root_against = float(kp_root_against)
        # ``step_ahead_servo``: the pelvis gain while a step after a back push is under way,
        # and the one the push set (back to it on landing)
        self._ahead_servo = float(step_ahead_servo)
        self._kp_pushed = float(self.kp[0])
        self._step_pushed = bool(step_pushed)
        self._pushed = False  # an external force has acted on the body
        self._pushing = False  # one acts now
        self._standing = False  # the mocap stands now (both feet planted for step_time)
        self._xfrc = np.zeros((len(wc.body_ids), 6))
        self._back_from = -np.inf  # the last time they were off
        self._w_hip = float(hip_weight)
        self._hip_gain = float(hip_gain)
        self._hip_free = float(hip_free)
        self._hip_margin = float(hip_margin)
        self._hip_back = float(hip_back)
        self._hip_tilt = float(hip_tilt)
        self._hip_tilt_step = float(hip_tilt_step) or self._hip_tilt
        self._hip_from = -np.inf  # the last time the hip strategy was fully on
        self._hip_acc = np.zeros(2)  # the centre of mass's horizontal acceleration it asks
        # the joints whose rows it frees: the trunk turns about the hips
        self._hip_joints = np.concatenate(
            [3 * BALL_JOINTS.index(j) + np.arange(3) for j in ("waist", "back", "l_hip", "r_hip")]
        )
        self._mass = float(m.body_subtreemass[wc.body_ids[0]])
        self._chest = int(wc.body_ids[SIM_BODIES.index("chest")])
        self.sqrt_wc = float(np.sqrt(contact_weight))
        self.contact_kv = float(contact_kv)
        self.mu = float(friction) * float(world.config.friction)
        self.touch = float(touch)
        self.sqrt_reg = float(np.sqrt(force_reg))
        self._dofs = wc.qvel_slice
        self._full = np.zeros((m.nv, m.nv))
        # translation rows over rotation rows, filled by mj_jac / mj_jacDot through views
        self._jac6 = np.zeros((6, m.nv))
        self._jacd6 = np.zeros((6, m.nv))
        self._jacp, self._jacr = self._jac6[:3], self._jac6[3:]
        self._jacd, self._jacrd = self._jacd6[:3], self._jacd6[3:]
        self._qref = np.zeros(m.nq)
        self._dq = np.zeros(m.nv)
        rows = character * NJ
        self._ff = servo.feedforward[rows : rows + NJ]  # (15, 3) view
        edges = np.column_stack([self.mu * _PYRAMID, np.ones(4)])  # (4, 3)
        self._edges = edges.T  # (3, 4) columns: unnormalised pyramid edges
        self._corner_basis = np.tile(edges, (4, 1, 1))  # (corner, edge, xyz)
        self._corner_owner = np.repeat(np.arange(4), 4)
        self._patch_basis = np.concatenate([edges, np.tile(_UP.T, (4, 1))])
        self.last_plan: WholeBodyPlan | None = None
        #: ``(6,)`` extra pelvis acceleration asked of the plan (world linear m/s^2, local
        #: angular rad/s^2), on top of its feedback; set by
        #: :class:`~reactmocap.sim.controllers.predictive.PredictiveTracker`, zero otherwise
        self.root_bias = np.zeros(6)
        path = with_soles(
            world,
            character,
            reference
            if isinstance(reference, ReferencePath)
            else reference_path(
                world,
                character,
                reference,
                reach=reach,
                pivot_rate=pivot_rate,
                slide_speed=slide_speed or None,
                centre_speed=centre_speed or None,
            ),
        )
        super().__init__(
            world, character, path, start, dt_tick=self.control_every * world.timestep,
            roll_band=roll_band, anchor_tau=anchor_tau, anchor_touch=anchor_touch,
            anchor_return=anchor_return, anchor_deadband=anchor_deadband,
            balance_margin=balance_margin, balance_tau=balance_tau, stepping=stepping,
            step_margin=step_margin, step_time=step_time, step_height=step_height,
            place_gain=place_gain, place_deadband=place_deadband, place_height=place_height,
            warp_gain=warp_gain, warp_lead=warp_lead, warp_phase=warp_phase, step_leg=step_leg,
            step_alternate=step_alternate, step_short=step_short,
            place_pushed=place_pushed, step_ease=step_ease, step_ease_in=step_ease_in,
            step_hold=step_hold, step_hold_for=step_hold_for, warp_for=warp_for,
            anchor_lag=anchor_lag, anchor_lag_heading=anchor_lag_heading,
            anchor_lag_speed=anchor_lag_speed, step_ahead=step_ahead,
            step_ahead_horizon=step_ahead_horizon, step_ahead_swing=step_ahead_swing,
            step_ahead_phase=step_ahead_phase, centre_speed_lock=centre_speed_lock,
            anchor_turn_rate=anchor_turn_rate, centre_speed_lock_walking=centre_speed_lock_walking,
        )  # fmt: skip
        self._stand_frames = max(1, round(self.step_time * self.path.fps))
        self._flat_w = float(flat_weight)
        if flat_toe and self._toe_pitch() > np.sin(flat_toe):
            self._flat_w = 0.0  # a clip on the balls of its feet: no flat rows
        self._flat_cos = float(np.cos(flat_band))
        self._soft = float(step_soft)
        self._soft_reg = float(np.sqrt(step_soft_reg))
        self._dt_tick = self.control_every * world.timestep
        self.sqrt_ws = float(np.sqrt(swing_weight))
        self.kp_swing = float(kp_swing)
        self.kv_swing = critical_kv(kp_swing)
        legs = [
            [BALL_JOINTS.index(f"{side}_{j}") for j in ("hip", "knee", "ankle")] for side in "lr"
        ]
        self._leg_rows = [np.concatenate([3 * k + np.arange(3) for k in leg]) for leg in legs]
        self._hold_balance = bool(hold_balance)
        self._stance_rows = np.r_[np.arange(6), 6 + np.concatenate(self._leg_rows)]
        self._holding = False  # hold_balance has taken hold
        self._scale = 1.0  # the last scale_gains
        self._stiffness = 1.0  # the last stiffen_joints
        self.release()

    # ------------------------------------------------------------------ control
    def release(self) -> None:
        """Give both feet back their sole boxes (undo any pivot). The tracker switches patches
        at each tick; call this when done with a world that lives on."""
        for f in range(2):
            self.world.set_foot_patch(self.character, f, False)

    def _support(
        self, d: mujoco.MjData, planted: NDArray[np.bool_], held: NDArray[np.bool_]
    ) -> _Support:
        """The contact model at the current state: the sole corners MuJoCo has in contact that
        the mocap holds down (``held`` ``(2, 4)``), or the ball patch of a pivoting foot, of
        the feet planted in the mocap."""
        m = self.world.model
        corners = self.sole_corners()
        patch_on = self.world.foot_patch_on(self.character)
        sl = self._dofs
        qdot = d.qvel[sl]
        feet: list[int] = []
        gens: list[F64] = []  # (nb_f, ndof) the generators as generalised forces
        bases: list[F64] = []  # (nb_f, 3) world force per unit coefficient
        owners: list[NDArray[np.int64]] = []  # (nb_f,) the point of each coefficient
        pts: list[F64] = []
        rows: list[F64] = []
        bias: list[F64] = []
        nrows: list[int] = []
        k0 = 0
        for f in range(2):
            if not planted[f]:
                continue
            if patch_on[f]:
                rot = d.geom_xmat[self.patch[f]].reshape(3, 3)
                p = d.geom_xpos[self.patch[f]] - rot[:, 2] * self.patch_half[f]  # bottom face
                low = p[2] - self.patch_half[f] * np.abs(rot[2, :2]).sum()  # its lowest corner
                if low - self.floor_z >= self.touch:
                    continue
                axes = d.geom_xmat[self.sole[f]].reshape(3, 3)[:, :2].T.copy()
                axes[:, 2] = 0.0  # the centre-of-pressure range lies on the floor
                axes /= np.linalg.norm(axes, axis=1, keepdims=True)
                # the patch's centre holds still (pyramid), its centre-of-pressure corners push
                p_f = np.concatenate([p[None], p + self.patch_arm[f] * (_PATCH_SIGNS @ axes)])
                basis, owner, still = self._patch_basis, _PATCH_OWNER, 1
            else:
                touching = corners[f, :, 2] - self.floor_z < self.touch
                if not touching.any():
                    continue
                if (touching & held[f]).any():
                    touching &= held[f]
                p_f = corners[f, touching]
                k = len(p_f)
                basis, owner, still = self._corner_basis[:k], self._corner_owner[: 4 * k], k
            feet.append(f)
            # every point of the foot from the foot's Jacobians at its origin (two calls, not
            # two per point): a point r from it moves at v + w x r and accelerates (qdd = 0) at
            # a + alpha x r + w x (w' x r), w' the body's velocity of MuJoCo's last forward
            # pass (``cvel``), as ``mj_jacDot`` has it (with w' = w, results moved: a whole walk
            # drifted 1.1 m instead of 0.45 m)
            body = int(self.feet[f])
            o = d.xpos[body]
            mujoco.mj_jac(m, d, self._jacp, self._jacr, o, body)
            mujoco.mj_jacDot(m, d, self._jacd, self._jacrd, o, body)
            jr = self._jac6[3:, sl]
            w = jr @ qdot
            acc0 = self._jacd6[:, sl] @ qdot  # (a, alpha) of the origin
            r = p_f - o
            neg_skew = (r @ _LEVI_CIVITA).reshape(-1, 3, 3)  # -[r]x: r x u = -neg_skew u
            jac = self._jac6[:3, sl] + neg_skew @ jr  # (k, 3, ndof)
            pts.append(p_f)
            bases.append(basis.reshape(-1, 3))
            owners.append(owner + k0)
            k0 += len(p_f)
            rows.append(jac[:still].reshape(-1, jac.shape[-1]))
            nrows.append(3 * still + 2 * bool(patch_on[f]))
            rs = r[:still]
            w_old = d.cvel[body, :3]
            # w x (w' x r) = w' (w . r) - r (w . w')
            acc = (
                acc0[:3] + neg_skew[:still] @ acc0[3:] + np.outer(rs @ w, w_old) - rs * (w @ w_old)
            )
            bias.append(acc.reshape(-1))
            if patch_on[f]:  # its centre's pyramid, its corners' upward pushes
                gens.append(self._edges.T @ jac[0])
                gens.append(jac[1:, 2])
                # the foot does not roll or pitch on its patch; its yaw is free
                rows.append(jr[:2].copy())  # the buffer is the next foot's
                bias.append(acc0[3:5])
            else:  # corners: one pyramid each
                gens.append((self._edges.T @ jac).reshape(-1, jac.shape[-1]))
        if not feet:
            z = np.zeros((0, 3))
            return _Support(
                (), z, z, np.zeros(0, np.int64), np.zeros((NV, 0)), np.zeros((0, NV)), np.zeros(0)
            )
        return _Support(
            feet=tuple(feet),
            points=np.concatenate(pts),
            basis=np.concatenate(bases),
            owner=np.concatenate(owners),
            gen=np.concatenate(gens).T,
            rows=np.concatenate(rows),
            bias=np.concatenate(bias),
            nrows=tuple(nrows),
        )

    def plan(self, t: float) -> WholeBodyPlan:
        """Solve the tracking program at rollout time ``t`` for the current state (MuJoCo's
        quantities of the last step). Does not touch the simulation."""
        m, d = self.world.model, self.world.data
        qr, vr, ar, planted = self.reference(t)
        held = self._held(t)
        flat = self._flat_feet(planted, t) if self._flat_w else {}
        sl = self._dofs
        v = d.qvel[sl]
        if not (np.isfinite(d.qpos[self.wc.qpos_slice]).all() and np.isfinite(v).all()):
            raise SimulationError(f"WholeBodyTracker: the state at t = {t:.4f} s is not finite")
        # position error in qvel coordinates: world translation, local rotation vectors
        np.copyto(self._qref, d.qpos)
        self._qref[self.wc.qpos_slice] = qr
        mujoco.mj_differentiatePos(m, self._dq, 1.0, d.qpos, self._qref)
        acc_des = ar + self.kp * self._dq[sl] + self.kv * (vr - v)
        acc_des[:6] += self.root_bias

        mujoco.mj_fullM(m, d, self._full)
        big_m = self._full[sl, sl]
        # gravity and Coriolis; MuJoCo's passive joint damping is left out of the plan on
        # purpose, so it acts as extra damping (compensating it, first version: 50% of the benchmark windows
        # tracked instead of 64%)
        h = d.qfrc_bias[sl]
        sup = self._support(d, planted, held)
        nc = len(sup.points)
        qb = sup.gen
        nb = qb.shape[1]
        nj = 3 * NJ
        # unknowns: the joint accelerations y (45) and the pyramid coefficients beta (nb); the
        # pelvis follows from its Newton-Euler equation, qdd_root = r_0 + r_b beta - r_y y
        _, sol, info = dposv(big_m[:6, :6], np.column_stack([big_m[:6, 6:], qb[:6], h[:6]]))
        if info:
            raise SimulationError(f"WholeBodyTracker: singular pelvis inertia at t = {t:.4f} s")
        r_y, r_b, r_0 = sol[:, :nj], sol[:, nj:-1], -sol[:, -1]
        # the rows other than the joints': (P, target), weights folded in
        tasks: list[tuple[F64, F64]] = []
        hip = 0.0  # the hip strategy's strength (0-1)
        wj = self._wj
        if nc:
            w_trunk = self._push_response(t)
            # a balance step under way is the response: the hip strategy's rows flung the
            # swinging leg to push the body back and the foot never reached its target
            hip = self._hip_strength(t) if self.step is None else 0.0
            if hip:
                # bounded: it fades as the trunk (pelvis, waist, back) turns ``hip_tilt`` rad
                # off the mocap, so the joint rows bring it back before it folds
                turn = self._dq[sl][3:12].reshape(3, 3)
                tilt = self._hip_tilt_step if self.stepping else self._hip_tilt
                hip *= max(0.0, 1.0 - float(np.linalg.norm(turn, axis=1).sum()) / tilt)
            root_rows, root_target = self._root_rows, self._w_root * acc_des[:6]
            if hip:
                # the pelvis's turn and the trunk's joints freed: their angular momentum
                # lets the ground push the centre of mass back further than the feet's
                # centre of pressure alone could
                free = 1.0 - hip * (1.0 - self._hip_free)
                root_rows, root_target = root_rows * free, root_target * free
                wj = wj.copy()
                wj[self._hip_joints] = free
            tasks.append((root_rows, root_target))
            if w_trunk:
                # the chest's world turn as the plan's own targets turn it (pelvis, waist and
                # back together): without it the least squares spent the waist to hold the
                # pelvis, and whole clips fell after the waist had drifted ~1 rad
                mujoco.mj_jac(m, d, None, self._jacr, d.xpos[self._chest], self._chest)
                jt = self._jacr[:, sl] * w_trunk
                tasks.append((jt, jt @ acc_des))
            # the corners in contact do not move (J_c qdd + Jdot_c qdot = -k_c v_c), so the
            # planned forces are the ones MuJoCo's rigid-ish contact will produce: with only
            # the tangential rows and a soft weight, joint accelerations missed the plan by
            # 100-350 rad/s^2 in double support
            jt = sup.rows
            wc = self._landing_weights(t, sup) if self._soft else None
            if wc is None:
                tasks.append(
                    (self.sqrt_wc * jt, -self.sqrt_wc * (sup.bias + self.contact_kv * (jt @ v)))
                )
            else:
                tasks.append((wc[:, None] * jt, -wc * (sup.bias + self.contact_kv * (jt @ v))))
        # with nothing to push on, the pelvis follows momentum whatever the joints do: asking
        # the joints to steer it anyway made them whip and blew up falls (tumbling kicks)
        swing = self._swing_targets(t)
        if swing:
            # a stepping leg follows its foot's target, not the mocap's leg
            wj = wj.copy()
            for f in swing:
                wj[self._leg_rows[f]] = 0.1
            if self.step is not None and self.step_leg:
                # the stance knee bends so the pelvis can lower (``step_leg``)
                wj[self._leg_rows[1 - self.step.foot]] = 0.3
        for f, (p_d, v_d, a_d, up_d) in swing.items():
            tasks.append(self._swing_task(f, v, p_d, v_d, a_d, up_d))
        for f, up_d in flat.items():
            if f not in swing:  # the tilt rows only, at ``flat_weight``
                rows, target = self._swing_task(f, v, _ZERO3, _ZERO3, _ZERO3, up_d)
                k = np.sqrt(self._flat_w) / self.sqrt_ws
                tasks.append((k * rows[3:], k * target[3:]))
        a = acc_des[6:]
        beta = np.zeros(0)
        if not tasks:
            y = a.copy()
        else:
            # the rows P qdd - target = U y + V beta - c, with the pelvis's row of qdd from sol
            pmat = np.concatenate([task[0] for task in tasks])
            x = pmat[:, :6] @ sol
            u = pmat[:, 6:] - x[:, :nj]
            vb = x[:, nj:-1]
            c = np.concatenate([task[1] for task in tasks]) + x[:, -1]
            if hip:
                # the centre of mass's horizontal acceleration: the ground forces' sum (and
                # the push's) over the mass, rows on beta only
                w = self._w_hip * hip
                push = self._xfrc[:, :2].sum(axis=0) if self._pushing else 0.0
                u = np.concatenate([u, np.zeros((2, nj))])
                vb = np.concatenate([vb, (w / self._mass) * sup.basis[:, :2].T])
                c = np.concatenate([c, w * (self._hip_acc - push / self._mass)])
            # min |wj (y - a)|^2 + |U y + V beta - c|^2 + reg |beta|^2, beta >= 0: y eliminated
            # in closed form leaves e^T S^-1 e, e = U a + V beta - c, S = I + U D^-1 U^T
            # (a few rows instead of the QR of all 51 + r)
            ud = u / (wj * wj)
            s_mat = ud @ u.T
            s_mat.flat[:: len(u) + 1] += 1.0
            chol, info = dpotrf(s_mat, lower=1)
            e0 = u @ a - c
            # BLAS's trsm: LAPACK's trtrs went multi-threaded here and cost 1-2 ms a call on a
            # busy machine
            x = dtrsm(1.0, chol, np.column_stack([vb, e0]), lower=1)
            if info:
                raise SimulationError(f"WholeBodyTracker: singular program at t = {t:.4f} s")
            if nb:
                mt = x[:, :nb]
                scale = float(np.sqrt((mt * mt).sum(axis=0).max())) or 1.0
                reg = self.sqrt_reg
                if self._soft and 0.0 <= t - self._landed[1] < self._soft:
                    reg = self._soft_reg  # a soft touchdown: large ground forces cost more
                lhs = np.concatenate([mt, reg * scale * np.eye(nb)])
                rhs = np.zeros(len(lhs))
                rhs[: len(mt)] = -x[:, nb]
                beta = self._nnls(lhs, rhs)
                e0 = e0 + vb @ beta
            z, _ = dpotrs(chol, e0, lower=1)
            y = a - ud.T @ z
        qdd = np.empty(NV)
        qdd[6:] = y
        qdd[:6] = r_0 + r_b @ beta - r_y @ y
        tau = big_m[6:] @ qdd + h[6:] - qb[6:] @ beta
        forces = np.zeros((nc, 3))
        np.add.at(forces, sup.owner, sup.basis * beta[:, None])
        return WholeBodyPlan(
            qacc=qdd, torques=tau.reshape(NJ, 3), support=sup.feet, points=sup.points,
            forces=forces, desired_qacc=acc_des, generalized_contact=qb @ beta,
        )  # fmt: skip

    def _flat_feet(self, planted: NDArray[np.bool_], t: float) -> dict[int, F64]:
        """``flat_weight``: the planted feet on at most two sole corners whose sole is more than
        ``flat_band`` off the mocap's, with the mocap's sole normal (world, as re-anchored)."""
        assert self.path.sole_up is not None
        d = self.world.data
        i = self.clock.nearest(t)
        patch_on = self.world.foot_patch_on(self.character)
        corners = self.sole_corners()
        out: dict[int, F64] = {}
        for f in range(2):  # two feet
            if not planted[f] or patch_on[f]:
                continue
            if (corners[f, :, 2] - self.floor_z < self.touch).sum() > 2:
                continue
            up = self.path.sole_up[i, f].copy()
            up[:2] = rot2(self.anchor_yaw) @ up[:2]
            if float(d.geom_xmat[self.sole[f], 2::3] @ up) > self._flat_cos:  # its z axis
                continue
            out[f] = up
        return out

    def _toe_pitch(self) -> float:
        """The sine of the median toe-down pitch of the clip's planted (not pivoting) soles
        about their headings (0 with none)."""
        p = self.path
        assert p.sole_up is not None and p.sole_yaw is not None
        on = p.planted & ~p.pivoting
        if not on.any():
            return 0.0
        up, yaw = p.sole_up[on], p.sole_yaw[on]
        return float(np.median(up[:, 0] * np.cos(yaw) + up[:, 1] * np.sin(yaw)))

    def _landing_weights(self, t: float, sup: _Support) -> F64 | None:
        """The no-slip rows' square-root weights in the ``step_soft`` s after a balance
        step lands: the landed foot's rise linearly from a tick's share, the others'
        ``sqrt_wc`` (``None`` otherwise: all ``sqrt_wc``)."""
        f, landed = self._landed
        if f not in sup.feet or not 0.0 <= t - landed < self._soft:
            return None
        w = np.full(len(sup.rows), self.sqrt_wc)
        k = sup.feet.index(f)
        r0 = sum(sup.nrows[:k])
        w[r0 : r0 + sup.nrows[k]] *= (t - landed + self._dt_tick) / (self._soft + self._dt_tick)
        return w

    def _push_response(self, t: float) -> float:
        """Follows pushes and returns the trunk rows' weight at ``t``: while the mocap stands,
        off while an external force acts and, after one, while the capture point is more than
        ``trunk_band`` m from the mocap's; back linearly over ``trunk_give`` s after. A walk
        pushed gets the softer pelvis servo (``kp_root_pushed``)."""
        if not ((self._w_trunk and self._give) or self._w_hip or self.warp_gain
                or self._step_pushed or self.place_pushed or self.anchor_lag
                or self.step_ahead):  # fmt: skip
            return self._w_trunk
        # into a buffer: this runs every control tick
        np.take(self.world.data.xfrc_applied, self.wc.body_ids, axis=0, out=self._xfrc)
        pushing = self._pushing = bool(self._xfrc.any())
        i = self.clock.nearest(t)
        # standing: both feet planted for a balance step's time, as for balance steps (a
        # walk's double support is shorter; a walk kept its trunk rows, its figures dropped
        # where they gave in double support)
        standing = bool(self.path.planted[i : i + self._stand_frames].all())
        if pushing and not self._pushed and not standing:
            # a walk pushed: its clip follows the body's speed (``warp_gain``)
            self.warping = self.warp_gain > 0
            if self.warp_for:
                self.warp_until = t + self.warp_for
            # and a sideways push places its swing feet (``place_pushed``): placing them after
            # a diagonal one lost more front-right pushes than it caught
            heading = self.sole_heading()
            f = self._xfrc[:, :2].sum(axis=0)
            along = abs(np.cos(heading) * f[0] + np.sin(heading) * f[1])
            side = abs(np.cos(heading) * f[1] - np.sin(heading) * f[0])
            sideways = bool(along < _PLACE_SIDE_TAN * side)
            self._start_placing(self.place_pushed > 0 and sideways, t)
            # the rate follows a capture point running ahead (``warp_lead``) only after a
            # sideways push: after a diagonal one it lost more pushes than it caught
            self.leading = self.warping and self.warp_lead > 0 and sideways
            ahead = np.cos(heading) * f[0] + np.sin(heading) * f[1]
            # ``step_ahead`` only after a push within 60 deg of straight back: after a forward
            # push the clip played faster (``warp_gain``) and after a sideways one the placed
            # foot (``place_pushed``) caught what a step from double support lost
            self._ahead_armed = self.step_ahead > 0 and ahead <= -0.5 * np.hypot(f[0], f[1])
            if self._kp_root_pushed:
                # a softer pelvis servo lets its steps catch it
                kp = self._kp_root_pushed
                if self._kp_root_against and ahead < -_AGAINST_COS * np.hypot(f[0], f[1]):
                    kp = self._kp_root_against
                self.kp[:3] = kp
                self.kv[:3] = critical_kv(kp)
            self._kp_pushed = float(self.kp[0])
        if self._ahead_servo and self._ahead_armed:
            # the clip's pelvis, at the clip's speed, pulled the body on past its feet while
            # the step after the push swung
            kp = self._ahead_servo if self.step is not None else self._kp_pushed
            if self.kp[0] != kp:
                self.kp[:3] = kp
                self.kv[:3] = critical_kv(kp)
        if pushing and not self._pushed and standing and self._step_pushed:
            self.stepping = True  # a standing body pushed steps when it must
        self._pushed |= pushing
        self._standing = standing
        if not (self._w_trunk and self._give):
            return self._w_trunk
        if self._pushed and standing:
            xi, omega = self.capture_point()
            c, v, _ = self.com_reference(t)
            if pushing or np.linalg.norm(xi - c[:2] - v[:2] / omega) > self._give_band:
                self._back_from = t
        return self._w_trunk * min(1.0, max(0.0, t - self._back_from) / self._give)

    def _hip_strength(self, t: float) -> float:
        """The hip strategy (``hip_weight``) after :meth:`_push_response` at ``t``: while a
        pushed body's mocap stands and its capture point is within ``hip_margin`` m of the feet's
        edge or beyond, full (1), back to 0 linearly over ``hip_back`` s after. Sets the centre
        of mass's horizontal acceleration that brings the capture point back to the mocap's
        (critically damped at ``hip_gain`` times omega)."""
        if not (self._w_hip and self._pushed and self._standing):
            return 0.0
        feet = [f for f in self._footprint(t) if len(f)]
        if not feet:
            return 0.0
        points = np.concatenate(feet)
        xi, omega = self.capture_point()
        if outside_distance(xi, points) > -self._hip_margin:
            self._hip_from = t
        hip = 1.0 - min(1.0, (t - self._hip_from) / self._hip_back)
        if hip:
            c, v, _ = self.com_reference(t)
            goal = c[:2] + v[:2] / omega
            vel = self.world.data.subtree_linvel[self._root][:2]
            self._hip_acc[:] = omega * (self._hip_gain * omega * (goal - xi) - vel)
        return hip

    def _swing_task(
        self, f: int, v: F64, p_d: F64, v_d: F64, a_d: F64, up_d: F64 | None
    ) -> tuple[F64, F64]:
        """The rows of foot ``f`` swinging to a target (see :meth:`plan`): a swinging foot goes
        where balance needs it (the mocap's landing moved by the capture point's error, or a
        balance step), level with the floor."""
        m, d = self.world.model, self.world.data
        sl = self._dofs
        body = int(self.feet[f])
        rot = d.geom_xmat[self.sole[f]].reshape(3, 3)
        point = d.geom_xpos[self.sole[f]] - rot[:, 2] * self._sole_half[f]
        mujoco.mj_jac(m, d, self._jacp, self._jacr, point, body)
        mujoco.mj_jacDot(m, d, self._jacd, self._jacrd, point, body)
        jf = np.concatenate([self._jacp[:, sl], self._jacr[:2, sl]])
        jdv = np.concatenate([self._jacd[:, sl] @ v, self._jacrd[:2, sl] @ v])
        vel = jf @ v
        want = np.r_[
            a_d + self.kp_swing * (p_d - point) + self.kv_swing * (v_d - vel[:3]),
            self.kp_swing * np.cross(rot[:, 2], up_d if up_d is not None else rot[:, 2])[:2]
            - self.kv_swing * vel[3:],
        ]
        # bounded: an out-of-reach target must not whip the leg
        want[:3] *= min(1.0, _SWING_ACC / max(float(np.linalg.norm(want[:3])), 1e-9))
        want[3:] *= min(1.0, _SWING_ACC / max(float(np.linalg.norm(want[3:])), 1e-9))
        if up_d is None:  # a placement: where the foot lands, not how it swings
            jf, jdv, want = jf[:2], jdv[:2], want[:2]
        return self.sqrt_ws * jf, self.sqrt_ws * (want - jdv)

    def _nnls(self, a: F64, b: F64) -> F64:
        """``argmin |a x - b|, x >= 0``: first the last solution's free set as a plain least
        squares, kept when it is optimal (its coefficients positive, no other one's gradient
        pointing in; between contact changes it mostly is), else scipy's NNLS."""
        n = a.shape[1]
        free = self._free
        if len(free) == n and free.any():
            af = a[:, free]
            _, xf, info = dposv(af.T @ af, af.T @ b[:, None])
            if not info and (xf > 0).all():
                x = np.zeros(n)
                x[free] = xf[:, 0]
                grad = a.T @ (b - a @ x)
                if (grad[~free] <= 1e-10).all():  # no bound coefficient would lower it
                    return x
        x = nnls(a, b, maxiter=50 * n)[0]
        self._free = x > 0
        return x

    def scale_gains(self, scale: float) -> None:
        """The tracking gains (joints and pelvis; not the pelvis and legs once
        ``hold_balance`` holds them) times ``scale``, damping times its root."""
        self._scale = float(scale)
        self.kp[:] = self._kp0 * scale
        self.kv[:] = self._kv0 * np.sqrt(scale)
        if self._holding:
            r = self._stance_rows
            self.kp[r], self.kv[r] = self._kp0[r], self._kv0[r]

    def stiffen_joints(self, factor: float) -> None:
        """The joints' stiffness as built times ``factor`` (damping times its root) from the
        next tick, under any :meth:`scale_gains`; the pelvis rows keep theirs. The response's
        physical mode stiffens a hit body from the match on, so that it settles onto the found
        clip's pose before drifting off it (``docs/benchmarks.md``); :meth:`reset` undoes it."""
        if not (np.isfinite(factor) and factor > 0.0):
            raise ConfigError(f"stiffen_joints: factor must be > 0, got {factor!r}")
        ratio = float(factor) / self._stiffness
        self._stiffness = float(factor)
        self._kp0[6:] *= ratio
        self._kv0[6:] *= np.sqrt(ratio)
        self.scale_gains(self._scale)

    def _check_balance(self, t: float) -> None:
        """``hold_balance``: hold the pelvis and leg rows once the simulated capture point is
        outside the feet on the floor."""
        feet = [f for f in self._footprint(t) if len(f)]
        if not feet:
            return
        xi, _ = self.capture_point()
        if outside_distance(xi, np.concatenate(feet)) > 0.0:
            self._holding = True
            self.scale_gains(self._scale)

    def memory(self) -> tuple[object, ...]:
        return (*super().memory(), self._hip_from, self._pushed, self._back_from,
                self.kp[:3].copy(), self.kv[:3].copy(), self._holding, self._scale)  # fmt: skip

    def restore(self, memory: tuple[object, ...]) -> None:
        super().restore(memory[:-7])
        self._hip_from = float(memory[-7])  # type: ignore[arg-type]
        self._pushed = bool(memory[-6])
        self._back_from = float(memory[-5])  # type: ignore[arg-type]
        self.kp[:3], self.kv[:3] = memory[-4], memory[-3]
        self._holding, self._scale = bool(memory[-2]), float(memory[-1])  # type: ignore[arg-type]

    def reset(self, world: World) -> None:
        self.reset_ground(world)
        self._pushed, self._back_from, self._hip_from = False, -np.inf, -np.inf
        self._holding = False
        if self._stiffness != 1.0:
            self.stiffen_joints(1.0)
        if self._kp_root_pushed:  # the pelvis servo as built
            self.kp[:3], self.kv[:3] = self._kp0[:3], self._kv0[:3]
        servo = world.servo
        servo.enable(self.character, on=True)
        servo.set_gains(0.0, self.servo_kv, self.character)
        servo.refresh_every = self.control_every

    def control(self, world: World, t: float) -> None:
        d = world.data
        if not (np.isfinite(d.qpos).all() and np.isfinite(d.qvel).all()):
            # diverged between the engine's checks: it reports that at its next check (a
            # result, not an exception)
            self._ff[:] = 0.0
            return
        i = self.clock.nearest(t)
        patch = self._lock_pivoting[i]
        for f in range(2):
            world.set_foot_patch(self.character, f, bool(patch[f]))
        self.update_ground(t)
        if self._hold_balance and not self._holding:
            self._check_balance(t)
        plan = self.plan(t)
        self.last_plan = plan
        # the servo (damping only by default) keeps acting between ticks; at the tick the
        # total joint torque is the plan's (within ``torque_limit``)
        self._ff[:] = plan.torques
        if self.torque_limit > 0:  # each joint's torque scaled down to the limit, in place
            scale = np.linalg.norm(self._ff, axis=1, keepdims=True)
            np.divide(self.torque_limit, np.maximum(scale, 1e-12, out=scale), out=scale)
            self._ff *= np.minimum(scale, 1.0, out=scale)
        self._ff -= self.servo.torques(self.character)
