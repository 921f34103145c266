"""The controller registry: every way to drive a character, keyed by name, with the one table of
its parameters' defaults. ``build(name, world, reference, params)`` makes one; an unknown name
or parameter lists the valid ones. Adding a controller is a module plus a row here."""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.library.motion import Motion
from reactmocap.sim.controllers.balance import StanceBalance
from reactmocap.sim.controllers.base import Controller, Group
from reactmocap.sim.controllers.pd import Passive, PDTracker
from reactmocap.sim.controllers.predictive import PredictiveTracker
from reactmocap.sim.controllers.root_assist import RootAssist
from reactmocap.sim.controllers.wholebody import WholeBodyTracker
from reactmocap.sim.reference import ReferencePath
from reactmocap.sim.world import World

__all__ = [
    "CONTROLLERS",
    "WHOLE_CLIP",
    "ControllerSpec",
    "Factory",
    "build",
    "controller_help",
    "controller_spec",
    "register",
]

Param = float | int | None
Reference = Motion | ReferencePath
#: ``factory(world, character, reference, start, params)``; ``params`` complete (defaults filled)
Factory = Callable[[World, int, Reference, float, dict[str, Any]], Controller]


def _options(*classes: type) -> tuple[str, ...]:
    """Keyword-only constructor parameters that have defaults of their own (tuning options)."""
    return tuple(
        p.name
        for cls in classes
        for p in inspect.signature(cls).parameters.values()
        if p.kind is p.KEYWORD_ONLY
        and p.default is not p.empty
        and p.name not in ("kv", "kv_joint")
    )


@dataclass(frozen=True)
class ControllerSpec:
    """A registered controller: what it is, its gains and rates with their defaults (``None``:
    derived, e.g. critical damping), its other options (their defaults live in the
    constructors), how to build it, and whether only joint torques act."""

    name: str
    description: str
    defaults: Mapping[str, Param]
    factory: Factory
    options: tuple[str, ...] = ()
    physical: bool = True

    def params(self, given: Mapping[str, Any] | None) -> dict[str, Any]:
        """``given`` over the defaults; ``None`` values mean the default."""
        out = dict(self.defaults)
        for key, value in (given or {}).items():
            if key not in self.defaults and key not in self.options:
                raise ConfigError(
                    f"controller {self.name!r} has no parameter {key!r}; its parameters are "
                    f"{sorted({*self.defaults, *self.options})}"
                )
            if value is not None:
                out[key] = value
        return out

    def help(self) -> str:
        shown = ", ".join(
            f"{k} {'critical' if v is None and k.startswith('kv') else v}"
            for k, v in self.defaults.items()
            if k in ("kp", "kv", "control_every")
        )
        return f"{self.name}: {self.description} ({shown})"


def _pd(world: World, c: int, ref: Reference, start: float, p: dict[str, Any]) -> Controller:
    return PDTracker(world, c, ref, start, **p)


def _balance(world: World, c: int, ref: Reference, start: float, p: dict[str, Any]) -> Controller:
    pd = {k: p.pop(k) for k in ("kp", "kv", "refresh_every")}
    every = p["control_every"]
    return Group([PDTracker(world, c, ref, start, control_every=every, **pd),
                  StanceBalance(world, c, ref, start, **p)])  # fmt: skip


def _wholebody(world: World, c: int, ref: Reference, start: float, p: dict[str, Any]) -> Controller:
    return WholeBodyTracker(world, c, ref, start, kp_joint=p.pop("kp"), kv_joint=p.pop("kv"), **p)


def _predictive(
    world: World, c: int, ref: Reference, start: float, p: dict[str, Any]
) -> Controller:
    wb = {k: p.pop(k) for k in ("kp", "kv", "servo_kv", "control_every")}
    # ``whole_clip``: steer the whole-clip tracker (``WHOLE_CLIP``), not the window one
    options: dict[str, Any] = dict(WHOLE_CLIP) if p.pop("whole_clip", False) else {}
    tracker = WholeBodyTracker(
        world, c, ref, start, kp_joint=wb["kp"], kv_joint=wb["kv"],
        servo_kv=wb["servo_kv"], control_every=wb["control_every"],
        hold_balance=p.pop("hold_balance", False), **options,
    )  # fmt: skip
    return PredictiveTracker(tracker, **p)


def _passive(world: World, c: int, ref: Reference, start: float, p: dict[str, Any]) -> Controller:
    del ref, start
    return Passive(world, c, **p)


def _root_assist(
    world: World, c: int, ref: Reference, start: float, p: dict[str, Any]
) -> Controller:
    return RootAssist(world, c, ref, start, **p)


def _athletic_balance(
    world: World, c: int, ref: Reference, start: float, p: dict[str, Any]
) -> Controller:
    # imported here: the engine does not import the layer above it at load time
    from reactmocap.athletics.controller import athletic_balance

    return athletic_balance(world, c, ref, start, p)


def _bicycle_rider(
    world: World, c: int, ref: Reference, start: float, p: dict[str, Any]
) -> Controller:
    from reactmocap.athletics.controller import bicycle_rider

    return bicycle_rider(world, c, ref, start, p)


