"""Composed maneuvers (thesis ch. 8): a maneuver is a sequence of phases, each a basis controller
from :data:`CONTROLLERS` (``balance``, ``leap``, ``tumble``, ``land``, ``stretch``,
``handspring``, ``backdrop``) with its parameters and the event that ends it; the sequencer runs
them with automatic transitions. A user writes one in a TOML file (:func:`load_maneuver`,
``reactmocap athletics maneuver FILE.toml``); the somersaults, dives and the back handspring
are built-in maneuvers (:mod:`reactmocap.athletics.routines`).

A maneuver file::

    name = "back_somersault"
    body = "male"            # male, female or a BVH file
    seconds = 4.5            # how long to simulate
    backpack = 0.0           # kg on the chest (optional)

    [[phase]]
    controller = "balance"
    exit = { event = "after", seconds = 0.3 }

    [[phase]]
    controller = "leap"
    params = { effort = 0.6, spin = -55.0, spin_limit = 1.0 }
    exit = { event = "liftoff" }

    ...

Parameters are SI, angles in radians; each controller's parameters and exit events are listed
by :func:`describe` (and in ``docs/athletics.md``)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from reactmocap.athletics import tables
from reactmocap.athletics.backdrop import Backdrop, backdrop_keyframes
from reactmocap.athletics.balance import (
    BALANCE_GAINS,
    STANDING_BOW_EASE,
    STANDING_GAINS,
    STANDING_STEP,
    Balance,
    Posture,
    Step,
)
from reactmocap.athletics.behaviours import (
    AthleticsResult,
    athletics_result,
    landing_report,
    plausibility_report,
    simulate,
    standing_heights,
)
from reactmocap.athletics.bodies import BODIES, Athlete, athlete
from reactmocap.athletics.dive import PLATFORM_MAX, Platform, Stretch, entry_report
from reactmocap.athletics.handspring import Handspring, HandspringParams, handspring_report
from reactmocap.athletics.land import Landing, LandingParams
from reactmocap.athletics.leap import Leap, LeapParams
from reactmocap.athletics.machine import Basis
from reactmocap.athletics.scene import DEFAULT_CONTACT, athletics_world, stand_angles
from reactmocap.athletics.tumble import POSITIONS, Tumble, TumbleParams
from reactmocap.errors import ConfigError
from reactmocap.io import read_toml
from reactmocap.sim.world import World

__all__ = [
    "CONTROLLERS",
    "BasisSpec",
    "Maneuver",
    "Perturbation",
    "Phase",
    "capture_region",
    "capture_summary",
    "describe",
    "load_maneuver",
    "run_maneuver",
]


@dataclass(frozen=True)
class Phase:
    """One phase of a maneuver: a basis controller by name, its parameters (SI, radians), and
    the event that ends it (``exit``; ``seconds`` for ``after``)."""

    controller: str
    exit: str
    params: Mapping[str, Any] = field(default_factory=dict)
    seconds: float | None = None


@dataclass(frozen=True)
class Maneuver:
    """A named sequence of phases on a body, simulated for ``seconds``."""

    name: str
    phases: tuple[Phase, ...]
    body: str = "male"
    seconds: float = 5.0
    backpack: float = 0.0
    #: platform height (m) over the water: 0 stands on the floor; > 0 the floor drops away
    #: after lift-off and the run is judged at the water (a dive, :mod:`.dive`)
    platform: float = 0.0


@dataclass(frozen=True)
class BasisSpec:
    """A basis controller a phase can name: its parameters (name -> kind: ``number``,
    ``bool``, ``string``, ``numbers``), its exit events, and how it is built."""

    name: str
    description: str
    params: Mapping[str, str]
    exits: Mapping[str, str]
    build: Callable[[Phase, Athlete], Basis]


def _kinds(cls: type, skip: tuple[str, ...] = ()) -> dict[str, str]:
    """Parameter kinds of a parameter dataclass, from its fields' defaults."""
    out = {}
    for f in dataclasses.fields(cls):
        if f.name in skip:
            continue
        d = f.default
        if isinstance(d, bool):
            out[f.name] = "bool"
        elif isinstance(d, (int, float)) or d is None:
            out[f.name] = "number"
        elif isinstance(d, str):
            out[f.name] = "string"
        else:
            out[f.name] = "numbers"
    return out


