"""The measured tables behind the commanded behaviours (thesis Tables 4.1, 4.2 and 6.1, rebuilt
for our bodies): one parameter ``s`` in [0, 1] walks a path through the low-level leap
parameters (:func:`leap_params`, :func:`broad_params`); the tables hold the height or distance
each ``s`` achieved, and a command is interpolated back to its ``s``. The landing table holds
the foot-servo delta per horizontal velocity. ``benchmarks/bench_athletics.py --tables``
rebuilds them (``build_table``); the supported ranges are measured by the same script.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from reactmocap.athletics import measured
from reactmocap.athletics.land import LandingParams
from reactmocap.athletics.leap import BROAD_TIMING, LeapParams
from reactmocap.errors import ConfigError

__all__ = [
    "BROAD_ARMS",
    "BROAD_CROUCH",
    "BROAD_LANDING",
    "BROAD_LONG",
    "BROAD_PITCH_EASE",
    "BROAD_SPIN",
    "BROAD_SPIN_GAIN",
    "BROAD_TABLES",
    "LANDING_DELTAS",
    "LANDING_DELTAS_FAST",
    "LANDING_FALL",
    "LANDING_LEADS",
    "LEAP_LANDING_TABLE",
    "LEAP_TABLES",
    "SUPPORTED",
    "BroadLong",
    "VERTICAL_LANDING",
    "VERTICAL_LANDING_COM",
    "VERTICAL_LANDING_COM_AIM",
    "VERTICAL_LANDING_COM_MOMENTUM",
    "broad_params",
    "effort_for",
    "landing_delta",
    "landing_params",
    "leap_params",
    "supported_range",
]


def leap_params(s: float) -> LeapParams:
    """The vertical leap at effort ``s``: a deeper crouch and stiffer push as ``s`` grows (the
    thesis's Table 4.1 walks crouch height and torso pitch the same way)."""
    s = float(np.clip(s, 0.0, 1.0))
    # the landing takes over at lift-off, not at the apex: its knees then reach their ready
    # bend before touchdown (from the apex, a 0.3 m leap's landing had 0.25 s and touched
    # down with the knees at 0.4 rad of 0.6; the female bounced off them)
    return LeapParams(leg=0.85 - 0.2 * s, pitch=0.0, lean=0.5, stiffness=0.1 + 0.9 * s,
                      spin_gain=20.0, handover="liftoff")  # fmt: skip


def broad_params(s: float, body: str | None = None) -> LeapParams:
    """The standing broad jump at effort ``s``: crouch, COM ahead of the feet, arm swing;
    the take-off's backward angular momentum is the body's :data:`BROAD_SPIN`."""
    s = float(np.clip(s, 0.0, 1.0))
    long = BROAD_LONG.get(body or "")
    if long is not None and s <= long.start:
        long = None
    # on the long path the crouch and the take-off spin are the path's end's (effort 1.0)
    at = s if long is None else 1.0
    spin = _along(BROAD_SPIN.get(body or "", ((0.0, DEFAULT_BROAD_SPIN),)), at)
    spin_gain = _along(BROAD_SPIN_GAIN.get(body or "", ((0.0, DEFAULT_BROAD_SPIN_GAIN),)), at)
    knots = np.array(BROAD_CROUCH.get(body or "", DEFAULT_BROAD_CROUCH)).T
    leg, pitch = (float(np.interp(at, knots[0], k)) for k in knots[1:])
    com_offset = 0.12 + 0.1 * s if long is None else _along(long.com_offset, s)
    return LeapParams(leg=leg, pitch=pitch, lean=0.0, com_offset=com_offset,
                      stiffness=0.3 + 1.0 * s, timing=BROAD_TIMING, ankle_gain=3.6,
                      arms=-1.8 - 1.0 * s, broad=True, spin=spin, spin_gain=spin_gain, hold=0.1)  # fmt: skip


def _along(knots: tuple[tuple[float, float], ...], s: float) -> float:
    """A value along the effort: knots ``((effort, value), ...)``, interpolated (held past
    the ends)."""
    e, v = np.array(knots).T
    return float(np.interp(s, e, v))


#: the broad jump's crouch along the effort: knots (effort s, hip-to-ankle leg fraction,
#: torso pitch rad), interpolated
DEFAULT_BROAD_CROUCH = ((0.0, 0.8, 0.3), (1.0, 0.65, 0.3))
#: per body. The thesis's longest jumps crouch much deeper (its Table 4.2, male hip height
#: 0.72 / 0.68 / 0.50 m for 0.38 / 1.16 / 2.12 m): the push's path sets the take-off speed.
#: Male, 2026-12-02: the default path's effort 1.0 (leg 0.65) took off at 2.7 m/s (1.95
#: across, 1.93 up) for a 1.41 m leap; leg 0.45 with the trunk pitched 0.6 rad takes off at
#: 4.3 m/s (2.9 across, 3.2 up) and lands 2.39 m. The trunk pitch grows with the crouch: at
#: leg 0.5 with 0.3 rad the push passed behind the COM (pitch momentum +13.6 kg m^2/s at
#: lift-off, where the spin feedback asks -5) and the landing pitched face down. Efforts up
#: to 0.6 keep the default path (their landings were measured on it)
#: Female (2026-12-03): her default path (exactly) up to effort 0.75 (her landings measured on
#: it), then to leg 0.5 with the trunk pitched 0.75 rad at 1.0; with her BROAD_LONG COM offset
#: (0.2 m at 1.0), BROAD_SPIN and BROAD_SPIN_GAIN effort 1.0 lifts off at 3.8 m/s pitching back
#: (-2.7 kg m^2/s), touches down with the trunk 35 deg from upright at 2.4 m/s and lands 1.80 m
#: (at pitch 0.6 she took off at 3.2 m/s, -0.2 kg m^2/s, touched down 65 deg forward, fell).
#: Above effort 0.6 she runs her BROAD_LONG path, which takes this path's effort-1.0 values
BROAD_CROUCH: Mapping[str, tuple[tuple[float, float, float], ...]] = MappingProxyType(
    {
        "male": ((0.0, 0.8, 0.3), (0.6, 0.71, 0.3), (1.0, 0.45, 0.6)),
        "female": ((0.0, 0.8, 0.3), (0.75, 0.6875, 0.3), (1.0, 0.5, 0.75)),
    }
)


#: the broad jump's take-off pitch momentum (kg m^2/s, backward < 0)
DEFAULT_BROAD_SPIN = -5.0
#: per body (measured 2026-12-02, efforts 0.1/0.2/0.45/0.7): the female (m L^2 under half
#: the male's, so the same momentum is a larger rotation) with -5 touched down from a low jump
#: with the feet 0.13 m behind the COM after a 0.1 s flight and fell forward; with -1 her
#: 0.35 and 0.43 m jumps land (-2: 0.43 m only; -3: none)
#: Values are knots along the effort ``((effort, value), ...)``, interpolated. Female
#: (2026-12-03): -1 up to effort 0.75, then to -5 at 1.0 (her deeper crouch: with -1 effort
#: 1.0 lifted off at +3.5 kg m^2/s, pitching forward, and fell; with -5 at -2.7)
BROAD_SPIN: Mapping[str, tuple[tuple[float, float], ...]] = MappingProxyType(
    {"female": ((0.75, -1.0), (1.0, -5.0))}
)
#: the take-off spin feedback's gain (LeapParams.spin_gain: hip offset per unit momentum error)
DEFAULT_BROAD_SPIN_GAIN = 40.0
#: per body. Male, 2026-12-02: with 40 the feedback hit its limit (spin_limit 0.6 rad) in his
#: deeper crouch's pushes, and the lift-off momentum jumped between -4.9 and +2.0 kg m^2/s
#: over efforts 0.85-1.0 (0.4 rad: +2.7 to +5.7, all 17 of efforts 0.8-1.0 fell; 80 or a
#: 1.0 rad limit: -3.6 to +17); with 20 it stays -1 to -3.4 and the distance grows smoothly
#: Knots along the effort, as BROAD_SPIN. Female (2026-12-03): 40 up to effort 0.75, then to
#: 20 at 1.0 (her deeper crouch's effort 1.0 with 40: -1.9 kg m^2/s, fell at every delta
#: tried; with 20: -2.7, landed)
BROAD_SPIN_GAIN: Mapping[str, tuple[tuple[float, float], ...]] = MappingProxyType(
    {"male": ((0.0, 20.0),), "female": ((0.75, 40.0), (1.0, 20.0))}
)


class BroadLong(NamedTuple):
    """A body's long broad jumps (:data:`BROAD_LONG`): above effort ``start`` the crouch, trunk
    pitch and take-off spin are the body's effort-1.0 jump's, the COM offset ahead of the feet
    follows ``com_offset`` (knots ``((effort, m), ...)``), and the landing is ``landing``
    (capture-point lead, ((touchdown speed m/s, foot-servo delta m), ...)), as
    :data:`BROAD_LANDING`."""

    start: float
    com_offset: tuple[tuple[float, float], ...]
    landing: tuple[float, tuple[tuple[float, float], ...]]


#: per body. Female (2026-12-03): between her effort 0.6 (0.75 m) and 0.925 her path went from
#: a shallow crouch to the deep one, and the take-offs there lifted off pitching forward by
#: +0.1 to +4.1 kg m^2/s (or rolled) and 9 of 13 fell, each landing at single 0.025 m deltas
#: if at all. Her deep crouch with the COM offset lowered takes off pitching back (-3.4 to
#: -4.6) at 0.8-1.9 m/s touchdown, and one delta lands all of it (docs/athletics.md). The
#: offset at 1.0: 0.22 took off at -0.0 kg m^2/s and touched down 70 deg forward, 0.2 at -2.7
#: and 35 deg (1.80 m). Efforts 0.95-1.0 (0.172-0.2 m) still take off rolled: only the ends land
BROAD_LONG: Mapping[str, BroadLong] = MappingProxyType(
    {
        "female": BroadLong(
            start=0.6,
            com_offset=(
                (0.6, 0.129),
                (0.7, 0.14),
                (0.8, 0.15),
                (0.9, 0.163),
                (0.95, 0.172),
                (1.0, 0.2),
            ),
            landing=(0.5, ((0.0, -0.175),)),
        )
    }
)


#: (effort s, achieved COM rise m) measured per body; benchmarks/bench_athletics.py --tables
LEAP_TABLES: Mapping[str, tuple[tuple[float, float], ...]] = MappingProxyType(measured.LEAP_TABLES)
#: (effort s, achieved COM travel m)
BROAD_TABLES: Mapping[str, tuple[tuple[float, float], ...]] = MappingProxyType(
    measured.BROAD_TABLES
)
#: (horizontal velocity m/s, foot-servo delta m), thesis Table 6.1 rebuilt
LANDING_DELTAS: Mapping[str, tuple[tuple[float, float], ...]] = MappingProxyType(
    measured.LANDING_DELTAS
)
#: faster rows of Table 6.1 per body, (horizontal velocity m/s, foot-servo delta m), used
#: above the measured table's fastest row (a rebuild that reaches these speeds supersedes
#: them). Female, COM 1.25 m up, lead 1.0, 2026-12-02: the middle of the deltas that landed on
#: a 0.01 m grid (2.25: -0.48..-0.44; 2.5: -0.54..-0.50; 2.75: -0.62..-0.57; 3.0:
#: -0.67..-0.63), where the 0.02 m rebuild grid (-0.5..0.3 m, 0.5 m/s steps) stops short of
#: them; with the 2.0 m/s row's -0.38 held she fell at every speed above 2.0 m/s
LANDING_DELTAS_FAST: Mapping[str, tuple[tuple[float, float], ...]] = MappingProxyType(
    {"female": ((2.25, -0.46), (2.5, -0.52), (2.75, -0.595), (3.0, -0.65))}
)
#: the landing's capture-point lead per body (tuned like the thesis's per-body deltas; a BVH
#: body gets the landing's default)
LANDING_LEADS: Mapping[str, float] = MappingProxyType({"male": 0.5, "female": 1.0})
#: the drops' placement by the fall, per body: (fall_ref m, fall_gain s/m), see
#: LandingParams.fall_gain; used by the ``land`` behaviour's drops only (leaps, broad jumps, the
#: maneuver files' landings and the vault keep it off). fall_ref: the delta tables' drop, the
#: sole clearance that puts the landing pose's COM 1.25 m up (thesis ch. 6), so those drops
#: are placed as before; gains from the windows at 2.5 m/s from COM 1.15 / 1.35 m, 2026-12-02
LANDING_FALL: Mapping[str, tuple[float, float]] = MappingProxyType(
    {"male": (0.273, 0.12), "female": (0.393, 0.2)}
)
#: bodies whose landings after a leap (``after_leap``: the maneuver files' landings) use the
#: drops' delta table (vertical leaps use VERTICAL_LANDING, broad jumps BROAD_LANDING where
#: the body has one). Chosen when broad jumps still used it: the male's landed 3 of 6 with it
#: against 1 without; the female's fell in all 6
LEAP_LANDING_TABLE: frozenset[str] = frozenset({"male"})
#: the landing after a vertical leap, per body: (capture-point lead, foot-servo delta m), a
#: constant delta (no table). Measured over the ten Fig. 4.1 commands (0.1-1.0 m, landed of 10,
#: 2026-12-02): male delta -0.04 (the table's) / -0.01 / +0.04: 9 / 10 / 4; female (lead 0.5)
#: -0.07 / -0.05 / -0.04 / -0.01: 8 / 10 / 10 / 7, and 1 with her drops' lead of 1.0 (a
#: vertical leap drifts back at 0.15-0.6 m/s, and her drops' lead put the feet so far behind
#: that the shins leaned 0.7 rad at touchdown and the ankles threw her back up once the
#: landing stiffened). Her -0.05 over -0.04: on the leap table's 41 efforts it lands
#: 0.07-0.76 m unbroken, where -0.04 lost the 0.39 m leap (range 0.41-0.87 m)
VERTICAL_LANDING: Mapping[str, tuple[float, float]] = MappingProxyType(
    {"male": (0.5, -0.01), "female": (0.5, -0.05)}
)
#: the landing after a "com" push's vertical leap (LeapParams.push), per body, as BROAD_LANDING:
#: (capture-point lead, ((horizontal speed m/s, foot-servo delta m), ...)), the delta
#: interpolated on the speed sensed in the air (a body without one uses VERTICAL_LANDING). Its
#: take-off is upright (pitch momentum about 0 to +2 kg m^2/s against the timed push's -3.4)
#: and drifts back faster the higher the leap (female -0.19 m/s at 0.1 m to -0.47 at 1.0 m).
#: Over the ten Fig. 4.1 commands (0.1-1.0 m, landed of 10, lead 0.5, 2026-12-02): male
#: constant delta -0.04 / -0.01 / 0.0 / +0.01 / +0.02: 6 / 9 / 10 / 9 / 9; female constant
#: -0.07 / -0.05 / -0.01: 6 / 7 / 3 (her 0.1 m leap landed only with -0.1, her 1.0 m only with
#: 0.0 to +0.04), this table 9 (the 0.9 m leap falls: it drifts back as fast as the 0.8 m
#: one, -0.40 m/s, and landed only with deltas the 0.8 m one fell with). Since her push's
#: softer hips and ankles (leap.COM_PUSH_LEGS) her 0.9 m leap lands and her 0.1 m one (drift
#: -0.21 m/s) fell with the -0.1 row at -0.19 m/s: with it at -0.22 (-0.05 kept at -0.23) 10
#: of 10, 0.15-0.85 m in 0.1 steps held out 7 of 8 (0.75 falls; docs/athletics.md). His
#: constant 0.0 lost his 0.95 m leap, +0.01 his 0.1 m one: 0.0 at his slow drifts (0.1 m:
#: -0.07 m/s), +0.01 from -0.15 m/s lands 0.1-1.0 m in 0.05 steps and, held out, 0.125 /
#: 0.325 / 0.525 / 0.725 / 0.925 / 0.975 m
VERTICAL_LANDING_COM: Mapping[str, tuple[float, tuple[tuple[float, float], ...]]] = (
    MappingProxyType(
        {
            "male": (0.5, ((-0.15, 0.01), (-0.1, 0.0))),
            "female": (0.5, ((-0.47, 0.0), (-0.43, -0.05), (-0.23, -0.05), (-0.22, -0.1))),
        }
    )
)
#: the "com" leap's landing's pitch-momentum feedback per body: (LandingParams.momentum_gain
#: m per kg m^2/s, momentum_ref kg m^2/s). Her take-off's pitch momentum is set by the push's
#: last two ticks (the feet rolling off) and scatters (-1.1 to +1.6 kg m^2/s over 0.1-1.0 m)
#: where her drift speed grows smoothly: her 0.75 m leap (+1.57, -0.40 m/s) landed only with
#: deltas 3-5 cm ahead of her table's, her 0.95 m one (-1.11, -0.41 m/s) 2 cm behind it. Over
#: 0.1-1.0 m in 0.05 steps (landed of 19, 2026-12-02): gain/ref 0 17 (0.75, 0.95 fell),
#: 0.01/0.8 18 (0.75), 0.015/0.3 and 0.015/0.5 19, 0.02/0.8 18 (0.95), 0.03/0.8 16
VERTICAL_LANDING_COM_MOMENTUM: Mapping[str, tuple[float, float]] = MappingProxyType(
    {"female": (0.015, 0.5)}
)
#: bodies whose "com" leap's landing aims the legs sideways from the pelvis's whole
#: orientation (LandingParams.aim_sideways). Her 0.825 m leap (0.025 m grid, 2026-12-02)
#: touched down on one foot and fell sideways 0.7 m, her 0.775 m one 0.8 m; with it 0.825
#: lands, and 0.1-1.0 m in 0.05 steps still land 19 of 19 on both bodies
VERTICAL_LANDING_COM_AIM: frozenset[str] = frozenset({"male", "female"})
#: the landing after a broad jump, per body: (capture-point lead, ((touchdown speed m/s,
#: foot-servo delta m), ...)), thesis Table 6.1 measured on broad jumps, not drops (a broad
#: jump lands lower, with the trunk pitched forward). Each row: the middle of the deltas that
#: landed (0.04 m grid, lead 0.5, pitch_ease BROAD_PITCH_EASE) at one effort, 2026-12-02
#: (/tmp sweep of ``run("broad-jump", body, effort=s)``; docs/athletics.md). The male's rows
#: from 1.68 m/s: efforts 0.7 / 0.8 / 0.875 / 0.9 / 0.925 / 1.0 of his deeper crouch
#: (BROAD_CROUCH), 0.025 m grid, his arms swung behind (BROAD_ARMS): landed -0.075..0,
#: -0.125..-0.05, -0.125..-0.075, -0.05 only, -0.15 and -0.1, -0.225..-0.15 m. Since his
#: take-off spin gain of 20 (BROAD_SPIN_GAIN; no more forward-pitching take-offs) efforts
#: 0.875 / 0.8875 (2.30 / 2.37 m/s) land at -0.15..-0.1: the rows at 2.25 / 2.3 m/s replace
#: the 0.9 take-off's own (2.34 m/s, -0.05, when it pitched forward at +2 kg m^2/s)
BROAD_LANDING: Mapping[str, tuple[float, tuple[tuple[float, float], ...]]] = MappingProxyType(
    {
        "male": (
            0.5,
            (
                (0.66, 0.1),
                (1.12, 0.04),
                (1.35, 0.02),
                (1.68, -0.04),
                (2.01, -0.09),
                (2.25, -0.1),
                (2.3, -0.125),
                (2.48, -0.15),
                (2.9, -0.19),
            ),
        ),
        "female": (
            0.5,
            (
                (0.44, 0.16),
                (0.55, 0.12),
                (0.82, 0.06),
                (1.01, 0.06),
                (1.2, 0.04),
            ),
        ),
    }
)
#: the shoulder pitch (rad, > 0 behind the trunk) a broad jump's landing swings the arms to
#: in the air, per body (LandingParams.arms; others keep its -0.6, in front). Why: the take-off
#: leaves the arms overhead, and swinging them forward-down and on behind the trunk turns the
#: rest of the body back (angular momentum is conserved in the air), so the trunk touches
#: down less pitched forward. Female, 2026-12-02: with 0.6 her 0.65 m command (effort 0.42,
#: trunk 57 deg forward at touchdown against 62) lands where it fell (docs/athletics.md)
#: Male (2026-12-02): for his deeper crouch's fast jumps (1.7-2.9 m/s; docs/athletics.md);
#: his jumps at efforts 0-0.6 land with it at their table deltas as before
BROAD_ARMS: Mapping[str, float] = MappingProxyType({"female": 1.0, "male": 1.0})
#: seconds over which a broad jump's landing rights the trunk (LandingParams.pitch_ease):
#: righting it at once threw the male's 0.96 m and the female's 0.67 m jumps back up off
#: their legs (the hips' extension pushed into the floor)
BROAD_PITCH_EASE = 0.3
#: (behaviour, parameter) -> body -> (low, high): the measured supported range; a key with a
#: third item, the variant (the leap's push), holds that variant's own range
SUPPORTED: Mapping[tuple[str, ...], Mapping[str, tuple[float, float]]] = MappingProxyType(
    measured.SUPPORTED
)


def effort_for(table: tuple[tuple[float, float], ...], value: float, what: str) -> float:
    """Interpolate a table back from an achieved value to its effort ``s`` (piecewise linear,
    the table sorted by value)."""
    if len(table) < 2:
        raise ConfigError(f"no {what} table for this body; build one (build_table)")
    s, v = np.array(sorted(table, key=lambda r: r[1])).T
    return float(np.interp(value, v, s))


def landing_delta(table: tuple[tuple[float, float], ...], velocity: float) -> float:
    """The foot-servo delta (m) for a horizontal velocity (m/s), interpolated."""
    if not table:
        return -0.04
    v, d = np.array(sorted(table)).T
    return float(np.interp(velocity, v, d))


def landing_params(
    body: str,
    velocity: float,
    after_leap: bool = False,
    vertical: bool = False,
    broad: bool = False,
    push: str = "timed",
    effort: float | None = None,
) -> LandingParams:
    """The landing controller's parameters for a body and a horizontal velocity (m/s); the
    delta table goes with them (interpolated in the air) unless ``after_leap`` and the body
    is not in :data:`LEAP_LANDING_TABLE`. ``vertical``: after a vertical leap, the body's
    :data:`VERTICAL_LANDING` where it has one; ``broad``: after a broad jump, the body's
    :data:`BROAD_LANDING` where it has one, the arms swung to :data:`BROAD_ARMS` in the air
    where it has one, and the trunk righted over :data:`BROAD_PITCH_EASE`. ``push``: the
    vertical leap's push-off (``"com"``: the body's :data:`VERTICAL_LANDING_COM` first).
    ``effort``: the broad jump's; on the body's :data:`BROAD_LONG` path its landing."""
    if broad:
        base = landing_params(body, velocity, after_leap=True)
        long = BROAD_LONG.get(body)
        if long is not None and effort is not None and effort > long.start:
            lead, table = long.landing
            base = LandingParams(lead=lead, delta=landing_delta(table, velocity), deltas=table)
        elif body in BROAD_LANDING:
            lead, table = BROAD_LANDING[body]
            base = LandingParams(lead=lead, delta=landing_delta(table, velocity), deltas=table)
        arms = BROAD_ARMS.get(body, base.arms)
        return replace(base, pitch_ease=BROAD_PITCH_EASE, arms=arms)
    if vertical and push == "com" and body in VERTICAL_LANDING_COM:
        lead, table = VERTICAL_LANDING_COM[body]
        gain, ref = VERTICAL_LANDING_COM_MOMENTUM.get(body, (0.0, 0.0))
        return LandingParams(lead=lead, delta=landing_delta(table, velocity), deltas=table,
                             momentum_gain=gain, momentum_ref=ref,
                             aim_sideways=body in VERTICAL_LANDING_COM_AIM)  # fmt: skip
    if vertical and body in VERTICAL_LANDING:
        lead, delta = VERTICAL_LANDING[body]
        return LandingParams(lead=lead, delta=delta)
    lead = LANDING_LEADS.get(body, LandingParams().lead)
    table = _with_fast_rows(tuple(LANDING_DELTAS.get(body, ())), LANDING_DELTAS_FAST.get(body, ()))
    if after_leap and body not in LEAP_LANDING_TABLE:
        table = ()
    fall_ref, fall_gain = LANDING_FALL.get(body, (0.0, 0.0)) if not after_leap else (0.0, 0.0)
    return LandingParams(lead=lead, delta=landing_delta(table, velocity), deltas=table,
                         fall_gain=fall_gain, fall_ref=fall_ref)  # fmt: skip


def _with_fast_rows(
    table: tuple[tuple[float, float], ...], fast: tuple[tuple[float, float], ...]
) -> tuple[tuple[float, float], ...]:
    """The measured delta table with the :data:`LANDING_DELTAS_FAST` rows faster than its
    fastest row appended."""
    top = max((v for v, _ in table), default=-math.inf)
    return table + tuple(r for r in fast if r[0] > top)


def supported_range(
    behaviour: str, param: str, body: str, variant: str | None = None
) -> tuple[float, float] | None:
    """The measured supported range of a behaviour's parameter for a body (a BVH body gets the
    narrower of the two thesis bodies'); None if nothing was measured. ``variant`` (the
    leap's push): that variant's own range where one was measured, else the plain one."""
    ranges = SUPPORTED.get((behaviour, param, variant or "")) or SUPPORTED.get((behaviour, param))
    if not ranges:
        return None
    if body in ranges:
        return ranges[body]
    lo = max(r[0] for r in ranges.values())
    hi = min(r[1] for r in ranges.values())
    return (lo, hi) if lo <= hi else None
