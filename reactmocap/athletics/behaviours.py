"""The behaviours a user can ask for (``balance``, ``leap``, ``broad-jump``, ``land``), each a
sequence of basis controllers on the thesis bodies or any mapped skeleton, run through the
engine's :func:`~reactmocap.sim.rollout`; :func:`run` is the Python entry point the CLI
wraps. Inputs are checked before anything runs: unknown names list the valid ones, numbers
outside the measured supported range (:mod:`reactmocap.athletics.tables`) name that range."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from reactmocap.athletics import tables
from reactmocap.athletics.balance import (
    STANDING_BOW_EASE,
    STANDING_GAINS,
    STANDING_LEG,
    STANDING_STEP,
    Balance,
    Posture,
)
from reactmocap.athletics.bodies import BODIES, Athlete, athlete
from reactmocap.athletics.land import Landing
from reactmocap.athletics.leap import PUSHES, Leap, LeapParams, com_push
from reactmocap.athletics.machine import Context
from reactmocap.athletics.report import (
    fell,
    ground_force,
    joint_peaks,
    plausibility,
    report_json,
    standing_balanced,
)
from reactmocap.athletics.scene import (
    CONTACT_MODELS,
    DEFAULT_CONTACT,
    Slope,
    add_backpack,
    athletics_world,
    stand_angles,
)
from reactmocap.athletics.sequencer import Sequencer
from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.library.motion import Motion
from reactmocap.sim.controllers.base import Controller
from reactmocap.sim.impacts import Impact
from reactmocap.sim.rollout import RolloutResult, rollout
from reactmocap.sim.world import World

__all__ = ["BEHAVIOURS", "AthleticsResult", "Behaviour", "Param", "run"]

#: seconds the athlete must stay balanced after touching down for ``landed``
LANDED_AFTER = 2.0
#: the posture a landing stands up into, slowly (a quick stand-up from a deep crouch pushes
#: the COM off the feet)
STAND_UP = Posture(settle=0.5)
#: seconds of quiet standing before a leap
LEAD_IN = 0.3
#: the highest COM rise a run's length allows for when the height is not known beforehand
MAX_APEX = 1.3
#: physics steps per control tick (4 ms)
CONTROL_EVERY = 8


@dataclass(frozen=True)
class Param:
    """A behaviour's parameter: SI units inside (``angle``: radians inside, degrees at the
    CLI), its default, and the bounds it must keep (``minimum``, ``maximum``) or anything finite."""

    name: str
    #: a number, or one of ``choices`` for a text parameter
    default: float | str | None
    unit: str
    help: str
    angle: bool = False
    minimum: float | None = None
    maximum: float | None = None
    #: a text parameter's valid values (a number otherwise)
    choices: tuple[str, ...] = ()


@dataclass(frozen=True)
class Behaviour:
    name: str
    description: str
    params: tuple[Param, ...]
    runner: Callable[[Athlete, dict[str, Any], Callable[[float], None] | None], AthleticsResult]
    #: parameters whose supported range is measured (checked by :func:`run`)
    ranged: tuple[str, ...] = ()
    #: the text parameter whose value selects its own measured range (the leap's push)
    variant: str | None = None


@dataclass
class AthleticsResult:
    """A finished run: the motion on the athlete's skeleton, the report, and what produced
    them (the rollout, the per-tick log arrays, the state transitions)."""

    behaviour: str
    body: str
    motion: Motion
    report: dict[str, Any]
    rollout: RolloutResult
    log: dict[str, np.ndarray]
    transitions: list[tuple[float, str, str]] = field(default_factory=list)

    def write_bvh(self, path: str | Path) -> Path:
        """The motion as BVH (written atomically)."""
        from reactmocap.library.bvh import write_bvh

        write_bvh(self.motion, path)
        return Path(path)

    def report_json(self) -> str:
        return report_json(self.report)


# ---------------------------------------------------------------------------------- running
def simulate(
    ath: Athlete, world: World, bases: list, duration: float, *, behaviour: str,
    impacts: tuple[Impact, ...] = (), extra: tuple[Controller, ...] = (),
    on_tick: Callable[[float], None] | None = None, fps: float = 60.0,
    extra_from_ctx: Callable[[Context], Controller] | None = None,
    energy_limit_per_kg: float = 100.0,
) -> tuple[Context, Sequencer, RolloutResult]:  # fmt: skip
    """Roll ``bases`` out on ``world`` for ``duration`` s: the run's context, sequencer and
    rollout (the rig released afterwards)."""
    ctx = Context.make(world, ath, control_every=CONTROL_EVERY)
    seq = Sequencer(ctx, bases)
    if extra_from_ctx is not None:  # a controller that needs the run's context (a platform)
        extra = (*extra, extra_from_ctx(ctx))
    tick = None if on_tick is None else (lambda t: on_tick(min(t / duration, 1.0)))
    cpu = time.process_time()
    try:
        res = rollout(world, duration, controllers=[seq, *extra], impacts=impacts,
                      record_fps=fps, on_unstable="stop", on_tick=tick, tick_every=200,
                      energy_limit_per_kg=energy_limit_per_kg)  # fmt: skip
    finally:
        ctx.rig.release()
    ctx.handover["cpu_s"] = time.process_time() - cpu
    del behaviour
    return ctx, seq, res


def athletics_result(
    name: str, ath: Athlete, ctx: Context, seq: Sequencer, res: RolloutResult,
    report: dict[str, Any],
) -> AthleticsResult:  # fmt: skip
    """The run's :class:`AthleticsResult`, its report completed with timing and status."""
    report = {"behaviour": name, "body": ath.name, "mass_kg": round(ath.mass, 2), **report,
              "simulated_s": round(res.seconds, 3), "wall_s": round(res.wall_s, 3),
              "realtime_factor": round(res.seconds / max(res.wall_s, 1e-9), 2),
              "realtime_factor_cpu": round(res.seconds / max(float(ctx.handover["cpu_s"]),  # type: ignore[arg-type]
                                                              1e-9), 2),
              "status": res.status}  # fmt: skip
    if res.status != "ok":
        report["reason"] = res.reason
        report["fell"] = True
        for key in ("landed", "balanced"):
            if key in report:
                report[key] = False
    motion = res.motion(0, name=f"{name}_{ath.name}")
    trans = [(tr.time, tr.source, tr.target) for tr in seq.transitions]
    return AthleticsResult(name, ath.name, motion, report, res, ctx.log.arrays(), trans)