def _build_balance(phase: Phase, ath: Athlete) -> Basis:
    del ath
    p = dict(phase.params)
    if "com_offset" in p:
        p["com_offset"] = tuple(p["com_offset"])
    share = p.pop("settle_share", None)
    if share is not None and phase.exit != "settled":
        raise ConfigError(
            f"balance settle_share applies to the exit 'settled' only, not {phase.exit!r}"
        )
    step = Step.of(p.pop("step", ()))
    gains = p.pop("gains", "balance")
    if gains not in BALANCE_GAIN_SETS:
        raise ConfigError(
            f"balance gains must be one of {sorted(BALANCE_GAIN_SETS)}, got {gains!r}"
        )
    g = BALANCE_GAIN_SETS[gains]
    standing = bool(p.pop("standing_step", False))
    standing_only = {k: float(p.pop(k)) for k in _STANDING_ONLY if k in p}  # see check_phase
    if standing:
        # the balance behaviour's step="on": a hung foot planted, steps across the feet too,
        # the bow (standing gains) eased; `step` numbers override its own, not the plant
        step = replace(step, hang_still=STANDING_STEP.hang_still) if step else STANDING_STEP
        step = replace(step, **standing_only)
        g = replace(g, bow_ease=STANDING_BOW_EASE) if g.bow is not None else g
    seconds = phase.seconds if phase.exit == "after" else None
    within = None
    if phase.exit == "settled":
        within = phase.seconds if phase.seconds is not None else SETTLE_WITHIN
    return Balance(Posture(**p), seconds=seconds, gains=g, settle_within=within,
                   settle_share=share, step=step, standing_step=standing)  # fmt: skip


def _build_leap(phase: Phase, ath: Athlete) -> Basis:
    p = dict(phase.params)
    effort = p.pop("effort", None)
    broad = bool(p.get("broad", False))
    if effort is not None:
        # the body's own broad jump (its crouch and take-off spin), as run("broad-jump")
        base = (tables.broad_params(float(effort), ath.name) if broad
                else tables.leap_params(float(effort)))  # fmt: skip
    else:
        base = LeapParams(broad=broad)
    for key in ("timing", "crouch_until"):
        if key in p:
            p[key] = tuple(p[key])
    return Leap(replace(base, handover=phase.exit, **p))


def _build_tumble(phase: Phase, ath: Athlete) -> Basis:
    del ath
    p = dict(phase.params)
    if phase.exit == "after":
        p["open_at"] = phase.seconds
    return Tumble(TumbleParams(**p))


def _build_stretch(phase: Phase, ath: Athlete) -> Basis:
    del ath
    return Stretch(**phase.params)


def _build_handspring(phase: Phase, ath: Athlete) -> Basis:
    del ath
    return Handspring(HandspringParams(**phase.params))


def _build_backdrop(phase: Phase, ath: Athlete | None = None) -> Basis:
    del ath
    p = phase.params
    keys = backdrop_keyframes(str(p.get("direction", "backward")))
    loops = p.get("loops", 1.0)
    if int(loops) != loops:
        raise ConfigError(f"backdrop loops must be a whole number, got {loops}")
    segment = float(p.get("segment", 0.5))
    return Backdrop(keys, segment, int(loops), handover=phase.exit == "done")


def _build_land(phase: Phase, ath: Athlete) -> Basis:
    base = tables.landing_params(ath.name, 0.0, after_leap=True)
    if "delta" in phase.params:  # an explicit delta holds at every speed
        base = replace(base, deltas=())
    p = dict(phase.params)
    for key in ("step", "late_delta"):
        if key in p:
            p[key] = tuple(p[key])
    return Landing(replace(base, **p))