_PD = {"kp": 4000.0, "kv": None, "control_every": 10, "refresh_every": 10}
_WHOLEBODY = {"kp": 1000.0, "kv": None, "servo_kv": 20.0, "control_every": 4}
#: the whole-body tracker's options for whole clips (``track``, ``push``; see
#: ``docs/tracking.md``): corners within 3 mm support, a foot skimming the floor faster than
#: 0.5 m/s is not planted, a heel raised 2 cm is let go, the ground path re-anchored to the
#: feet (0.1 s), the targets keeping the capture point 5 cm inside them (0.1 s) and the chest's
#: world turn held as tracked (weight 30, as the pelvis; after a push they give while the mocap
#: stands and the capture point is off, back over 0.5 s: the hip strategy a standing body
#: needs), the pelvis position servo at half stiffness (50 1/s^2; 30 once a walk is pushed,
#: but for a push against the walk: ``kp_root_against``), a pushed walk's clip played faster
#: for 1.5 s (``warp_gain``, ``warp_for``),
#: and after a push while the mocap stands a hip strategy (``hip_weight``) near the feet's edge
#: and balance steps once the capture point leaves them (``step_pushed``; the pelvis lowered so
#: the step reaches the floor, the next step by the other foot or by one lifted off the floor,
#: a short step quicker).
#: Without them
#: the tracker follows the captured world path, as the 1 s benchmark windows, predictive
#: sampling and the response pipeline's physical mode expect; ``"predictive"`` steers the
#: tracker with them when asked (``whole_clip``: ``docs/tracking.md``, "Twelfth pass").
WHOLE_CLIP: Mapping[str, Param] = MappingProxyType(
    {"touch": 0.003, "slide_speed": 0.5, "roll_band": 0.02, "anchor_tau": 0.1, "balance_tau": 0.1,
     "balance_margin": 0.05, "trunk_weight": 30.0, "trunk_give": 0.5, "kp_root": 50.0,
     "kp_root_pushed": 30.0, "hip_weight": 300.0, "hip_tilt_step": 0.5, "warp_gain": 0.8,
     "step_pushed": True, "step_leg": 0.9, "step_alternate": True, "step_short": 0.3,
     "place_pushed": 1.0, "step_ease": 0.1, "kp_root_against": 50.0, "warp_for": 1.5}
)  # fmt: skip

_REGISTRY: dict[str, ControllerSpec] = {
    "pd": ControllerSpec(
        "pd", "the paper's inertia-scaled PD servo toward the reference joints (no balance)",
        _PD, _pd),
    "balance": ControllerSpec(
        "balance", "the PD servo plus stance-leg balance (COM and trunk servos)",
        _PD, _balance, _options(StanceBalance)),
    "wholebody": ControllerSpec(
        "wholebody", "inverse dynamics with optimised ground forces (pelvis tracked through "
        "the feet)", _WHOLEBODY, _wholebody, _options(WholeBodyTracker)),
    "predictive": ControllerSpec(
        "predictive", "the whole-body tracker steered by predictive sampling (looks 0.5 s "
        "ahead; ~40x slower)", _WHOLEBODY, _predictive,
        (*_options(PredictiveTracker), "hold_balance", "whole_clip")),
    "passive": ControllerSpec(
        "passive", "no control: the servo off, joint damping and limits only (a ragdoll)",
        {"control_every": 10}, _passive),
    "root_assist": ControllerSpec(
        "root_assist", "NON-PHYSICAL external pelvis wrench toward the reference (an add-on "
        "to another controller)", {"kp": 100.0, "kv": None, "control_every": 1}, _root_assist,
        physical=False),
    "athletic_balance": ControllerSpec(
        "athletic_balance", "the thesis's balance (athletics, ch. 7): COM over the feet by ankle "
        "and hip offsets; does not follow the clip", {"control_every": 8},
        _athletic_balance, ("pitch", "leg", "com_offset_x", "com_offset_y")),
    "bicycle_rider": ControllerSpec(
        "bicycle_rider", "Hodgins et al. 1995's bicycle rider (athletics): speed and heading "
        "through the pedals and handlebars, on the bicycle the character is mounted on in a "
        "cycling World; does not follow the clip", {"control_every": 4},
        _bicycle_rider, ("speed", "heading", "kp", "arm_scale", "leg_scale")),
}  # fmt: skip
#: every registered controller (read-only view; :func:`register` adds); the gains and rates
#: here are the only defaults (the CLI help and the scenario docs print them from this table)
CONTROLLERS: Mapping[str, ControllerSpec] = MappingProxyType(_REGISTRY)


def register(spec: ControllerSpec) -> ControllerSpec:
    """Add a controller defined outside this package (a plugin; the package's own are rows of
    the table above). Its name must be new."""
    if not isinstance(spec, ControllerSpec):
        raise ConfigError(f"register() takes a ControllerSpec, got {type(spec).__name__}")
    if spec.name in _REGISTRY:
        raise ConfigError(f"a controller named {spec.name!r} is already registered")
    _REGISTRY[spec.name] = spec
    return spec


def controller_spec(name: str) -> ControllerSpec:
    """The registered controller ``name``; an unknown name lists the valid ones."""
    try:
        return CONTROLLERS[name]
    except KeyError:
        raise UnknownKeyError(
            f"unknown controller {name!r}; valid controllers are {sorted(CONTROLLERS)}"
        ) from None


def build(
    name: str,
    world: World,
    reference: Reference,
    params: Mapping[str, Any] | None = None,
    *,
    character: int = 0,
    start: float = 0.0,
) -> Controller:
    """The controller ``name`` for ``character`` of ``world``, following ``reference`` (a
    Motion on the character's skeleton or a :class:`ReferencePath`) from its time ``start``
    at rollout time 0, with ``params`` over the table's defaults."""
    spec = controller_spec(name)
    return spec.factory(world, character, reference, float(start), spec.params(params))


def controller_help(names: tuple[str, ...] | None = None) -> str:
    """One line per controller with its default gains (for ``--help`` texts)."""
    return "; ".join(CONTROLLERS[n].help() for n in (names or tuple(CONTROLLERS)))