def standing_heights(ctx: Context) -> tuple[float, float]:
    """COM height and pelvis height at the first tick (standing)."""
    log = ctx.log
    return float(log.rows[0][1][2]), float(log.pelvis[0])


def plausibility_report(ctx: Context, ath: Athlete, start: float, end: float) -> dict[str, Any]:
    """Peak joint torques and powers over ``[start, end]`` s against the strength model."""
    peaks = joint_peaks(ctx, start, end)
    ok, over = plausibility(peaks, ath.mass, female=ath.name == "female")
    return {"peak_joint_torque_nm": {k: v["torque_nm"] for k, v in peaks.items()},
            "peak_joint_power_w": {k: v["power_w"] for k, v in peaks.items()},
            "human_plausible": ok, "strength_exceeded": over}  # fmt: skip


def landing_report(
    ctx: Context, log: dict[str, np.ndarray], standing_pelvis: float
) -> dict[str, Any]:
    td = ctx.touchdown_time
    weight = ctx.athlete.mass * float(np.linalg.norm(ctx.world.model.opt.gravity))
    t = log["t"]
    # the tick-mean force from the momentum, as peak_grf_bw (report.ground_force says why)
    tf, force = ground_force(log, ctx.rig.mass, ctx.world.model.opt.gravity)
    grf = np.linalg.norm(force, axis=1) / weight
    after = tf >= (td if td is not None else np.inf)
    went_down = fell(ctx, standing_pelvis)
    end = float(t[-1]) if t.size else 0.0
    landed = (td is not None and not went_down and end >= td + LANDED_AFTER - 1e-6
              and standing_balanced(ctx))  # fmt: skip
    return {"touchdown_s": td, "landing_peak_grf_bw": float(grf[after].max()) if after.any()
            else None, "fell": went_down, "landed": bool(landed)}  # fmt: skip


def _leap_duration(height: float, params: LeapParams) -> float:
    flight = 2.0 * math.sqrt(2.0 * max(height, 0.05) / 9.81)
    return LEAD_IN + params.crouch + params.hold + 0.4 + flight + LANDED_AFTER + 0.1