#: seconds a balance phase ending "settled" may take by default
SETTLE_WITHIN = 2.0
#: a balance phase's ``gains`` by name: the thesis's COM servo, or the standing behaviour's
#: (its hip and arm strategies and windmilling against a fall; on a level floor the rest is the
#: same)
#: balance keys taken only with ``standing_step``: (upper bound, unit), each in (0, bound]
_STANDING_ONLY = {"hang_near": (0.3, "m"), "plant_settle": (5.0, "s")}
BALANCE_GAIN_SETS = MappingProxyType({"balance": BALANCE_GAINS, "standing": STANDING_GAINS})
_LEAP_KINDS = {"effort": "number", **_kinds(LeapParams, skip=("handover",))}
CONTROLLERS: Mapping[str, BasisSpec] = MappingProxyType({
    "balance": BasisSpec(
        "balance", "stand balanced in a posture (thesis ch. 7); `settle_share`: the weight "
        "each foot must bear for the exit `settled` (default 0.2); `gains`: \"balance\" "
        "(default) or \"standing\" (the hip and arm strategies against a fall as well); "
        "`step`: [margin, reach, lift, seconds], a step when the capture point leaves the feet; "
        "`standing_step` (default false): the standing balance's step (the `balance` "
        "behaviour's step \"on\": a foot left hanging put down once the COM is slower than "
        "0.25 m/s, steps across the feet too; `step` overrides its step's numbers, not the "
        "plant); `hang_near` (m, (0, 0.3], with `standing_step`; default off): that foot "
        "is put down only once the COM also lies within this of the standing sole's middle; "
        "`plant_settle` (s, (0, 5], with `standing_step`; default off): as that foot is put "
        "down the stand-up starts again from rest and takes this long",
        {**_kinds(Posture), "settle_share": "number", "gains": "string", "step": "numbers",
         "standing_step": "bool", "hang_near": "number", "plant_settle": "number"},
        {"after": "after `seconds`", "never": "holds to the end of the run",
         "settled": "once standing still on both feet with the COM over them (a perturbed "
                    "start); not settled within `seconds` (default 2): the run fails there"},
        _build_balance),
    "leap": BasisSpec(
        "leap", "crouch and leap (ch. 4); `effort` 0-1 picks the measured leap (broad = true: "
        "the broad jump's), any other parameter overrides it; `spin` (kg m^2/s, pitch, "
        "forward > 0) is the take-off angular momentum aimed for",
        _LEAP_KINDS,
        {"apex": "at the top of the flight", "liftoff": "as the feet leave the floor",
         "auto": "apex for a vertical leap, lift-off for a broad jump"}, _build_leap),
    "tumble": BasisSpec(
        "tumble", "somersault in the air in a layout, pike or tuck (ch. 5)",
        _kinds(TumbleParams, skip=("open_at",)),
        {"open": "when the rotation predicted at touchdown reaches `turns`",
         "after": "after `seconds` in the air (the thesis's timed transition)"}, _build_tumble),
    "land": BasisSpec(
        "land", "passive landing (ch. 6); ends once it has settled and handed over",
        _kinds(LandingParams, skip=("deltas",)), {"settled": "once the landing has settled"}, _build_land),
    "handspring": BasisSpec(
        "handspring", "back handspring's hand support (ch. 8.3): arched with the arms over the "
        "head until the hands touch, arms as struts, then push and snap down",
        _kinds(HandspringParams),
        {"released": "once the hands have left the floor after the push, or a foot touches"},
        _build_handspring),
    "backdrop": BasisSpec(
        "backdrop", "Frohlich's torque-free backdrop in the air (5.1.1): pike, circle both arms "
        "(`direction` backward or forward: the way the body turns), open; `loops` times, "
        "`segment` s per move", {"direction": "string", "loops": "number", "segment": "number"},
        {"done": "once the loops are done", "never": "holds the last shape to the end"},
        _build_backdrop),
    "stretch": BasisSpec(
        "stretch", "straighten with the arms over the head for a dive's entry; holds to the "
        "end", {"seconds": "number"}, {"never": "holds to the end of the run"}, _build_stretch),
})  # fmt: skip


def describe() -> str:
    """The controllers a phase can name, their parameters and exit events (for help)."""
    lines = []
    for spec in CONTROLLERS.values():
        lines.append(f"{spec.name}: {spec.description}")
        lines.append("  params: " + ", ".join(f"{k} ({v})" for k, v in spec.params.items()))
        lines.append("  exits: " + "; ".join(f"{k}: {v}" for k, v in spec.exits.items()))
    return "\n".join(lines)


# ---------------------------------------------------------------------------------- loading
def _check_value(kind: str, value: Any, where: str) -> Any:
    if kind == "number":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{where} must be a number, got {value!r}")
        if not math.isfinite(value):
            raise ConfigError(f"{where} must be a finite number, got {value!r}")
        return float(value)
    if kind == "bool":
        if not isinstance(value, bool):
            raise ConfigError(f"{where} must be true or false, got {value!r}")
        return value
    if kind == "string":
        if not isinstance(value, str):
            raise ConfigError(f"{where} must be a string, got {value!r}")
        return value
    if not (isinstance(value, list) and value
            and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                    and math.isfinite(v) for v in value)):  # fmt: skip
        raise ConfigError(f"{where} must be a list of finite numbers, got {value!r}")
    return [float(v) for v in value]


