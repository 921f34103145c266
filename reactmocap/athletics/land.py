"""Landing (thesis ch. 6), a passive landing: in the air a foot-placement servo adds an offset to
the hips (eq. 6.1) that puts the feet where the horizontal velocity will be gone when the COM
is over them (the desired place: a velocity-proportional lead plus the foot-servo delta,
interpolated over the horizontal velocity as in Table 6.1), the knees bend ready and the ankles
keep the feet flat. At touchdown the knees' stiffness goes to zero and their damping up; once
they have slowed to 20% of their touchdown speed the stiffness comes back, and the balance
controller takes over when the COM passes over the feet, stops near them or starts to move
away."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from reactmocap.athletics.balance import (
    BALANCE_GAINS,
    BalanceLaw,
    Posture,
    Step,
    Stepper,
    hips_for_thighs,
    hold_pelvis_and_feet,
    knee_for_length,
)
from reactmocap.athletics.leap import pitch_momentum
from reactmocap.athletics.machine import NEXT, Basis, Context, law, touchdown
from reactmocap.athletics.rig import joint_index, per_joint
from reactmocap.athletics.tumble import time_to_height
from reactmocap.errors import ConfigError
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.controllers.machine import State, after
from reactmocap.sim.world import World

__all__ = ["LANDING_STIFFNESS", "Landing", "LandingParams"]

NJ = len(BALL_JOINTS)
_HIP = [joint_index(f"{s}_hip") for s in "lr"]
_KNEE = [joint_index(f"{s}_knee") for s in "lr"]
_ANKLE = [joint_index(f"{s}_ankle") for s in "lr"]
_SHOULDER = [joint_index(f"{s}_shoulder") for s in "lr"]
#: the most the arms spread out to the sides (shoulder roll, rad) against a twist (twist_arms)
ARMS_SPREAD = 1.4
#: stiffness while reaching for the ground (units of m g L N m/rad)
LANDING_STIFFNESS = {
    "waist": 3.0, "back": 3.0, "neck": 0.3, "shoulder": 0.3, "elbow": 0.15, "wrist": 0.05,
    "hip": 1.5, "knee": 0.3, "ankle": 0.3,
}  # fmt: skip
#: joint damping while absorbing (units of m L sqrt(g L) N m s/rad; knees: see LandingParams)
ABSORB_DAMPING = {"waist": 0.1, "back": 0.1, "hip": 0.05, "ankle": 0.05}
#: lowest hip-to-ankle length (fraction of the leg) the absorption plans to stop by
DEEPEST_LEG = 0.55
#: most ground force (body weights) the absorption asks for
MAX_SUPPORT = 6.0
#: fraction of the crouch left at touchdown that the planned stop uses
PLAN_ROOM = 0.7

#: knee flexion (rad) below which a knee switched off while absorbing is servoed again, the
#: flexion it is driven to, and how stiffly (m g L N m/rad). Why: a knee is a hinge with an
#: extension stop, but our ball joint's cone lets a passive, nearly straight knee (a short
#: flight leaves no time to bend it) buckle backwards under the landing's push (seen to
#: -1.5 rad; the servo's return then launched the body). A soft stop: at the balance's 3.0 the
#: example broad-jump maneuver's landing fell.
KNEE_STOP = 0.0
KNEE_GUARD = 0.2
KNEE_GUARD_STIFFNESS = 1.0
#: a foot within this height (m) of the floor after touchdown carries weight
STANCE_REACH = 0.02


@dataclass(frozen=True)
class LandingParams:
    """Landing parameters.

    Args:
        knee: knee flexion held in the air (rad).
        kp, kv: foot-placement servo gains (rad/m, rad s/m) on the hips.
        lead: how far ahead of the COM the feet go, in units of the capture point's lead
            (the horizontal velocity times ``sqrt(z / g)``).
        delta: foot-servo delta (m) added to the desired foot place (from the table).
        damping: knee damping after touchdown as a vertical damper on the hips (units of
            m sqrt(g / L) N s/m; turned into the knee's damping through the leg's lever,
            ``d(hip-ankle length) / d(knee angle)``, each tick).
        restore: fraction of the touchdown knee speed below which the knee stiffness returns.
        arms: shoulder pitch held in the air (rad).
        knee_stiffness: knee stiffness while absorbing (units of m g L N m/rad); 0 is the
            thesis's knee with its stiffness off; more makes the knees follow the planned
            crouch.
        lean: torso pitch per radian of knee flexion while absorbing (see ``Posture``).
        toes: ankle plantar flexion held in the air (rad): the forefoot lands first and the
            foot rolls flat under load, as people land (the thesis lands flat-footed).
        deltas: the foot-servo delta per horizontal velocity, ``((v m/s, delta m), ...)``
            (thesis Table 6.1), interpolated on the velocity sensed in the air, so that a
            landing after a broad jump gets its own speed's delta; empty: ``delta`` at every
            speed.
        pitch_ease: seconds over which the absorption's pelvis pitch goes from where it was
            at touchdown to the upright (``lean``) target; 0: the target at once. A broad
            jump lands with the trunk pitched far forward, and righting it at once drove the
            hips' extension into the floor and threw the body back up.
        swing_cap: the most the placement swings a leg from under its hip, as the sine of the
            swing (the foot at most ``swing_cap`` leg lengths ahead of or behind the hip). A fast
            backward landing (the female back handspring) needs the feet farther behind
            than the default allows.
        aim_sideways: the hips' roll (the legs' sideways aim) from the pelvis's whole
            orientation (pitch, roll and yaw), so the pair of feet lands under the sideways
            capture point (the eq. 6.1 servo stays on top as a correction); the hips' pitch is
            as without it. Off (the default), the roll is the servo alone, with the pelvis's
            own roll not taken out: a back tuck from a perturbed start touched down with the
            pelvis rolled up to 16 degrees, the feet up to 7 cm to the side of the COM and
            6-8 cm apart fore-aft, and stood on one foot after the landing.
        spin_aim: the reach for a body still turning (a somersault's landing): the legs are
            aimed in the heading of the pelvis's left-right axis (``Senses.side_heading``;
            the pelvis's forward axis, the default's heading, flips by half a turn as the
            body passes the horizontal, which mirrored the placement in mid-reach), and the
            hips' target is led by the servo's lag (``Rig.lag``) times the pelvis's pitch
            rate (the target turns with the body, and the servo trailed it by 20-40
            degrees: the male back tuck's legs were still swinging forward at 3-5 m/s when
            the feet touched, and a few ms of that decided where they landed). The legs hold
            their aim in the world and the feet arrive still under the COM. Off (the
            default): as before.
        twist_aim: with ``aim_sideways``, the hips' roll from where the pelvis will be once
            the hips get there (its whole angular velocity times the servo's lag,
            ``Rig.lag``), not where it is. Why: a take-off's few kg m^2/s of cartwheel
            momentum becomes a twist about the long axis as the opening body passes the
            horizontal, where its inertia is least; the female back tuck's pelvis rolled at
            ~4 rad/s through the reach and her feet touched down 10-17 cm to the side of the
            COM, and she stood up on one foot and fell sideways. Off (the default): as before.
        fall_gain: how much nearer (m) the feet go per m/s of horizontal speed and per metre
            that the fall exceeds ``fall_ref`` (s/m); 0: off (the deltas hold for one drop
            height only). The fall is predicted as the reach begins: the soles' clearance
            plus the rise still to come, ``vz^2 / (2 g)`` if rising (the COM's apex less its
            height over the soles, so a backpack's higher COM does not read as a longer
            fall); it sets the touchdown's vertical speed. Why: a harder touchdown makes a
            larger landing force, whose horizontal part along the leg takes the horizontal
            speed off sooner, so the feet must land nearer the COM (the female at 2.5 m/s:
            the window of deltas that land moved from -0.47 m to -0.52 and -0.57 m with the
            COM 1.15, 1.25, 1.35 m up).
        fall_ref: the fall (m) the deltas were measured at (``fall_gain``'s zero).
        momentum_gain: how much farther ahead (m) the feet go per kg m^2/s of whole-body
            pitch momentum (> 0 pitching forward, :func:`~reactmocap.athletics.leap.pitch_momentum`,
            constant in the air) over ``momentum_ref``; 0: off. Why: the ground force must
            also stop the body's rotation, and a force under feet behind the COM pitches the
            body forward, so a body turning back needs its feet farther back (the female's
            "com" leaps lift off with -1.1 to +1.6 kg m^2/s: at 0.75 m, +1.6, she landed only
            with the feet 3-5 cm ahead of where her 0.7 and 0.8 m leaps, +0.4 / +0.9, land).
        momentum_ref: the pitch momentum (kg m^2/s) the deltas were measured at.
        momentum_side: ``momentum_gain``'s momentum taken about the pelvis's left-right axis
            when the reach begins (as ``spin_ref``'s), not about the heading's pitch axis each
            tick. Why: the heading flips by half a turn as an inverted body passes the
            horizontal; a somersault's weak take-off (the female back tuck's under 22 of her
            usual 23 kg m^2/s) landed with the feet placed for the usual spin, 2 cm too far
            behind the COM, and fell forward (docs/athletics.md).
        side_lead: the sideways placement's lead (0-2, units of the capture point's);
            ``None``: ``lead``. Why: ``lead`` is tuned with the forward delta, which has no
            sideways counterpart; a perturbed broad jump touching down with 0.2-0.7 m/s
            sideways stood up on one foot and fell sideways (docs/athletics.md).
        twist_arms: the arms spread against a twist in the reach: both shoulders roll out
            to the sides by this much (rad) per unit (m L^2 rad/s) of the whole-body angular
            momentum about the pelvis's long axis, measured each tick, at most
            :data:`ARMS_SPREAD`; 0: off (the arms as ``arms``). Why: the opened body's
            inertia about its long axis is least (female 0.82 kg m^2 with the arms forward,
            1.74 with them out), and the 2-4 kg m^2/s about it that the tuck opens with (a
            take-off's cartwheel and yaw momentum) twisted the female back tuck's reach at up
            to 7 rad/s: 40-120 degrees by touchdown, on one foot first (docs/athletics.md).
        stance_push: while absorbing, the legs push along the line from the feet that carry
            the weight (their shares) to the COM, not from the middle of both feet; off (the
            default): from the middle. Why: a foot that lands first, or a pair of feet to one
            side of the COM, tilted the line, and up to 6 body weights along it threw the
            COM sideways off the foot under it.
        spin_ref: the delta is scaled by the whole-body angular momentum about the pelvis's
            left-right axis when the reach begins (constant in the air) over this (kg m^2/s,
            the spin the delta was tuned at, backward < 0); 0: off. Why: feet placed behind
            the COM stop the spin by the ground force's moment, whose arm grows with their
            distance, so a landing that must stop more spin puts them farther; the male back
            handspring's landing lands only within about 6 kg m^2/s of its -95 (a
            perturbed push leaves -69 to -116; docs/athletics.md). Measured about the
            left-right axis because the pelvis's heading flips as an inverted body turns.
        step: a step when the capture point leaves the feet as the landing stands up
            (``[margin, reach, lift, seconds]``, any leading part, :class:`~reactmocap.athletics.balance.Step`;
            empty: off): from the recovery on, carried on by the balance that follows. Why:
            the male back handspring's perturbed landings that fall are decided in the first
            0.15 s on the feet by how far the capture point lies past them, which no
            placement of the feet tried reached (docs/athletics.md).
        roll_ease: seconds over which the pelvis's roll (sideways tilt) target goes from
            where it was at touchdown to upright, through the absorption and the recovery
            (which hands over no sooner); 0: upright at once (the default). Why: a forward
            tuck touching down with the pelvis rolled 20-30 degrees (its legs aimed under the
            COM, ``aim_sideways``) had the hips right the trunk within ~0.1 s, and the
            reaction on the legs lifted one foot: it stood up on the other, which pivoted, and
            turned about the vertical and fell (docs/athletics.md).
        roll_min: ``roll_ease`` only for a touchdown roll of at least this (rad); a smaller
            one is righted at once, as without it. Why: the ease changed the fate of landings
            touching down nearly level too, both ways (the forward tuck's 2 kg backpack
            lands rolled 25 degrees, and lands only righted at once).
        turn_gain: how much farther ahead (m) the feet go per radian that the somersault
            rotation predicted at touchdown lies past ``turn_ref`` (> 0: forward; the rotation
            now plus its rate, measured over the last control tick, times the time the COM
            takes to fall by the soles' clearance), updated each tick in the reach's last
            ``turn_window`` seconds; 0: off. Why: the male back layout's touchdown spreads
            over -297..-308 degrees with the opening's 4 ms tick (one tick moves it 3-5
            degrees, the window that lands is 4-5 wide): touching down less turned the
            ground stopped the spin too hard and it fell forward, more turned it went on
            backward; 100 ms before touchdown the rotation already differs by its final
            amount (docs/athletics.md).
        turn_ref: the touchdown rotation (rad, backward < 0) at which ``turn_gain`` moves
            nothing.
        turn_window: the predicted time to touchdown (s) below which ``turn_gain`` acts (the
            prediction, a straight line, runs ahead of the reach's slowing turn before).
        late_delta: ``(seconds, offset m, delta m)``: ``seconds`` into the reach, if the feet's
            horizontal distance from the COM exceeds ``offset``, the foot-servo delta is
            ``delta`` for the rest of the landing (instead of ``delta`` / ``deltas``); empty:
            off. Why: on the male back layout the starts that touch down too little turned
            (-296..-301.5 deg) have their feet already well past the COM early in the reach
            (it opened a tick late in the legs' swing: 0.21-0.35 m 24 ms in, against at most
            0.085 on the others), and they land with the feet farther ahead from the reach's
            start, which the others do not (docs/athletics.md).
        recover_spin: the recovery also hands over to the balance once the whole-body pitch
            momentum (:func:`~reactmocap.athletics.leap.pitch_momentum`, > 0 forward) exceeds
            this (kg m^2/s); 0: off (it hands over when the COM stops near its target or moves
            away from it). Why: a male back layout standing over its feet but still turning
            forward (+8..+10 kg m^2/s, the COM creeping on at 0.02-0.11 m/s) met neither, stayed
            in the recovery 0.5 s and fell forward; the balance takes such momentum down
            (docs/athletics.md).
        carry_pitch: the balance after the landing starts its pelvis pitch target from the
            recovery's last target (its lean eased from there), not from the pelvis's pitch;
            off: the target drops to the pelvis's pitch at the hand-over (0.44 rad on a male
            back layout with ``lean`` 0.8).
        late_kv: the placement servo's ``kv`` for the rest of the reach once ``late_delta``
            has found a late start (its decision needs ``late_delta``); ``None``: ``kv``.
            Why: on the male back layout the late class's feet trail their target by ~10 cm
            at touchdown with the servo at its clip, the ``kv`` term braking the legs' swing
            (the landers' by ~1 cm); a lower ``kv`` on every start moves the landers' feet
            past their ~1 cm windows too (docs/athletics.md, "late_kv").
        late_kv_margin: ``(from m, to m)``: ``late_kv`` scaled by how far past ``late_delta``'s
            offset the feet are at its decision: ``kv`` up to ``from`` past it, ``late_kv``
            from ``to`` on, blended linearly between (``from == to``: a step); empty:
            ``late_kv`` on every late start. Why: on the male back layout a tenth's late
            starts (0.09 m past) land with ``kv`` and fall with ``late_kv`` 0, full size's
            (0.13-0.31 m past) the other way round (docs/athletics.md, "late_kv_margin").
        late_kv_rotation: ``late_kv`` only for a late start whose somersault rotation at
            ``late_delta``'s decision is at least this far along (rad, signed like the
            rotation: a backward somersault's is negative); the others keep ``kv``. ``None``:
            every late start. Why: on the male back layout the late starts that land only
            with ``kv`` have turned -3.03..-3.08 rad by then, those that land only with
            ``late_kv`` 0 -3.09..-3.29, where the feet's distance does not sort them
            (docs/athletics.md, "late_kv_rotation").
        step_across, step_ground, step_down_after: the ``step``'s
            :class:`~reactmocap.athletics.balance.Step` ``across``, ``ground`` and
            ``down_after`` (0: off, their defaults; only with ``step``). Why:
            on the male back handspring 13 of 19 full-size failures that reach the feet had
            a step's swing run its whole 0.75 s without the foot down (docs/athletics.md,
            "the step put down").
        step_foresee: the ``step``'s :class:`~reactmocap.athletics.balance.Step` ``foresee``
            (s, 0: off; only with ``step_across``). Why: on the male back handspring the
            class-S fallers tipped out sideways over one foot after the closing step; with
            ``step_across`` 0.05 and ``step_foresee`` 0.25 the three seeds land 106 of 150
            from 94, none lost (docs/athletics.md, "class S ... across/foresee").
        step_knees: the ``step``'s :class:`~reactmocap.athletics.balance.Step` ``knees``
            (a share in [0, 1], 0: off; only with ``step``). Why: on the male back handspring
            the starts that stood on both feet after the two landing steps kept each stepped
            knee at its swing's last target, 0.17-0.19 rad apart; the pelvis rolled 15-20 deg
            and the COM drifted out over the more bent leg until it fell (docs/athletics.md,
            "kind (c)"; the share of the way to the two knees' mean).
        step_hang_plant: the ``step``'s :class:`~reactmocap.athletics.balance.Step`
            ``hang_plant`` (s, 0: off; only with ``step``). Why: on the male back handspring
            starts stood 1-2 s on one foot after the landing, the other hung, and fell when a
            later step's swing never came down (docs/athletics.md, "the last falling starts").
        recover_leg: the recovery stands up to at least this fraction of the straight leg
            (0: off, to where the legs are, at least half; else in [0.5, 1]). Why: on the male
            back handspring the fallers stood on one knee bent 1.6-1.7 rad with the COM at
            0.71-0.78 m, sinking (docs/athletics.md, "the one-leg stand-up").
        recover_min: the recovery's shortest time (s, [0.05, 1]) before it may hand over to
            the balance while a foot is off the floor; on both feet, and at the default 0.05,
            the code's 0.05. Why: the forward tuck's file with a 4 kg backpack bounced off both
            feet 12 ms into the recovery, was handed over at 0.052 s on one foot and fell; a
            minimum on both feet too moved most perturbed starts' landings and lost some
            (docs/athletics.md, "Forward tuck: the file's 4 kg backpack landed").
        absorb_spin: ``(gate, wait)``: the absorb does not hand over to the recovery while
            the whole body's angular momentum about the pelvis's side axis is below ``gate``
            (kg m^2/s, < 0: the back somersault's sense) until ``wait`` s (0, 1] after
            touchdown; () off. Why: on the male back handspring every start that stepped
            forward out of the recovery entered it at -27..-36 kg m^2/s, the others at
            +2.7..+8.3 (docs/athletics.md, "the absorb's hand-over held").
        hop_spin: ``(ref, gain)``: if the recovery's kick lifts the feet off (a hop), the
            feet of its second touchdown go ``gain * (spin - ref)`` m farther ahead (the hips'
            pitch, on top of the balance law's), the spin (kg m^2/s, about the pelvis's side
            axis) read once as the feet leave, as ``momentum_gain`` places the reach's; the
            recovery hands over only with a foot down; () off. Why: the female back
            handspring's hop lands only if it leaves with -8.5..-2.8 kg m^2/s; with more the
            feet came down ahead of the COM, with less behind it (docs/athletics.md).
        held_hip_share: once ``absorb_spin``'s gate has held a hand-over (the knees had slowed
            to ``restore`` with the body's momentum still below the gate), the share in [0, 1]
            of the balance's COM-servo hip pitch offset (its ``0.5 delta``) kept in the
            recovery and the balance after the landing; 1: off. Why: on the male back
            handspring the held starts that fell stood on one foot while that offset flexed
            the hip up to its limit and pitched the pelvis forward past its target
            (docs/athletics.md, "the balance's hip offset zeroed after a held absorb").
    """

    knee: float = 0.6
    kp: float = 1.5
    kv: float = 0.15
    lead: float = 0.75
    delta: float = -0.04
    damping: float = 1.0
    restore: float = 0.2
    arms: float = -0.6
    toes: float = 0.0
    lean: float = 0.5
    knee_stiffness: float = 0.0
    deltas: tuple[tuple[float, float], ...] = ()
    pitch_ease: float = 0.0
    swing_cap: float = 0.9
    aim_sideways: bool = False
    spin_aim: bool = False
    twist_aim: bool = False
    fall_gain: float = 0.0
    fall_ref: float = 0.0
    momentum_gain: float = 0.0
    momentum_ref: float = 0.0
    momentum_side: bool = False
    side_lead: float | None = None
    spin_ref: float = 0.0
    twist_arms: float = 0.0
    stance_push: bool = False
    step: tuple[float, ...] = ()
    roll_ease: float = 0.0
    roll_min: float = 0.0
    turn_gain: float = 0.0
    turn_ref: float = 0.0
    turn_window: float = 0.1
    late_delta: tuple[float, ...] = ()
    recover_spin: float = 0.0
    carry_pitch: bool = False
    late_kv: float | None = None
    late_kv_margin: tuple[float, ...] = ()
    late_kv_rotation: float | None = None
    step_across: float = 0.0
    step_ground: float = 0.0
    step_down_after: float = 0.0
    step_foresee: float = 0.0
    recover_leg: float = 0.0
    step_knees: float = 0.0
    step_hang_plant: float = 0.0
    recover_min: float = 0.05
    absorb_spin: tuple[float, ...] = ()
    hop_spin: tuple[float, ...] = ()
    held_hip_share: float = 1.0

    def __post_init__(self) -> None:
        self.balance_step()  # checked here (ConfigError) though built per run
        for name in (
            "knee",
            "kp",
            "kv",
            "lead",
            "delta",
            "damping",
            "restore",
            "arms",
            "toes",
            "lean",
            "knee_stiffness",
            "pitch_ease",
            "fall_gain",
            "fall_ref",
            "momentum_gain",
            "momentum_ref",
            "spin_ref",
            "twist_arms",
            "roll_ease",
            "roll_min",
            "turn_gain",
            "turn_ref",
            "recover_spin",
        ):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ConfigError(f"landing {name} must be a finite number, got {v!r}")
        if not 0.0 <= self.twist_arms <= 100.0:
            raise ConfigError(f"landing twist_arms must be in [0, 100] rad, got {self.twist_arms}")
        if self.side_lead is not None and not (
            isinstance(self.side_lead, (int, float)) and 0.0 <= self.side_lead <= 2.0
        ):
            raise ConfigError(f"landing side_lead must be in [0, 2], got {self.side_lead!r}")
        if self.pitch_ease < 0:
            raise ConfigError(f"landing pitch_ease must be >= 0 s, got {self.pitch_ease}")
        if not 0.0 <= self.roll_ease <= 0.9:  # the recovery hands over within 1 s anyway
            raise ConfigError(f"landing roll_ease must be in [0, 0.9] s, got {self.roll_ease}")
        r = self.recover_leg
        if not (isinstance(r, (int, float)) and (r == 0.0 or 0.5 <= r <= 1.0)):
            raise ConfigError(f"landing recover_leg must be 0 or in [0.5, 1], got {r!r}")
        m = self.recover_min
        if not (isinstance(m, (int, float)) and 0.05 <= m <= 1.0):  # after(1.0) ends it anyway
            raise ConfigError(f"landing recover_min must be in [0.05, 1] s, got {m!r}")
        a = self.absorb_spin
        if a and not (
            len(a) == 2
            and all(isinstance(x, (int, float)) and math.isfinite(x) for x in a)
            and -200.0 <= a[0] < 0.0
            and 0.0 < a[1] <= 1.0  # the absorb's after(1.0) ends it anyway
        ):
            raise ConfigError(
                "landing absorb_spin must be (gate in [-200, 0) kg m^2/s, wait in (0, 1] s), "
                f"got {a!r}"
            )
        h = self.hop_spin
        if h and not (
            len(h) == 2
            and all(isinstance(x, (int, float)) and math.isfinite(x) for x in h)
            and -100.0 <= h[0] <= 100.0
            and -0.1 <= h[1] <= 0.1
        ):
            raise ConfigError(
                "landing hop_spin must be (ref in [-100, 100] kg m^2/s, gain in [-0.1, 0.1] "
                f"m per kg m^2/s), got {h!r}"
            )
        hs = self.held_hip_share
        if not (isinstance(hs, (int, float)) and 0.0 <= hs <= 1.0):
            raise ConfigError(f"landing held_hip_share must be in [0, 1], got {hs!r}")
        if hs < 1.0 and not a:
            raise ConfigError(
                "landing held_hip_share needs absorb_spin (it acts on its held starts)"
            )
        if not 0.0 < self.turn_window <= 1.0:
            raise ConfigError(f"landing turn_window must be in (0, 1] s, got {self.turn_window!r}")
        if self.late_delta and not (
            len(self.late_delta) == 3
            and all(isinstance(x, (int, float)) and math.isfinite(x) for x in self.late_delta)
            and 0.0 <= self.late_delta[0] <= 1.0
            and self.late_delta[1] > 0.0
        ):
            raise ConfigError(
                "landing late_delta must be (seconds in [0, 1], offset > 0 m, delta m), "
                f"got {self.late_delta!r}"
            )
        if not isinstance(self.carry_pitch, bool):
            raise ConfigError(
                f"landing carry_pitch must be true or false, got {self.carry_pitch!r}"
            )
        if self.late_kv is not None and not (
            isinstance(self.late_kv, (int, float)) and 0.0 <= self.late_kv <= 1.0
        ):
            raise ConfigError(f"landing late_kv must be in [0, 1] rad s/m, got {self.late_kv!r}")
        if self.late_kv is not None and not self.late_delta:
            raise ConfigError("landing late_kv needs late_delta (it acts on its late class)")
        if self.late_kv_margin and not (
            len(self.late_kv_margin) == 2
            and all(isinstance(x, (int, float)) for x in self.late_kv_margin)
            and 0.0 <= self.late_kv_margin[0] <= self.late_kv_margin[1] <= 1.0
        ):
            raise ConfigError(
                "landing late_kv_margin must be (from, to) m with 0 <= from <= to <= 1, "
                f"got {self.late_kv_margin!r}"
            )
        if self.late_kv_margin and self.late_kv is None:
            raise ConfigError("landing late_kv_margin needs late_kv (it scales it)")
        if self.late_kv_rotation is not None and not (
            isinstance(self.late_kv_rotation, (int, float))
            and math.isfinite(self.late_kv_rotation)
            and self.late_kv_rotation != 0.0
        ):
            raise ConfigError(
                f"landing late_kv_rotation must be a nonzero rotation (rad), "
                f"got {self.late_kv_rotation!r}"
            )
        if self.late_kv_rotation is not None and self.late_kv is None:
            raise ConfigError("landing late_kv_rotation needs late_kv (it gates it)")
        if self.recover_spin < 0:
            raise ConfigError(f"landing recover_spin must be >= 0, got {self.recover_spin}")
        if not 0.0 <= self.roll_min <= 0.5 * math.pi:
            raise ConfigError(f"landing roll_min must be in [0, pi/2] rad, got {self.roll_min}")
        if not (isinstance(self.swing_cap, (int, float)) and 0.0 < self.swing_cap < 1.0):
            raise ConfigError(f"landing swing_cap must be in (0, 1), got {self.swing_cap!r}")
        for row in self.deltas:
            if len(row) != 2 or not all(
                isinstance(x, (int, float)) and math.isfinite(x) for x in row
            ):
                raise ConfigError(f"landing deltas rows must be two finite numbers, got {row!r}")

    @cached_property
    def _delta_table(self) -> tuple[np.ndarray, np.ndarray]:
        # sorted once: the lookup runs every control tick in the air
        v, d = np.array(sorted(self.deltas), dtype=float).T
        return v, d

    def delta_at(self, velocity: float) -> float:
        """The foot-servo delta (m) for a horizontal velocity (m/s): the table's, else ``delta``."""
        if not self.deltas:
            return self.delta
        v, d = self._delta_table
        return float(np.interp(velocity, v, d))

    def late_kv_at(self, past: float, rotation: float = 0.0) -> float:
        """The placement servo's ``kv`` for a late start whose feet are ``past`` m beyond
        ``late_delta``'s offset and whose somersault has turned ``rotation`` rad at its
        decision (``late_kv``, gated by ``late_kv_rotation``, scaled by ``late_kv_margin``)."""
        if self.late_kv is None:
            return self.kv
        r = self.late_kv_rotation
        if r is not None and math.copysign(1.0, r) * (rotation - r) < 0.0:
            return self.kv
        if not self.late_kv_margin or past >= self.late_kv_margin[1]:
            return self.late_kv
        lo, hi = self.late_kv_margin
        w = max(past - lo, 0.0) / (hi - lo) if hi > lo else 0.0
        return self.kv + w * (self.late_kv - self.kv)

    def balance_step(self) -> Step | None:
        """The landing's :class:`~reactmocap.athletics.balance.Step` (``step`` and the
        ``step_*`` fields), or None (off)."""
        step = Step.of(self.step)
        more = {"across": self.step_across, "ground": self.step_ground,
                "down_after": self.step_down_after, "foresee": self.step_foresee,
                "knees": self.step_knees, "hang_plant": self.step_hang_plant}  # fmt: skip
        if step is None:
            if any(v != getattr(Step, k) for k, v in more.items()):
                raise ConfigError("landing step_across, step_ground, step_down_after, "
                                  "step_foresee, step_knees and step_hang_plant need a step")  # fmt: skip
            return None
        try:
            return replace(step, **more)
        except ConfigError as e:  # named as the landing's field
            raise ConfigError(f"landing step_{str(e).removeprefix('step ')}") from e


class Landing(Basis):
    """The landing basis controller; hands over to balance once the landing has settled."""

    name = "land"
    initial = "reach"

    def __init__(self, params: LandingParams | None = None) -> None:
        self.params = params or LandingParams()

    def states(self, ctx: Context) -> list[State]:
        p = self.params
        every = ctx.control_every
        rig = ctx.rig
        bl = BalanceLaw(ctx, BALANCE_GAINS)
        memo: dict[str, float] = {}
        guard = np.zeros(2, dtype=bool)  # knees held out of hyperextension (knee_stop)
        step = p.balance_step()
        if step is not None:
            bl.stepper = Stepper(ctx, step)
        m = ctx.world.model
        pre = rig.wc.prefix
        hip_joints = [m.joint(f"{pre}{s}_hip").id for s in "lr"]
        ankle_joints = [m.joint(f"{pre}{s}_ankle").id for s in "lr"]

        def reach_enter(world: World, t: float) -> None:
            rig.set_stiffness(per_joint(LANDING_STIFFNESS))
            rig.set_damping(per_joint({"knee": 0.1, "hip": 0.1, "ankle": 0.05}))
            rig.support[:] = 0.0
            goal = np.full((NJ, 3), np.nan)
            for s in "lr":
                goal[joint_index(f"{s}_knee")] = (p.knee, 0.0, 0.0)
                goal[joint_index(f"{s}_shoulder")] = (p.arms, 0.0, 0.0)
            for j in ("waist", "back", "neck"):
                goal[joint_index(j)] = 0.0
            moving = [j for j in range(NJ) if not np.isnan(goal[j]).all()]
            rig.move(goal, 0.2, t, moving)
            memo["lag"] = float(rig.lag(_HIP).mean()) if p.spin_aim or p.twist_aim else 0.0
            memo["scale"] = 1.0
            memo["unit"] = ctx.athlete.mass * ctx.athlete.leg_length**2
            if p.spin_ref or p.momentum_side:  # the spin the feet must stop (constant in the air)
                sn = ctx.sense(t)
                memo["spin"] = float(world.data.subtree_angmom[sn.root] @ sn.side_axis())
            if p.spin_ref:  # the spin to stop against the delta's (see spin_ref)
                memo["scale"] = memo["spin"] / p.spin_ref
            memo["fall"] = p.fall_ref
            if p.fall_gain:  # the fall predicted now, in the landing pose (see fall_gain)
                sn = ctx.sense(t)
                soles = (sn.sole_corners() - world.data.geom_xpos[sn.floor]) @ sn.floor_normal
                up = max(float(sn.com_vel @ sn.floor_normal), 0.0)
                g = float(np.linalg.norm(world.model.opt.gravity))
                memo["fall"] = max(float(soles.min()), 0.0) + up * up / (2.0 * g)
            memo["rot_prev"], memo["t_prev"] = ctx.rotation, t  # turn_gain's rate
            memo["reach_t"], memo["late"] = t, -1.0  # late_delta: not yet decided (-1)
            memo["kv"] = p.kv  # the placement servo's damping (late_kv once late)

        def reach(world: World, t: float) -> None:
            s = ctx.sense(t)
            h = s.side_heading() if p.spin_aim else s.heading()
            d = world.data
            hold_pelvis_and_feet(ctx, d, 0.0, h, t)  # ankles: feet flat (hips reset below)
            feet = s.sole_corners().mean(axis=(0, 1))  # the middle of the soles
            fvel = _feet_velocity(world, s.feet)
            v = s.local(s.com_vel, h)
            # capture point: where the feet stop a pendulum of the COM's height (lead: its
            # time constant sqrt(z / g)), plus the foot-servo delta
            g = float(np.linalg.norm(world.model.opt.gravity))
            tau = math.sqrt(max(float(s.com @ s.floor_normal), 0.3) / g)
            lead = p.lead * tau
            side = lead if p.side_lead is None else p.side_lead * tau
            x = s.local(feet - s.com, h)
            if p.late_delta and memo["late"] < 0 and t - memo["reach_t"] >= p.late_delta[0]:
                memo["late"] = float(np.hypot(*x) > p.late_delta[1])  # decided once (late_delta)
                if memo["late"] > 0:
                    past = float(np.hypot(*x)) - p.late_delta[1]
                    memo["kv"] = p.late_kv_at(past, ctx.rotation)
            delta = p.late_delta[2] if memo["late"] > 0 else p.delta_at(float(v[0]))
            want = np.array([lead * v[0] + delta * memo["scale"], side * v[1]])
            want[0] -= p.fall_gain * v[0] * (memo["fall"] - p.fall_ref)
            if p.momentum_gain:  # the feet also stop the rotation (see momentum_gain)
                spin = memo["spin"] if p.momentum_side else pitch_momentum(world, s)
                want[0] += p.momentum_gain * (spin - p.momentum_ref)
            if p.turn_gain:  # the feet moved by the touchdown's predicted rotation (turn_gain)
                rate = (ctx.rotation - memo["rot_prev"]) / max(t - memo["t_prev"], 1e-9)
                memo["rot_prev"], memo["t_prev"] = ctx.rotation, t
                corners = s.sole_corners() - d.geom_xpos[s.floor]
                clearance = max(float((corners @ s.floor_normal).min()), 0.0)
                t_td = time_to_height(ctx, float(s.com[2]) - clearance)
                if t_td <= p.turn_window:
                    turn = ctx.rotation + rate * t_td - p.turn_ref
                    want[0] += p.turn_gain * turn
            # eq. 6.1 as a correction on top of the geometric placement below
            xd = s.local(fvel - s.com_vel, h)
            servo = np.clip(p.kp * (want - x) - memo["kv"] * xd, -0.3, 0.3)
            # each leg aimed in the world at its foot's place, whatever the pelvis's pitch
            # (it turns freely in the air with the body's angular momentum)
            pelvis = bl.pelvis_pitch()
            if p.spin_aim:  # where the pelvis will be when the hips get there (see spin_aim)
                pelvis += memo["lag"] * float(d.cvel[s.root, :3] @ s.side_axis())
            goal = np.full((NJ, 3), np.nan)
            thighs = np.zeros((2, 3))  # aim_sideways: each thigh's pitch and roll in the world
            hips = d.xanchor[hip_joints]
            if p.aim_sideways:
                middle = s.local(s.com - hips.mean(axis=0), h)
            for k in range(2):
                hip = hips[k]
                length = float(np.linalg.norm(hip - d.xanchor[ankle_joints[k]]))
                ahead = float(s.local(s.com - hip, h)[0]) + want[0]
                swing = math.asin(
                    float(np.clip(ahead / max(length, 0.2), -p.swing_cap, p.swing_cap))
                )
                geom = float(knee_for_length(ctx.athlete.thigh[k], ctx.athlete.shin[k],
                                             length)[1])  # fmt: skip
                goal[_HIP[k]] = (-swing + geom - servo[0] - pelvis, servo[1], 0.0)
                if p.aim_sideways:
                    side = float(np.clip((middle[1] + want[1]) / max(length, 0.2), -0.5, 0.5))
                    thighs[k] = (-swing + geom - servo[0], math.asin(side) + servo[1], 0.0)
            if p.aim_sideways:  # the roll from the pelvis's whole orientation; pitch as above
                ahead = memo["lag"] * d.cvel[s.root, :3] if p.twist_aim else None
                goal[_HIP, 1] = hips_for_thighs(ctx, d, thighs, h, ahead)[:, 1]
            rig.move(goal, 0.0, t, _HIP)
            rig.offset[:] = 0.0
            for k in range(2):
                rig.offset[_ANKLE[k], 0] = p.toes
            if p.twist_arms:  # the arms out against a twist (see twist_arms)
                twist = float(d.subtree_angmom[s.root] @ s.long_axis()) / memo["unit"]
                spread = min(p.twist_arms * abs(twist), ARMS_SPREAD)
                rig.offset[_SHOULDER, 1] = (spread, -spread)

        def absorb_enter(world: World, t: float) -> None:
            rig.move(rig.desired(t) + rig.offset, 0.0, t, _HIP)
            rig.offset[:] = 0.0
            stiff = rig.stiffness.copy()
            stiff[_KNEE] = p.knee_stiffness
            stiff[_ANKLE] = BALANCE_GAINS.stiffness_array()[_ANKLE]
            stiff[_HIP] = BALANCE_GAINS.stiffness_array()[_HIP]
            rig.set_stiffness(stiff)
            # light damping: a joint damper is rigid at impact speeds (its torque grows with
            # the joint rate), and a rigid leg makes the contact spring the body back up
            rig.set_damping(per_joint(ABSORB_DAMPING))
            memo["knee_peak"] = _knee_speed(world, ctx)
            guard[:] = False
            bl.posture = Posture(leg=_leg_fraction(ctx), lean=p.lean, settle=0.0)
            memo["t_touch"] = t
            memo["pitch_touch"] = bl.pelvis_pitch() - bl.lean()
            memo["roll_touch"] = bl.pelvis_roll(ctx.sense(t).heading()) if p.roll_ease else 0.0
            # eased only past roll_min (else as without: upright at once, no wait)
            memo["roll_ease"] = p.roll_ease if abs(memo["roll_touch"]) >= p.roll_min else 0.0

        def roll_now(t: float) -> float:
            """The pelvis's roll target (see roll_ease): the touchdown's, eased to upright."""
            if not memo["roll_ease"]:
                return 0.0
            return max(0.0, 1.0 - (t - memo["t_touch"]) / memo["roll_ease"]) * memo["roll_touch"]

        def stand(world: World, t: float) -> None:
            """The balance law, the pelvis's roll eased (roll_ease)."""
            if memo["roll_ease"]:
                bl.roll = roll_now(t)
            bl.control(world, t)

        def knee_stop(t: float) -> None:
            """Hold a switched-off knee out of hyperextension (see KNEE_STOP): servo it to
            KNEE_GUARD while below KNEE_STOP, release it once bent past KNEE_GUARD."""
            flex = rig.knee_flexion()
            new = (guard | (flex < KNEE_STOP)) & (flex < KNEE_GUARD)
            if np.array_equal(new, guard):
                return
            guard[:] = new
            stiff = rig.stiffness.copy()
            stiff[_KNEE] = np.where(new, KNEE_GUARD_STIFFNESS, p.knee_stiffness)
            rig.set_stiffness(stiff)
            goal = np.full((NJ, 3), np.nan)
            goal[np.asarray(_KNEE)[new]] = (KNEE_GUARD, 0.0, 0.0)
            rig.move(goal, 0.0, t, np.asarray(_KNEE)[new])

        def absorb(world: World, t: float) -> None:
            s = ctx.sense(t)
            # passive, as the thesis's: feet flat, pelvis upright (leaning as the knees bend),
            # no COM servo (its ankle torques would push the body back off the ground)
            ease = 0.0
            if p.pitch_ease > 0:
                ease = max(0.0, 1.0 - (t - memo["t_touch"]) / p.pitch_ease) * memo["pitch_touch"]
            h = s.heading()
            hold_pelvis_and_feet(ctx, world.data, ease + bl.lean(), h, t, roll_now(t))
            rig.offset[:] = 0.0
            _stance_support(ctx)
            damp = rig.damping.copy()
            damp[_KNEE] = p.damping * _knee_lever(ctx) ** 2 / rig.athlete.leg_length**2
            rig.set_damping(damp)
            # the constant deceleration that stops the sink within the crouch left, planned
            # afresh each tick (an impact may already have taken most of the speed), as a
            # vertical ground force the stance legs make; never less than the body's weight
            room = max((_leg_fraction(ctx) - DEEPEST_LEG) * ctx.athlete.leg_length, 0.03)
            v = min(float(s.com_vel @ s.floor_normal), 0.0)
            g = float(np.linalg.norm(world.model.opt.gravity))
            decel = v * v / (2.0 * PLAN_ROOM * room)
            vertical = float(np.clip(1.0 + decel / g, 1.0, MAX_SUPPORT))
            # along the legs, from the feet to the COM, as a passive leg pushes: its
            # horizontal part takes the horizontal speed off as the COM passes over the feet
            if p.stance_push and rig.support.any():  # from the feet that carry the weight
                line = s.com - rig.support @ s.sole_corners().mean(axis=1)
            else:
                line = s.com - s.sole_corners().mean(axis=(0, 1))
            line /= max(float(line @ s.floor_normal), 0.2)
            rig.support_scale = vertical * float(np.linalg.norm(line))
            rig.support_dir = line / np.linalg.norm(line)
            z_d = float(s.com @ s.floor_normal) + v * ctx.control_every * world.timestep
            z = float(s.com @ s.floor_normal)
            if p.knee_stiffness > 0:  # the knees' targets follow the planned height
                goal = np.full((NJ, 3), np.nan)
                hips = _hip_heights(ctx)
                for k in range(2):
                    length = float(np.clip(hips[k] + z_d - z, 0.3 * ctx.athlete.leg_length,
                                           ctx.athlete.leg_length))  # fmt: skip
                    knee = knee_for_length(ctx.athlete.thigh[k], ctx.athlete.shin[k], length)
                    goal[_KNEE[k]] = (float(knee[0]), 0.0, 0.0)
                rig.move(goal, 0.0, t, _KNEE)
            if p.knee_stiffness == 0.0:
                knee_stop(t)
            memo["knee_peak"] = max(memo["knee_peak"], _knee_speed(world, ctx))

        def slowed(world: World, t: float, t_in: float) -> bool:
            """The knees have slowed to ``restore`` of their peak speed (and, with absorb_spin,
            the body no longer turns on past its gate)."""
            if p.absorb_spin and t_in < p.absorb_spin[1]:
                s = ctx.sense(t)  # mj_subtreeVel has run
                if float(world.data.subtree_angmom[s.root] @ s.side_axis()) < p.absorb_spin[0]:
                    if p.held_hip_share < 1.0 and t_in > 0.03:  # held: the knees had slowed
                        knees = _knee_speed(world, ctx) < p.restore * memo["knee_peak"]
                        memo["held"] = max(memo.get("held", 0.0), float(knees))
                    return False
            return t_in > 0.03 and _knee_speed(world, ctx) < p.restore * memo["knee_peak"]

        def recover_enter(world: World, t: float) -> None:
            del world
            rig.support_scale = 1.0
            rig.support_dir = None
            rig.move(rig.current_angles(), 0.0, t, _KNEE)  # the knees stiffen where they are
            leg = _leg_fraction(ctx)
            bl.posture = Posture(leg=leg, lean=p.lean, settle=0.0)
            stand_up = max(leg, 0.5, p.recover_leg)  # recover_leg: at least so tall
            bl.set_posture(Posture(leg=stand_up, lean=p.lean, settle=0.3), t)
            memo["hop"] = 0.0  # hop_spin: 0 not off the floor yet, 1 in the hop, 2 down again
            if memo.get("held"):  # held_hip_share, from here and in the balance after
                bl.hip_share = float(p.held_hip_share)

        def recover(world: World, t: float) -> None:
            """The balance law; with hop_spin the hop's legs placed for its spin."""
            stand(world, t)
            if not p.hop_spin or memo["hop"] == 2.0:
                return
            s = ctx.senses  # sensed this tick by the law
            down = bool(s.foot_contact.any())
            if memo["hop"] == 0.0 and not down:  # the feet leave: the spin the hop keeps
                spin = float(world.data.subtree_angmom[s.root] @ s.side_axis())
                ahead = p.hop_spin[1] * (spin - p.hop_spin[0]) / ctx.athlete.leg_length
                memo["hop_hip"] = -math.asin(float(np.clip(ahead, -0.9, 0.9)))
                memo["hop"] = 1.0
            elif memo["hop"] == 1.0 and down:
                memo["hop"] = 2.0
            if memo["hop"] == 1.0:  # hip pitch < 0 swings the foot forward
                rig.offset[_HIP, 0] += memo["hop_hip"]

        def settled(world: World, t: float, t_in: float) -> bool:
            s = ctx.sense(t)
            h = s.heading()
            err = s.local(bl.com_target - s.com, h)
            vel = s.local(s.com_vel, h)
            passed = float(err @ vel) < 0.0  # moving away from the desired COM
            still = float(np.linalg.norm(vel)) < 0.05 and float(np.linalg.norm(err)) < 0.05
            eased = t - memo["t_touch"] >= memo["roll_ease"]  # the pelvis's roll upright first
            # pitching forward on feet it stands over: the balance takes that down (recover_spin)
            spin = p.recover_spin > 0 and pitch_momentum(world, s) > p.recover_spin
            # on one foot (a bounced landing) wait recover_min; on both the code's 0.05
            lo = 0.05 if s.foot_contact.all() else p.recover_min
            if p.hop_spin and memo["hop"] == 1.0:  # the hop's own placement until it is down
                return False
            return t_in > lo and (passed or still or spin) and eased

        def done(world: World, t: float) -> None:
            del world
            ctx.handover["posture"] = bl.posture
            if bl.stepper is not None:
                ctx.handover["stepper"] = bl.stepper
            if p.carry_pitch:  # the balance's pitch target starts from ours (carry_pitch)
                ctx.handover["pitch"] = bl.pitch_target(t)
            if memo.get("held"):  # the held absorb's hip share goes on (held_hip_share)
                ctx.handover["hip_share"] = float(p.held_hip_share)

        return [
            State("reach", law(reach, every), reach_enter, ((touchdown(ctx), "absorb"),)),
            State("absorb", law(absorb, every), absorb_enter,
                  ((slowed, "recover"), (after(1.0), "recover"))),
            State("recover", law(recover, every), recover_enter,
                  ((settled, "done"), (after(1.0), "done"))),
            State("done", law(stand, every), done, ((after(0.0), NEXT),)),
        ]  # fmt: skip


def _stance_support(ctx: Context) -> None:
    """Weight shares after touchdown: every foot whose sole is within :data:`STANCE_REACH`
    of the floor (a landing foot bounces off its contacts for a moment now and then), split
    by where the COM lies between the feet."""
    s = ctx.senses
    rel = s.sole_corners() - ctx.world.data.geom_xpos[s.floor]
    near = (rel @ s.floor_normal).min(axis=1) < STANCE_REACH
    rig = ctx.rig
    rig.support[:] = 0.0
    if not near.any():
        return
    if near.all():
        pts = s.sole_corners().mean(axis=1)
        a, b = pts[0, :2], pts[1, :2]
        ab = b - a
        w = float(np.clip(np.dot(s.com[:2] - a, ab) / max(float(ab @ ab), 1e-9), 0.0, 1.0))
        rig.support[:] = (1.0 - w, w)
    else:
        rig.support[np.flatnonzero(near)[0]] = 1.0


def _hip_heights(ctx: Context) -> np.ndarray:
    """``(2,)`` current hip-to-ankle distance of each leg (m)."""
    d = ctx.world.data
    wc = ctx.rig.wc
    m = ctx.world.model
    return np.array([
        float(np.linalg.norm(d.xanchor[m.joint(wc.prefix + f"{s}_hip").id]
                             - d.xanchor[m.joint(wc.prefix + f"{s}_ankle").id]))
        for s in "lr"
    ])  # fmt: skip


def _knee_lever(ctx: Context) -> float:
    """Mean ``d(hip-ankle distance) / d(knee angle)`` of the legs (m/rad), law of cosines."""
    a = ctx.athlete
    knee = ctx.rig.knee_flexion()
    ul, ll = a.thigh, a.shin
    length = np.sqrt(ul**2 + ll**2 + 2 * ul * ll * np.cos(knee))
    return float(np.mean(ul * ll * np.abs(np.sin(knee)) / length))


def _knee_speed(world: World, ctx: Context) -> float:
    wc = ctx.rig.wc
    d = world.data
    w = [d.qvel[wc.ball_dof_start + 3 * j : wc.ball_dof_start + 3 * j + 3] for j in _KNEE]
    return float(max(np.linalg.norm(x) for x in w))


def _feet_velocity(world: World, feet: np.ndarray) -> np.ndarray:
    """Mean world velocity of the feet's centres of mass (``mj_subtreeVel`` has run)."""
    return world.data.subtree_linvel[feet].mean(axis=0)


def _leg_fraction(ctx: Context) -> float:
    """Current mean hip-to-ankle distance as a fraction of the straight leg."""
    d = ctx.world.data
    wc = ctx.rig.wc
    m = ctx.world.model
    out = []
    for s in "lr":
        hip = d.xanchor[m.joint(wc.prefix + f"{s}_hip").id]
        ankle = d.xanchor[m.joint(wc.prefix + f"{s}_ankle").id]
        out.append(float(np.linalg.norm(hip - ankle)))
    return float(np.clip(np.mean(out) / ctx.athlete.leg_length, 0.3, 1.0))