def _run_leap(ath: Athlete, p: dict[str, Any], on_tick: Callable[[float], None] | None,
              broad: bool = False) -> AthleticsResult:  # fmt: skip
    key = "distance" if broad else "height"
    target = float(p[key])
    table = (tables.BROAD_TABLES if broad else tables.LEAP_TABLES).get(ath.name)
    if p.get("effort") is not None:
        s = float(p["effort"])
    elif table:
        s = tables.effort_for(table, target, key)
    else:
        raise ConfigError(
            f"no {'broad-jump' if broad else 'leap'} table for body {ath.name!r}: pass effort "
            "(0-1) or build one with reactmocap.athletics.tables / bench_athletics.py --tables"
        )
    params = tables.broad_params(s, ath.name) if broad else tables.leap_params(s)
    if not broad and p.get("push") == "com":
        # the COM push plans the commanded rise itself; an effort asks for the timed push's
        # height at that effort (its table), or 0.1-1.0 m without a table
        rise = target
        if p.get("effort") is not None:
            rise = (float(np.interp(s, [r[0] for r in table], [r[1] for r in table]))
                    if table else 0.1 + 0.9 * float(np.clip(s, 0.0, 1.0)))  # fmt: skip
        params = com_push(params, max(rise, 0.05), ath.name)
    if p.get("spin") is not None:
        from dataclasses import replace

        params = replace(params, spin=float(p["spin"]))
    world = athletics_world(ath, backpack=float(p.get("backpack") or 0.0), contact=p["contact"])
    landing = tables.landing_params(ath.name, 0.0, after_leap=True, vertical=not broad,
                                    broad=broad, push=params.push, effort=s)  # fmt: skip
    bases = [Balance(Posture(), seconds=LEAD_IN), Leap(params), Landing(landing),
             Balance(STAND_UP)]  # fmt: skip
    # the run lasts until well after touchdown: the flight time of the expected height
    reach = target if table and p.get("effort") is None and not broad else MAX_APEX
    ctx, seq, res = simulate(ath, world, bases, _leap_duration(reach, params),
                              behaviour="leap", on_tick=on_tick, fps=p["fps"])  # fmt: skip
    log = ctx.log.arrays()
    com0, pelvis0 = standing_heights(ctx)
    t = log["t"]
    thrust = next((tr.time for tr in seq.transitions if tr.target == "leap.thrust"), None)
    lift = ctx.liftoff_time
    weight = ath.mass * float(np.linalg.norm(world.model.opt.gravity))
    # the push's ground force, each control tick's mean (report.ground_force)
    _, force = ground_force(log, ctx.rig.mass, world.model.opt.gravity)
    push = (t[1:] > (thrust or 0.0)) & (t[:-1] < (lift if lift is not None else -1.0))
    rep: dict[str, Any] = {"effort": s}
    commanded = None if p.get("effort") is not None else target  # an effort asks no height
    if not broad:
        rep["push"] = params.push
    if broad:
        # the jump's length: COM travel (ahead, +X) from standing to where the landing took
        # the speed off (the landing's recovery starts), or 0.3 s after touchdown
        settled = next((tr.time for tr in seq.transitions if tr.target == "land.recover"),
                       (ctx.touchdown_time or t[-1]) + 0.3)  # fmt: skip
        i = min(int(np.searchsorted(t, settled)), t.size - 1)
        rep["commanded_distance_m"] = commanded
        rep["achieved_distance_m"] = float(log["com"][i, 0] - log["com"][0, 0])
        rep["final_distance_m"] = float(log["com"][-1, 0] - log["com"][0, 0])
    else:
        rep["commanded_height_m"] = commanded
        # the apex of the flight (lift-off to touchdown), not a later bounce off the landing
        td = ctx.touchdown_time
        flight = (t >= (lift if lift is not None else np.inf)) & (
            t <= (td if td is not None else np.inf)
        )
        rep["achieved_height_m"] = (
            float(log["com"][flight, 2].max() - com0) if flight.any() else 0.0
        )
    rep["time_to_liftoff_s"] = lift
    rep["peak_grf_bw"] = float(np.linalg.norm(force[push], axis=1).max() / weight) \
        if push.any() else None  # fmt: skip
    rep["liftoff_pitch_momentum"] = ctx.handover.get("liftoff_pitch_momentum")
    rep.update(landing_report(ctx, log, pelvis0))
    rep.update(plausibility_report(ctx, ath, thrust or 0.0, lift if lift is not None else np.inf))
    return athletics_result("broad-jump" if broad else "leap", ath, ctx, seq, res, rep)