def check_phase(phase: Phase, where: str) -> Phase:
    """``phase`` with its parameters checked against its controller (``where`` names it in
    the errors, e.g. ``"FILE: phase[2]"``); builds nothing."""
    spec = CONTROLLERS.get(phase.controller)
    if spec is None:
        raise ConfigError(
            f"{where}.controller: unknown basis controller {phase.controller!r}; valid "
            f"controllers are {sorted(CONTROLLERS)}"
        )
    if phase.exit not in spec.exits:
        raise ConfigError(
            f"{where}.exit.event: {phase.controller} has no exit event {phase.exit!r}; its "
            f"exit events are {sorted(spec.exits)}"
        )
    if phase.exit == "after" and (
        phase.seconds is None or not math.isfinite(phase.seconds) or phase.seconds < 0
    ):
        raise ConfigError(f"{where}.exit.seconds: exit 'after' needs seconds >= 0")
    if (
        phase.exit == "settled"
        and phase.seconds is not None
        and not (math.isfinite(phase.seconds) and phase.seconds > 0)
    ):
        raise ConfigError(f"{where}.exit.seconds: exit 'settled' needs seconds > 0 (the "
                          f"time it may take), got {phase.seconds}")  # fmt: skip
    params = {}
    for key, value in phase.params.items():
        if key not in spec.params:
            raise ConfigError(
                f"{where}.params.{key}: {phase.controller} has no parameter {key!r}; its "
                f"parameters are {sorted(spec.params)}"
            )
        params[key] = _check_value(spec.params[key], value, f"{where}.params.{key}")
    effort = params.get("effort") if phase.controller == "leap" else None
    if effort is not None and not 0.0 <= effort <= 1.0:  # the measured tables' range
        raise ConfigError(f"{where}.params.effort: must be 0-1, got {effort:g}")
    for key, (hi, unit) in _STANDING_ONLY.items() if phase.controller == "balance" else ():
        v = params.get(key)
        if v is not None and not (params.get("standing_step") is True and 0.0 < v <= hi):
            raise ConfigError(f"{where}.params.{key}: needs standing_step = true and must "
                              f"be in (0, {hi:g}] {unit}, got {v:g}")  # fmt: skip
    if phase.controller == "tumble" and params.get("position", "tuck") not in POSITIONS:
        raise ConfigError(
            f"{where}.params.position: unknown position {params['position']!r}; valid "
            f"positions are {sorted(POSITIONS)}"
        )
    checked = replace(phase, params=params)
    if phase.controller == "backdrop":  # its own checks, named here
        try:
            _build_backdrop(checked)
        except ConfigError as e:
            raise ConfigError(f"{where}.params: {e}") from e
    return checked


_TOP = {"name": "string", "body": "string", "seconds": "number", "backpack": "number",
        "platform": "number"}  # fmt: skip


def load_maneuver(path: str | Path) -> Maneuver:
    """Read and check a maneuver file (format: the module docstring). Every error is a
    :class:`~reactmocap.errors.ConfigError` naming the file and the field."""
    path = Path(path)
    data = read_toml(path, "maneuver")
    return maneuver_from_dict(data, str(path), default_name=path.stem)


