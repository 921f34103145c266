"""Scenario files (TOML): who plays what, where, and what hits them.

Validated once at load time with errors that name the file and field. Relative paths (the
library, clip files) resolve against the scenario file's folder first, then the working folder.
Angles are degrees in the file and radians inside.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import MISSING, dataclass, field, fields, replace
from pathlib import Path
from typing import Any, Literal

from reactmocap.errors import ConfigError
from reactmocap.io import read_toml

__all__ = [
    "MODES",
    "SIM1_MODES",
    "AttackerSpec",
    "CharacterSpec",
    "ImpactSpec",
    "ResponseConfig",
    "Scenario",
    "load_scenario",
    "parse_scenario",
]

SIM1_MODES = ("yielding", "holding", "passive")
MODES = ("blend", "physical")


@dataclass(frozen=True)
class CharacterSpec:
    """A character playing ``clip`` from ``start`` seconds, turned to ``facing_deg`` (heading
    from +X, counter-clockwise about +Z) with its root over ``position`` (x, y) at that time."""

    clip: str
    start: float = 0.0
    facing_deg: float = 0.0
    position: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class AttackerSpec(CharacterSpec):
    facing_deg: float = 180.0
    position: tuple[float, float] = (0.9, 0.0)


@dataclass(frozen=True)
class ImpactSpec:
    """An explicit force on the recipient: ``force`` N (world frame) on ``body`` at ``point``
    (body-local metres) from ``at`` seconds after the scenario start for ``duration``."""

    body: str = "chest"
    force: tuple[float, float, float] = (-350.0, 0.0, 0.0)
    at: float = 0.5
    duration: float = 0.1
    point: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class ResponseConfig:
    """The paper's defaults (Zordan et al. 2005), each overridable from ``[response]``."""

    reaction_delay: float = 0.15  # s, human reaction time 0.1-0.2 s
    #: the recipient's controller in Simulation 1 and 2, and the attacker's in both (keys of
    #: ``reactmocap.sim.controllers.CONTROLLERS``); the paper's PD servo by default
    sim1_controller: str = "pd"
    sim2_controller: str = "pd"
    attacker_controller: str = "pd"
    #: joint stiffness (1/s^2) and damping (1/s) of those controllers; unset: each
    #: controller's own default (the registry's table; ``pd``: kp 4000, kv critical)
    kp: float | None = None
    kv: float | None = None
    #: the largest joint torque (N m) of the controllers that plan torques (``wholebody``,
    #: through the servo's feed-forward, which nothing else limits); 0: none
    torque_limit: float = 0.0
    friction_sim1: float = 1.0
    #: Simulation 2's friction on the recipient's limbs (the paper's 0.5 "to allow foot
    #: slippage"); its trunk keeps ``friction_sim1``, so a fallen body does not slide off where
    #: Simulation 1's lay, where the search placed the found clip
    friction_sim2: float = 0.5
    #: Simulation 1: ``yielding`` (the recipient gives way to the hit with its stiffness cut to
    #: ``yield_gain`` for the reaction delay, holding its pose at impact, then recovers over
    #: ``yield_recover`` s; Simulation 2 keeps the same passive phase), ``holding`` (keeps
    #: tracking the old clip at full stiffness) or ``passive`` (a ragdoll from the impact on)
    sim1_mode: Literal["yielding", "holding", "passive"] = "yielding"
    yield_gain: float = 0.1
    yield_recover: float = 0.3
    sim1_duration: float = 1.0  # s after the impact
    search_start: float = 0.1  # s after the impact
    #: an impulse (N s) from which the recipient reacts: its own clip cannot be the
    #: continuation within ``reaction_delay + active_min`` s of the impact (below it, carrying
    #: on with the own clip is right)
    react_impulse: float = 5.0
    active_min: float = 0.2
    #: after a hit from ``react_impulse`` on, windows of the recipient's own clip within this
    #: many seconds of its undisturbed time cannot be the continuation (s)
    own_clip_margin: float = 1.0
    search_end: float = 1.0
    contact_shift_max: float = 0.25  # s the search start moves later while contact lasts
    attacker_follow: float = 0.1  # s the attacker follows its own simulation
    #: kp (1/s^2) of a NON-PHYSICAL root assist holding the attacker on its clip's path until
    #: it first touches the recipient (0: off), for strikes no body performs on its own
    attacker_assist: float = 0.0
    attacker_blend: float = 0.3  # s to blend the attacker back to its clip
    tail: float = 1.0  # s of the found clip played after landing
    top_k: int = 5
    timestep: float = 0.0005
    total_mass: float = 75.0
    #: pin planted feet that slide during the transition (two-bone IK; not in the paper)
    foot_lock: bool = True
    #: ``blend``: the paper's final blend lands on the found clip at the match time, whatever
    #: the simulation did; ``physical``: Simulation 2 runs on past the match, tracking the
    #: found clip, until the body is within ``land_position`` m (pelvis), ``land_angle`` rad
    #: (root turn) and ``land_joint`` rad (every joint) of it; the blend then only closes that
    #: small gap. If it is not there within ``land_within`` s, the report warns and the blend
    #: closes what is left
    mode: Literal["blend", "physical"] = "blend"
    land_position: float = 0.05
    land_angle: float = 0.17
    land_joint: float = 0.1
    land_within: float = 1.5
    #: physical mode: the landing check also compares the body with the found clip up to this
    #: many seconds ahead of or behind the path (a time warp: a hit body follows the clip a
    #: little late or early); it lands on the nearest frame, and the found clip plays on from
    #: there (0: the path's own frame only)
    land_warp: float = 0.2
    #: physical mode: from the match on, Simulation 2's whole-body tracker holds the joints
    #: this many times stiffer (damping times its root; 1: as built), so the hit body settles
    #: onto the found clip's pose before it drifts off it (``docs/benchmarks.md``)
    land_stiffness: float = 6.0
    #: physical mode: a body that does not land is simulated again toward the same found clip
    #: with the whole-body tracker's capture-point balance steps lasting this many seconds
    #: (before the search's next-best windows, ``land_tries``), and the closer of the two
    #: landings wins (0: no such retry)
    land_step_time: float = 0.2
    #: physical mode: a body that does not land is re-planned first: the search runs again on
    #: Simulation 2's body, over windows starting from the match to this many seconds after it,
    #: and Simulation 2 runs again along the first path eased into the clip so found (0: no
    #: re-plan)
    land_replan: float = 0.3
    #: physical mode: when the body does not land, Simulation 2 runs again toward the search's
    #: next-best windows of other clips, up to ``land_tries`` continuations in all, and the one
    #: the body came closest to (its landing gap over the tolerances) wins: a continuation the
    #: body can reach rather than the nearest window to Simulation 1. Blend mode: the same
    #: when the final blend would turn a joint or move the root beyond the warning thresholds,
    #: and the continuation whose final blend corrects least (over those thresholds) wins;
    #: where fewer other clips matched, the found clip's next-best windows at earlier starts
    #: fill the tries. Either way the others are searched and simulated only where the first
    #: would warn
    land_tries: int = 3
    #: blend mode: Simulation 2 tracks the found clip up to this many seconds past the match,
    #: and the final blend lands on the frame where it corrects least (``final.settle``: its
    #: largest joint turn and pelvis shift, each over its warning threshold), not at the match
    #: (0: at the match, the paper). Only where the final blend at the match would warn (joint
    #: turn or root shift over the thresholds): Simulation 2 then runs again, this much longer
    blend_settle: float = 0.5
    #: blend mode: a found clip that falls is moved on the ground so that its pelvis is over
    #: Simulation 2's at the landing (the search placed it over Simulation 1's at the match,
    #: and a falling body travels on: the real walkers kicked lay 0.4-0.55 m past it; a
    #: standing clip keeps its place); physical mode: any found clip, moved at most
    #: ``land_position`` (the body landed within that of it: the final blend then corrects the
    #: height, not the ground offset); the report gives the shift (``transition.found_shift_m``)
    blend_place: bool = True
    #: blend mode: the final blend corrects only the gap between Simulation 2 and the found
    #: clip at the landing, each joint's turn growing linearly over the transition as the root
    #: offset does (the paper's root; the physical mode's way), so the transition stays the
    #: physics'; false: each frame is slerped toward what Simulation 2 was asked to do there,
    #: its tracking error corrected along the way (a foot or an arm mid-fall 0.7-1.0 rad on
    #: the real recipients)
    blend_end_gap: bool = True