def _run_land(
    ath: Athlete, p: dict[str, Any], on_tick: Callable[[float], None] | None
) -> AthleticsResult:
    drop, vx = float(p["drop"]), float(p["vx"])
    world = athletics_world(ath, contact=p["contact"])
    add_backpack(world, ath, float(p["backpack"]))
    q = ath.standing_qpos(stand_angles(ath, LANDING_LEG), clearance=drop)
    v = np.zeros(world.model.nv)
    v[0] = vx
    world.set_pose(0, q, v[world.characters[0].qvel_slice])
    lp = tables.landing_params(ath.name, vx)
    fall = math.sqrt(2.0 * max(drop, 0.0) / 9.81)
    ctx, seq, res = simulate(ath, world, [Landing(lp), Balance(STAND_UP)], fall + LANDED_AFTER + 0.3,
                              behaviour="land", on_tick=on_tick, fps=p["fps"])  # fmt: skip
    log = ctx.log.arrays()
    standing_pelvis = float(ath.standing_qpos(stand_angles(ath))[2])
    rep: dict[str, Any] = {"drop_m": drop, "vx_mps": vx, "backpack_kg": float(p["backpack"]),
                           "foot_servo_delta_m": lp.delta}  # fmt: skip
    rep.update(landing_report(ctx, log, standing_pelvis))
    rep.update(plausibility_report(ctx, ath, 0.0, np.inf))
    return athletics_result("land", ath, ctx, seq, res, rep)


#: hip-to-ankle length (fraction of the leg) of the pose a drop starts in
LANDING_LEG = 0.92


def _run_balance(
    ath: Athlete, p: dict[str, Any], on_tick: Callable[[float], None] | None
) -> AthleticsResult:
    world = athletics_world(ath, backpack=float(p["backpack"]), contact=p["contact"])
    leg = STANDING_LEG
    if p.get("pelvis_height") is not None:
        ankle = float(np.mean(_ankle_heights(world)))
        leg = (float(p["pelvis_height"]) - ankle) / ath.leg_length
        if not 0.3 <= leg <= 1.0:
            raise ConfigError(
                f"pelvis height {p['pelvis_height']} m is outside what the legs reach: "
                f"{ankle + 0.3 * ath.leg_length:.2f}-{ankle + ath.leg_length:.2f} m"
            )
    posture = Posture(pitch=float(p["pitch"]), leg=leg,
                      com_offset=(float(p["com_offset_x"]), float(p["com_offset_y"])),
                      settle=1.0)  # fmt: skip
    extra: list[Controller] = []
    ramp = 0.0
    if p["slope"]:
        ramp = SLOPE_RAMP
        feet = world.data.xpos[world.characters[0].body_ids[[12, 15]]].mean(axis=0)
        extra.append(Slope(world, float(p["slope"]), float(p["slope_dir"]), ramp,
                           pivot=np.array([feet[0], feet[1], 0.0]), control_every=CONTROL_EVERY))  # fmt: skip
    impacts: tuple[Impact, ...] = ()
    if p["push"]:
        a = float(p["push_dir"])
        force = (p["push"] * math.cos(a), p["push"] * math.sin(a), 0.0)
        impacts = (Impact("chest", force=force, start=float(p["push_time"]) + ramp,
                          duration=float(p["push_duration"])),)  # fmt: skip
    seconds = float(p["seconds"]) + ramp
    # the COM target moves uphill on a slope; the step (opt-in) across the feet too
    step = STANDING_STEP if p["step"] == "on" else None
    gains = STANDING_GAINS if step is None else replace(STANDING_GAINS, bow_ease=STANDING_BOW_EASE)
    stand = Balance(posture, gains=gains, step=step, standing_step=True)
    ctx, seq, res = simulate(ath, world, [stand], seconds, behaviour="balance",
                              impacts=impacts, extra=tuple(extra), on_tick=on_tick, fps=p["fps"])  # fmt: skip
    log = ctx.log.arrays()
    _, pelvis0 = standing_heights(ctx)
    offsets = _com_offsets(ctx)
    went_down = fell(ctx, pelvis0)
    rep: dict[str, Any] = {
        "seconds": float(p["seconds"]), "push_n": float(p["push"]),
        "push_dir_deg": math.degrees(float(p["push_dir"])), "slope_deg": math.degrees(float(p["slope"])),
        "backpack_kg": float(p["backpack"]), "fell": went_down,
        "balanced": bool(not went_down and standing_balanced(ctx)),
        "max_com_offset_m": float(offsets.max()) if offsets.size else 0.0,
        # at the last tick: ``balanced`` allows a still body on one foot, which the report
        # says rather than hides (docs/athletics.md, Fig. 7.7)
        "on_both_feet": bool(ctx.senses.foot_contact.all()),
    }  # fmt: skip
    if p["feet"] == "both":
        rep["balanced"] = bool(rep["balanced"] and rep["on_both_feet"])
    if step is not None:
        # a run that stepped counts only if it ends on both feet (a step held on one foot is
        # no recovery; without a step the judge is the default's)
        steps = ctx.handover.get("steps")
        rep["steps"] = [dict(r) for r in steps] if isinstance(steps, list) else []
        if rep["steps"]:
            rep["balanced"] = bool(rep["balanced"] and rep["on_both_feet"])
    del log
    return athletics_result("balance", ath, ctx, seq, res, rep)