def maneuver_from_dict(
    data: Mapping[str, Any], source: str, default_name: str = "maneuver"
) -> Maneuver:
    """A :class:`Maneuver` from parsed TOML ``data`` (``source`` names it in errors)."""
    unknown = sorted(set(data) - set(_TOP) - {"phase"})
    if unknown:
        raise ConfigError(
            f"{source}: unknown field(s) {unknown}; a maneuver has {sorted([*_TOP, 'phase'])}"
        )
    top = {
        k: _check_value(kind, data[k], f"{source}: {k}") for k, kind in _TOP.items() if k in data
    }
    seconds = float(top.get("seconds", 5.0))
    if not 0 < seconds <= 60:
        raise ConfigError(f"{source}: seconds must be in (0, 60], got {seconds}")
    backpack = float(top.get("backpack", 0.0))
    if backpack < 0:
        raise ConfigError(f"{source}: backpack must be >= 0 kg, got {backpack}")
    platform = float(top.get("platform", 0.0))
    if not (platform == 0.0 or 1.0 <= platform <= PLATFORM_MAX):
        raise ConfigError(
            f"{source}: platform must be 0 (none) or 1-{PLATFORM_MAX:g} m, got {platform}"
        )
    rows = data.get("phase")
    if not isinstance(rows, list) or not rows:
        raise ConfigError(f"{source}: phase: a maneuver needs at least one [[phase]] table")
    phases = []
    for i, row in enumerate(rows):
        where = f"{source}: phase[{i + 1}]"
        if not isinstance(row, dict):
            raise ConfigError(f"{where} must be a table")
        extra = sorted(set(row) - {"controller", "params", "exit"})
        if extra:
            raise ConfigError(
                f"{where}: unknown field(s) {extra}; a phase has controller, params, exit"
            )
        if "controller" not in row:
            raise ConfigError(
                f"{where}.controller is missing; valid controllers are {sorted(CONTROLLERS)}"
            )
        controller = _check_value("string", row["controller"], f"{where}.controller")
        exit_ = row.get("exit")
        spec = CONTROLLERS.get(controller)
        valid = sorted(spec.exits) if spec is not None else []
        if exit_ is None:
            raise ConfigError(
                f"{where}.exit is missing: every phase names the event that ends it, e.g. "
                f'exit = {{ event = "{valid[0] if valid else "after"}" }}'
                + (f"; {controller}'s exit events are {valid}" if valid else "")
            )
        if not isinstance(exit_, dict) or "event" not in exit_:
            raise ConfigError(f"{where}.exit must be a table with an event, e.g. "
                              "exit = { event = \"after\", seconds = 0.5 }")  # fmt: skip
        if sorted(set(exit_) - {"event", "seconds"}):
            raise ConfigError(f"{where}.exit: only event and seconds are allowed")
        event = _check_value("string", exit_["event"], f"{where}.exit.event")
        secs = exit_.get("seconds")
        if secs is not None:
            secs = _check_value("number", secs, f"{where}.exit.seconds")
        params = row.get("params", {})
        if not isinstance(params, dict):
            raise ConfigError(f"{where}.params must be a table")
        phases.append(check_phase(Phase(controller, event, params, secs), where))
    body = str(top.get("body", "male"))
    if body not in BODIES and not body.lower().endswith(".bvh"):
        raise ConfigError(
            f"{source}: body must be one of {list(BODIES)} or a BVH file, got {body!r}"
        )
    name = str(top.get("name", default_name))
    return Maneuver(name, tuple(phases), body, seconds, backpack, platform)


# ---------------------------------------------------------------------------------- running
@dataclass(frozen=True)
class Perturbation:
    """A perturbed start: every joint angle of the standing pose (pitch, roll, yaw) off by
    ``joint_rad`` each, the pelvis pitched by ``pitch_rad``, the body moving at ``velocity``
    (m/s, world ``x, y, z``) and turning at ``spin`` (rad/s, the free joint's pelvis frame). The feet are
    put back on the floor (lowest sole corner 0.5 mm up)."""

    joint_rad: tuple[tuple[float, float, float], ...]
    pitch_rad: float = 0.0
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    spin: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @classmethod
    def sample(
        cls, rng: np.random.Generator, joint_sd: float = math.radians(3.0),
        pitch_sd: float = math.radians(2.0), velocity_sd: float = 0.05, spin_sd: float = 0.1,
    ) -> Perturbation:  # fmt: skip
        """Independent normal perturbations with the given standard deviations (the
        distribution the capture regions state: 3 deg per joint axis, 2 deg of pelvis pitch,
        0.05 m/s per velocity axis, 0.1 rad/s per spin axis)."""
        joints = rng.normal(0.0, joint_sd, (15, 3))
        return cls(tuple(tuple(float(x) for x in row) for row in joints),  # type: ignore[misc]
                   float(rng.normal(0.0, pitch_sd)),
                   tuple(float(x) for x in rng.normal(0.0, velocity_sd, 3)),  # type: ignore[arg-type]
                   tuple(float(x) for x in rng.normal(0.0, spin_sd, 3)))  # type: ignore[arg-type]  # fmt: skip

    def apply(self, world: World, ath: Athlete) -> None:
        angles = stand_angles(ath) + np.asarray(self.joint_rad, dtype=np.float64)
        q = ath.standing_qpos(angles, pitch=self.pitch_rad, clearance=0.0005)
        v = np.zeros(world.model.nv)
        wc = world.characters[0]
        qv = v[wc.qvel_slice]
        qv[0:3] = self.velocity
        qv[3:6] = self.spin
        world.set_pose(0, q, qv)