@dataclass(frozen=True)
class Scenario:
    library: Path
    recipient: CharacterSpec
    attacker: AttackerSpec | None = None
    impact: ImpactSpec | None = None
    response: ResponseConfig = field(default_factory=ResponseConfig)
    source: Path | None = None
    name: str = "scenario"
    #: body-part rules TOML for skeletons the name rules cannot map
    parts: Path | None = None

    def with_changes(self, **changes: Any) -> Scenario:
        return replace(self, **changes)


_TOP_KEYS = {"library", "recipient", "attacker", "impact", "response", "name", "parts"}


class _Reader:
    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, where: str, msg: str) -> ConfigError:
        return ConfigError(f"{self.source}: {where}: {msg}")

    def table(self, data: Mapping[str, Any], key: str) -> dict[str, Any]:
        value = data[key]
        if not isinstance(value, dict):
            raise self.fail(f"[{key}]", f"expected a table, got {type(value).__name__}")
        return value

    def number(
        self, where: str, value: Any, *, positive: bool = False, min_: float | None = None
    ) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(where, f"expected a number, got {value!r}")
        v = float(value)
        if not math.isfinite(v):
            raise self.fail(where, f"expected a finite number, got {value!r}")
        if positive and v <= 0:
            raise self.fail(where, f"expected a number > 0, got {value!r}")
        if min_ is not None and v < min_:
            raise self.fail(where, f"expected a number >= {min_}, got {value!r}")
        return v

    def vector(self, where: str, value: Any, n: int) -> tuple[float, ...]:
        if not isinstance(value, list) or len(value) != n:
            raise self.fail(where, f"expected a list of {n} numbers, got {value!r}")
        return tuple(self.number(f"{where}[{i}]", v) for i, v in enumerate(value))

    def controller(self, where: str, value: Any) -> str:
        from reactmocap.sim.controllers import CONTROLLERS

        if value not in CONTROLLERS:
            raise self.fail(where, f"expected one of {sorted(CONTROLLERS)}, got {value!r}")
        return str(value)

    def string(self, where: str, value: Any) -> str:
        if not isinstance(value, str) or not value:
            raise self.fail(where, f"expected a non-empty string, got {value!r}")
        return value

    def build(self, cls: type, section: str, raw: Mapping[str, Any]) -> Any:
        known = {f.name: f for f in fields(cls)}
        unknown = sorted(set(raw) - set(known))
        if unknown:
            raise self.fail(
                f"[{section}]", f"unknown key(s) {unknown}; valid keys are {sorted(known)}"
            )
        kwargs: dict[str, Any] = {}
        defaults = cls.__dataclass_fields__  # type: ignore[attr-defined]
        for name, value in raw.items():
            where = f"[{section}].{name}"
            ftype = str(defaults[name].type)
            if name == "clip" or name == "body":
                kwargs[name] = self.string(where, value)
            elif name.endswith("_controller"):
                kwargs[name] = self.controller(where, value)
            elif name in ("sim1_mode", "mode"):
                options = SIM1_MODES if name == "sim1_mode" else MODES
                if value not in options:
                    raise self.fail(where, f"expected one of {list(options)}, got {value!r}")
                kwargs[name] = value
            elif ftype == "bool":
                if not isinstance(value, bool):
                    raise self.fail(where, f"expected true or false, got {value!r}")
                kwargs[name] = value
            elif "tuple[float, float, float]" in ftype:
                kwargs[name] = self.vector(where, value, 3)
            elif "tuple[float, float]" in ftype:
                kwargs[name] = self.vector(where, value, 2)
            elif ftype == "int":
                if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                    raise self.fail(where, f"expected a positive integer, got {value!r}")
                kwargs[name] = value
            else:
                nonneg = name in {"start", "at", "reaction_delay", "search_start", "tail",
                                  "contact_shift_max", "attacker_follow", "attacker_blend",
                                  "friction_sim1", "friction_sim2", "kv", "yield_gain",
                                  "react_impulse", "active_min", "own_clip_margin", "attacker_assist",
                                  "yield_recover", "land_within", "land_warp", "blend_settle", "land_step_time",
                                  "land_replan",
                                  "torque_limit"}  # fmt: skip
                positive = name in {"duration", "kp", "sim1_duration", "search_end", "timestep",
                                    "total_mass", "land_position", "land_angle",
                                    "land_joint", "land_stiffness"}  # fmt: skip
                kwargs[name] = self.number(
                    where, value, positive=positive, min_=0.0 if nonneg else None
                )
        missing = [
            n
            for n, f in known.items()
            if f.default is f.default_factory is MISSING and n not in kwargs
        ]
        if missing:
            raise self.fail(f"[{section}]", f"missing required key(s) {missing}")
        return cls(**kwargs)