#: seconds over which a slope comes in under a balancing athlete
SLOPE_RAMP = 2.0


def _ankle_heights(world: World) -> np.ndarray:
    m, d = world.model, world.data
    pre = world.characters[0].prefix
    return np.array([d.xanchor[m.joint(f"{pre}{s}_ankle").id][2] for s in "lr"])


def _com_offsets(ctx: Context) -> np.ndarray:
    """Per tick, the horizontal distance (m) of the COM from the support centre."""
    return np.asarray(ctx.log.offsets, dtype=np.float64)


# ---------------------------------------------------------------------------------- registry
_FPS = Param("fps", 60.0, "1/s", "output frame rate", minimum=1.0)
_BACKPACK = Param("backpack", 0.0, "kg", "backpack mass on the chest", minimum=0.0)
_CONTACT = Param("contact", DEFAULT_CONTACT, "", "athletics contact model (scene.CONTACT_MODELS; "
                 "the measured tables are the default's)", choices=tuple(CONTACT_MODELS))  # fmt: skip
BEHAVIOURS: Mapping[str, Behaviour] = MappingProxyType({
    "balance": Behaviour(
        "balance", "stand balanced (thesis ch. 7): optional push, slope, posture, backpack",
        (Param("seconds", 3.0, "s", "how long to balance", minimum=0.0),
         Param("push", 0.0, "N", "push on the chest", minimum=0.0),
         Param("push_dir", 0.0, "deg", "push direction (0 forward, 90 to the left)", angle=True),
         Param("push_duration", 0.25, "s", "push duration", minimum=0.0),
         Param("push_time", 1.0, "s", "when the push starts", minimum=0.0),
         Param("slope", 0.0, "deg", "ground slope", angle=True),
         Param("slope_dir", 0.0, "deg", "direction the ground rises toward (0: ahead)",
               angle=True),
         Param("pitch", 0.0, "deg", "torso pitch (forward > 0)", angle=True),
         Param("pelvis_height", None, "m", "hip joint height above the ground"),
         Param("com_offset_x", 0.0, "m", "desired COM ahead of the support centre"),
         Param("com_offset_y", 0.0, "m", "desired COM left of the support centre"),
         Param("step", "off", "", "a balance step when the capture point leaves the soles "
               "(balance.STANDING_STEP; opt-in, our own: the thesis's balance has none)",
               choices=("off", "on")),
         Param("feet", "any", "", "what `balanced` asks of the feet at the last tick: 'any' "
               "(one foot allowed if still over it) or 'both' (opt-in: a still one-foot stand "
               "at 3 s was a fall in progress on 5 of 5 default pushes, docs/athletics.md)",
               choices=("any", "both")),
         _BACKPACK, _CONTACT, _FPS),
        lambda a, p, cb: _run_balance(a, p, cb), ("push", "slope")),
    "leap": Behaviour(
        "leap", "vertical leap to a COM rise, land, balance (thesis ch. 4, 6, 8.1)",
        (Param("height", None, "m", "commanded COM rise at the apex over standing"),
         Param("effort", None, "", "leap effort 0-1 instead of a height (no table needed)",
               minimum=0.0, maximum=1.0),
         Param("spin", None, "kg m^2/s", "take-off angular momentum (pitch) to aim for"),
         Param("push", "com", "", "push-off: 'com' (a servo on the COM, ground force "
               "planned) or 'timed' (the thesis's joints on fixed timing)", choices=PUSHES),
         _BACKPACK, _CONTACT, _FPS),
        lambda a, p, cb: _run_leap(a, p, cb), ("height",), variant="push"),
    "broad-jump": Behaviour(
        "broad-jump", "standing broad jump to a COM travel, land, balance (ch. 4.2, 8.2)",
        (Param("distance", None, "m", "commanded horizontal COM travel"),
         Param("effort", None, "", "jump effort 0-1 instead of a distance", minimum=0.0,
               maximum=1.0),
         Param("spin", None, "kg m^2/s", "take-off angular momentum (pitch) to aim for"),
         _BACKPACK, _CONTACT, _FPS),
        lambda a, p, cb: _run_leap(a, p, cb, broad=True), ("distance",)),
    "land": Behaviour(
        "land", "fall from a height (optionally moving) and land (thesis ch. 6)",
        (Param("drop", None, "m", "height of the soles above the ground at release",
               minimum=0.0),
         Param("vx", 0.0, "m/s", "horizontal COM velocity at release (forward > 0)"),
         _BACKPACK, _CONTACT, _FPS),
        lambda a, p, cb: _run_land(a, p, cb), ("drop", "vx")),
})  # fmt: skip