def capture_region(
    maneuver: Maneuver, starts: int = 50, seed: int = 0, workers: int = 1,
    contact: str = DEFAULT_CONTACT, **sd: float,
) -> dict[str, Any]:  # fmt: skip
    """Run ``maneuver`` from ``starts`` perturbed starts (:meth:`Perturbation.sample`, seeded;
    ``contact``: the athletics contact model, :data:`~reactmocap.athletics.scene.CONTACT_MODELS`)
    and report the success rate (``landed`` and not ``fell``) and, per perturbation, its size
    (RMS joint offset, pelvis pitch, horizontal speed, pitch spin) and whether it landed."""
    rng = np.random.default_rng(seed)
    perts = [Perturbation.sample(rng, **sd) for _ in range(starts)]
    jobs = [(maneuver, p, contact) for p in perts]
    if workers > 1:
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(workers) as ex:
            outcomes = list(ex.map(_capture_one, jobs))
    else:
        outcomes = [_capture_one(j) for j in jobs]
    rows = []
    for p, (ok, rot) in zip(perts, outcomes):
        rows.append({
            "joint_rms_deg": math.degrees(float(np.sqrt(np.mean(np.square(p.joint_rad))))),
            "pitch_deg": math.degrees(p.pitch_rad),
            "speed_mps": float(np.hypot(p.velocity[0], p.velocity[1])),
            "pitch_spin_rad_s": p.spin[1], "landed": ok, "rotation_deg": rot,
        })  # fmt: skip
    wins = sum(r["landed"] for r in rows)
    return {"maneuver": maneuver.name, "starts": starts, "seed": seed, "landed": wins,
            "success_rate": wins / max(starts, 1), "region": capture_summary(rows),
            "runs": rows}  # fmt: skip


#: the perturbation measures a capture region is described by
CAPTURE_MEASURES = ("joint_rms_deg", "pitch_deg", "speed_mps", "pitch_spin_rad_s")


def capture_summary(rows: list[dict[str, Any]]) -> dict[str, dict[str, float | None]]:
    """Where a maneuver succeeds, per perturbation measure (its size, ``abs``): the success
    rate of the starts below and above the median, and the largest size that still
    succeeded."""
    out: dict[str, dict[str, float | None]] = {}
    ok = np.array([bool(r["landed"]) for r in rows])
    for key in CAPTURE_MEASURES:
        v = np.abs(np.array([float(r[key]) for r in rows]))
        if v.size == 0:
            continue
        small = v <= np.median(v)
        out[key] = {
            "median": float(np.median(v)),
            "success_below_median": float(ok[small].mean()) if small.any() else None,
            "success_above_median": float(ok[~small].mean()) if (~small).any() else None,
            "largest_success": float(v[ok].max()) if ok.any() else None,
        }
    return out


def _capture_one(job: tuple[Maneuver, Perturbation, str]) -> tuple[bool, float]:
    m, p, contact = job
    r = run_maneuver(m, perturbation=p, fps=10.0, contact=contact).report
    return bool(r["landed"] and not r["fell"] and r["status"] == "ok"), float(r["rotation_deg"])