def parse_scenario(
    data: Mapping[str, Any], *, source: str = "<scenario>", base_dir: Path | None = None
) -> Scenario:
    """Validate a scenario mapping (as read from TOML)."""
    r = _Reader(source)
    unknown = sorted(set(data) - _TOP_KEYS)
    if unknown:
        raise r.fail("top level", f"unknown key(s) {unknown}; valid keys are {sorted(_TOP_KEYS)}")
    if "library" not in data:
        raise r.fail("library", "missing: a folder of BVH clips or a saved search index")
    if "recipient" not in data:
        raise r.fail("[recipient]", "missing: the character that is hit")
    library = _resolve(r, "library", r.string("library", data["library"]), base_dir)
    recipient = r.build(CharacterSpec, "recipient", r.table(data, "recipient"))
    attacker = (
        r.build(AttackerSpec, "attacker", r.table(data, "attacker")) if "attacker" in data else None
    )
    impact = r.build(ImpactSpec, "impact", r.table(data, "impact")) if "impact" in data else None
    if impact is not None:
        from reactmocap.errors import ReactMocapError
        from reactmocap.sim.impacts import Impact

        try:  # the body, the force's size: checked as the simulation will
            Impact(impact.body, force=impact.force, point=impact.point, duration=impact.duration)
        except ReactMocapError as exc:
            raise r.fail("[impact]", str(exc)) from None
    if attacker is None and impact is None:
        raise r.fail("top level", "give either an [attacker] or an [impact]")
    if attacker is not None and impact is not None:
        raise r.fail("top level", "give either an [attacker] or an [impact], not both")
    response = (
        r.build(ResponseConfig, "response", r.table(data, "response"))
        if "response" in data
        else ResponseConfig()
    )
    if response.search_end <= response.search_start:
        raise r.fail("[response].search_end", "must be greater than search_start")
    name = r.string("name", data["name"]) if "name" in data else Path(source).stem
    parts = None
    if "parts" in data:
        parts = _resolve(r, "parts", r.string("parts", data["parts"]), base_dir)
        from reactmocap.library.bodyparts import load_rules

        load_rules(parts)  # a bad rules file fails here, naming it
    return Scenario(library, recipient, attacker, impact, response, Path(source), name, parts)


def _resolve(r: _Reader, where: str, value: str, base_dir: Path | None) -> Path:
    p = Path(value)
    candidates = [p] if p.is_absolute() else ([base_dir / p] if base_dir else []) + [Path.cwd() / p]
    for c in candidates:
        if c.exists():
            return c.resolve()
    raise r.fail(where, f"{value!r} not found (looked in {[str(c) for c in candidates]})")


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file."""
    p = Path(path)
    data = read_toml(p, "scenario")
    return parse_scenario(data, source=str(p), base_dir=p.parent)