def behaviour(name: str) -> Behaviour:
    try:
        return BEHAVIOURS[name]
    except KeyError:
        raise UnknownKeyError(
            f"unknown behaviour {name!r}; valid behaviours are {sorted(BEHAVIOURS)}"
        ) from None


def _params(b: Behaviour, given: Mapping[str, Any], check_range: bool, body: str) -> dict[str, Any]:
    known = {p.name: p for p in b.params}
    unknown = sorted(set(given) - set(known))
    if unknown:
        raise ConfigError(
            f"{b.name} has no parameter(s) {unknown}; its parameters are {sorted(known)}"
        )
    out: dict[str, Any] = {}
    for p in b.params:
        v = given.get(p.name, p.default)
        if p.choices:
            if v is not None and v not in p.choices:
                raise ConfigError(f"{b.name} {p.name} must be one of {list(p.choices)}, got {v!r}")
        elif v is not None:
            try:
                v = float(v)
            except (TypeError, ValueError):
                raise ConfigError(f"{b.name} {p.name} must be a number, got {v!r}") from None
            if not math.isfinite(v):
                raise ConfigError(f"{b.name} {p.name} must be a finite number, got {v!r}")
            unit = f" {p.unit}" if p.unit else ""
            if p.minimum is not None and v < p.minimum:
                raise ConfigError(f"{b.name} {p.name} must be >= {p.minimum}{unit}, got {v}")
            if p.maximum is not None and v > p.maximum:
                raise ConfigError(f"{b.name} {p.name} must be <= {p.maximum}{unit}, got {v}")
        out[p.name] = v
    needed = [p.name for p in b.params if p.default is None and out[p.name] is None
              and p.name not in ("effort", "spin", "pelvis_height", "push")]  # fmt: skip
    if b.name in ("leap", "broad-jump") and out.get("effort") is not None:
        needed = []
        out["height" if b.name == "leap" else "distance"] = out.get(
            "height" if b.name == "leap" else "distance") or 0.0  # fmt: skip
    if needed:
        raise ConfigError(f"{b.name} needs {needed}")
    if check_range:
        for name in b.ranged:
            rng = tables.supported_range(b.name, name, body, out[b.variant] if b.variant else None)
            v = out[name]
            effort = name in ("height", "distance") and out.get("effort") is not None
            if rng is None or v is None or effort:
                continue
            if not rng[0] - 1e-9 <= v <= rng[1] + 1e-9:
                unit = next(p.unit for p in b.params if p.name == name)
                shown = (math.degrees(v), *map(math.degrees, rng)) if unit == "deg" else (v, *rng)
                kind = f" with {b.variant} {out[b.variant]!r}" if b.variant else ""
                raise ConfigError(
                    f"{b.name} {name} {shown[0]:g} {unit} is outside the supported range "
                    f"{shown[1]:g}-{shown[2]:g} {unit} for body {body!r}{kind} (measured; see "
                    "docs/athletics.md)"
                )
    return out


def run(
    name: str,
    body: str | Path | Motion = "male",
    *,
    on_tick: Callable[[float], None] | None = None,
    check_range: bool = True,
    **params: Any,
) -> AthleticsResult:
    """Run behaviour ``name`` on ``body`` (``"male"``, ``"female"``, a BVH path or a Motion)
    with SI parameters (radians for angles), e.g. ``run("leap", body="male", height=0.6)``.
    ``check_range=False`` runs outside the measured supported range (and reports honestly);
    ``on_tick`` is called now and then with the fraction simulated (a progress bar)."""
    b = behaviour(name)
    ath = athlete(body)
    key = ath.name if ath.name in BODIES else "custom"
    p = _params(b, params, check_range, key)
    result = b.runner(ath, p, on_tick)
    if p["contact"] != DEFAULT_CONTACT:  # (the default's report is as before the option)
        result.report["contact"] = p["contact"]
    return result