def run_maneuver(
    maneuver: Maneuver,
    body: str | Path | None = None,
    *,
    on_tick: Callable[[float], None] | None = None,
    fps: float = 60.0,
    perturbation: Perturbation | None = None,
    contact: str = DEFAULT_CONTACT,
) -> AthleticsResult:
    """Simulate ``maneuver`` (on ``body`` instead of the maneuver's own, if given). The
    report: ``rotation_deg`` (the somersault rotation at the end, the trunk's pitch in the
    take-off plane unwrapped, backward < 0), ``rotation_at_touchdown_deg``, ``twist_deg``,
    ``landed``, ``fell``, the take-off angular momentum and its drift in the air, the peak
    somersault angular velocity, the phases' transitions. ``perturbation`` starts it from a
    perturbed pose and velocity (:class:`Perturbation`; the capture regions). ``contact``: the
    athletics contact model (:data:`~reactmocap.athletics.scene.CONTACT_MODELS`)."""
    phases = [check_phase(p, f"{maneuver.name}: phase[{i + 1}]")
              for i, p in enumerate(maneuver.phases)]  # fmt: skip
    ath = athlete(body if body is not None else maneuver.body)
    bases = [CONTROLLERS[p.controller].build(p, ath) for p in phases]
    world = athletics_world(ath, backpack=maneuver.backpack, contact=contact)
    if perturbation is not None:
        perturbation.apply(world, ath)
    high = maneuver.platform
    platform = (lambda c: Platform(c, high)) if high > 0 else None
    # a dive's fall reaches 10-13 m/s: above the rollout's default kinetic-energy check
    ctx, seq, res = simulate(ath, world, bases, maneuver.seconds, behaviour=maneuver.name,
                              on_tick=on_tick, fps=fps, extra_from_ctx=platform,
                              energy_limit_per_kg=400.0 if high > 0 else 100.0)  # fmt: skip
    log = ctx.log.arrays()
    _, pelvis0 = standing_heights(ctx)
    t = log["t"]
    td, lift = ctx.touchdown_time, ctx.liftoff_time
    rot = log["rotation"]
    i_td = min(int(np.searchsorted(t, td)), t.size - 1) if td is not None else t.size - 1
    rep: dict[str, Any] = {
        "maneuver": maneuver.name,
        "phases": [p.controller for p in phases],
        "backpack_kg": maneuver.backpack,
        "rotation_deg": math.degrees(float(rot[-1])) if rot.size else 0.0,
        "rotation_at_touchdown_deg": math.degrees(float(rot[i_td])) if rot.size else 0.0,
        "twist_deg": math.degrees(float(log["twist"][-1])) if rot.size else 0.0,
        "twist_at_touchdown_deg": math.degrees(float(log["twist"][i_td])) if rot.size else 0.0,
        "travel_m": float(log["com"][-1, 0] - log["com"][0, 0]) if rot.size else 0.0,
        "time_to_liftoff_s": lift,
        "liftoff_pitch_momentum": ctx.handover.get("liftoff_pitch_momentum"),
        # the COM's rise over standing, up to the first touchdown after lift-off
        "achieved_height_m": float(log["com"][: i_td + 1, 2].max() - log["com"][0, 2])
        if lift is not None else 0.0,
    }  # fmt: skip
    if lift is not None and td is not None and td > lift + 0.05:
        flight = (t > lift + 0.01) & (t < td - 0.01)
        m = log["momentum"][flight]
        if m.shape[0] > 2:
            ref = float(np.linalg.norm(m[0]))
            rep["flight_momentum_drift"] = float(np.abs(m - m[0]).max() / max(ref, 1e-9))
            rate = np.abs(np.gradient(rot[flight], t[flight]))
            rep["peak_trunk_rate_rad_s"] = float(rate.max())
        rep["flight_s"] = td - lift
    if "tumble_peak_rate" in ctx.handover:
        rep["peak_somersault_rate_rad_s"] = ctx.handover["tumble_peak_rate"]
        rep["tumble_min_inertia_kgm2"] = ctx.handover["tumble_min_inertia"]
    steps = ctx.handover.get("steps")
    if isinstance(steps, list) and steps:  # the balance's steps (Step): when, how far, the foot
        rep["steps"] = [dict(r) for r in steps]
    if "unsettled_s" in ctx.handover:  # a balance phase timed out before it settled
        rep["unsettled_s"] = ctx.handover["unsettled_s"]
    if "tumble_twist_undone" in ctx.handover:  # when the tilt twist's throw was undone
        rep["twist_undone_s"] = ctx.handover["tumble_twist_undone"]
    if high > 0:  # judged at the water: entry angle, rotation and twist there
        rep.update(entry_report(ctx, high, res.status == "ok"))
        rep["touchdown_s"] = None
    else:
        rep.update(landing_report(ctx, log, pelvis0))
        if any(p.controller == "handspring" for p in phases):  # the hands' contacts are no fall
            rep.update(handspring_report(ctx, log, pelvis0))
    rep.update(plausibility_report(ctx, ath, 0.0, np.inf))
    if contact != DEFAULT_CONTACT:  # (the default's report is as before the option)
        rep["contact"] = contact
    result = athletics_result(maneuver.name, ath, ctx, seq, res, rep)
    return result
