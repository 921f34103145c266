"""How the recipient takes a hit in the simulations: it gives way. At the impact its stiffness
drops to ``yield_gain`` and it holds its pose at the impact, with no active resistance, for the
reaction delay; then the stiffness recovers over ``yield_recover`` seconds (Zordan and Hodgins
2002: stiffness drops at impact, then recovers). Simulation 1 does only that; Simulation 2 does
the same and, after the delay, heads for the found clip."""

from __future__ import annotations

from collections.abc import Callable

from reactmocap.errors import ConfigError
from reactmocap.response.blend import smoothstep
from reactmocap.response.scenario import ResponseConfig
from reactmocap.sim.controllers import Controller, GainScalable, Holdable
from reactmocap.sim.world import World

__all__ = ["AssistUntilHit", "YieldOnImpact", "yield_schedule"]


def yield_schedule(cfg: ResponseConfig, impact: float) -> Callable[[float], float]:
    """Stiffness scale over time: 1 before ``impact``, ``yield_gain`` through the reaction
    delay, then back to 1 over ``yield_recover`` s (eased in and out)."""
    delay, low, ramp = cfg.reaction_delay, cfg.yield_gain, max(cfg.yield_recover, 1e-9)

    def scale(t: float) -> float:
        if t < impact:
            return 1.0
        return low + (1.0 - low) * float(smoothstep((t - impact - delay) / ramp))

    return scale


class YieldOnImpact:
    """``inner`` (tracking the old clip) until the character is hit, then yielding: it holds
    the clip's pose at that moment with the :func:`yield_schedule` on its gains. The hit is the
    first contact with the other character, or ``impact`` (rollout seconds) for an explicit
    force. :attr:`impact` is when it happened."""

    def __init__(self, inner: Controller, cfg: ResponseConfig, impact: float | None) -> None:
        if not (isinstance(inner, GainScalable) and isinstance(inner, Holdable)):
            raise ConfigError(f"{type(inner).__name__} cannot yield (no gains to scale)")
        self.inner = inner
        self.cfg = cfg
        self.explicit = impact
        self.control_every = inner.control_every
        self.impact: float | None = None
        self._scale: Callable[[float], float] = lambda _t: 1.0

    def reset(self, world: World) -> None:
        self.impact = None
        self.inner.reset(world)

    def control(self, world: World, t: float) -> None:
        if self.impact is None and (
            world.characters_touching() if self.explicit is None else t >= self.explicit - 1e-9
        ):
            self.impact = t
            self.inner.hold(t)  # type: ignore[attr-defined]
            self._scale = yield_schedule(self.cfg, t)
        self.inner.scale_gains(self._scale(t))  # type: ignore[attr-defined]
        self.inner.control(world, t)


class AssistUntilHit:
    """NON-PHYSICAL help for an attacker whose strike a body cannot perform on its own (the
    spinning kicks of real capture need several times the moment a foot can give): ``assist``
    (a root assist) holds the attacker's pelvis on its clip's path until it first touches the
    recipient, then lets go, so it never drives the strike through the body it hits. Ticks
    every step (the assist's rate)."""

    def __init__(self, assist: Controller, body: int) -> None:
        self.assist = assist
        self.body = body
        self.control_every = assist.control_every
        self.released = False

    def reset(self, world: World) -> None:
        self.released = False
        self.assist.reset(world)

    def control(self, world: World, t: float) -> None:
        if self.released:
            return
        if world.characters_touching():
            self.released = True
            world.data.xfrc_applied[self.body] = 0.0
            return
        self.assist.control(world, t)
