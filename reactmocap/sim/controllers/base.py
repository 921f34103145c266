"""The controller interface of the simulation engine.

A controller acts on a :class:`~reactmocap.sim.world.World` at control ticks, every
``control_every`` physics steps: :meth:`Controller.reset` once before a rollout's first step,
:meth:`Controller.control` at each tick with ``t`` the seconds since the rollout started. It
acts through the world: the servo's targets, gains and feed-forward, ``qfrc_applied`` or
``xfrc_applied``. Between ticks MuJoCo steps on its own.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Protocol, runtime_checkable

import numpy as np

from reactmocap.errors import ConfigError
from reactmocap.sim.world import World

__all__ = [
    "Controller",
    "FunctionController",
    "GainScalable",
    "Group",
    "Holdable",
    "Scheduled",
    "check_character",
    "check_params",
]


@runtime_checkable
class Controller(Protocol):
    """Anything the engine can tick."""

    #: physics steps between control ticks (>= 1)
    control_every: int

    def reset(self, world: World) -> None:
        """Prepare for a rollout starting from the world's current state."""

    def control(self, world: World, t: float) -> None:
        """Act at rollout time ``t`` (seconds since the rollout started)."""


@runtime_checkable
class GainScalable(Protocol):
    """A controller whose feedback gains can be scaled on the fly (a gain schedule)."""

    def scale_gains(self, scale: float) -> None:
        """Stiffness times ``scale`` (damping times its square root) from the next tick."""


@runtime_checkable
class Holdable(Protocol):
    """A controller following a clip that can stop the clip and hold its pose."""

    def hold(self, t: float) -> None:
        """From rollout time ``t`` on, follow the clip's pose at ``t``."""


class Scheduled:
    """``inner`` with its gains scaled by ``schedule(t)`` at each tick (e.g. yielding to an
    impact, then recovering)."""

    def __init__(self, inner: Controller, schedule: Callable[[float], float]) -> None:
        if not isinstance(inner, GainScalable):
            raise ConfigError(f"{type(inner).__name__} has no gains to schedule")
        self.inner = inner
        self.schedule = schedule
        self.control_every = inner.control_every

    def reset(self, world: World) -> None:
        self.inner.reset(world)

    def control(self, world: World, t: float) -> None:
        self.inner.scale_gains(self.schedule(t))  # type: ignore[attr-defined]
        self.inner.control(world, t)


class FunctionController:
    """A plain function ``f(world, t)`` as a controller (tests, quick experiments)."""

    def __init__(self, fn: Callable[[World, float], None], control_every: int = 1) -> None:
        if control_every < 1:
            raise ConfigError(f"control_every must be >= 1, got {control_every!r}")
        self.fn = fn
        self.control_every = int(control_every)

    def reset(self, world: World) -> None:
        del world

    def control(self, world: World, t: float) -> None:
        self.fn(world, t)


class Group:
    """Controllers that tick together, in order (e.g. a PD tracker setting targets, then a
    balance controller adding feed-forward to them)."""

    def __init__(self, controllers: Sequence[Controller]) -> None:
        if not controllers:
            raise ConfigError("a controller group needs at least one controller")
        every = {c.control_every for c in controllers}
        if len(every) != 1:
            raise ConfigError(f"grouped controllers must tick together, got {sorted(every)}")
        self.controllers = tuple(controllers)
        self.control_every = every.pop()

    def reset(self, world: World) -> None:
        for c in self.controllers:
            c.reset(world)

    def control(self, world: World, t: float) -> None:
        for c in self.controllers:
            c.control(world, t)

    def scale_gains(self, scale: float) -> None:
        for c in self.controllers:
            if isinstance(c, GainScalable):
                c.scale_gains(scale)

    def hold(self, t: float) -> None:
        for c in self.controllers:
            if isinstance(c, Holdable):
                c.hold(t)


def check_params(params: Mapping[str, float | None]) -> None:
    """Constructor check shared by controllers: every given value is finite and >= 0."""
    for name, v in params.items():
        if v is not None and not (np.isfinite(v) and v >= 0):
            raise ConfigError(f"{name} must be a finite number >= 0, got {v!r}")


def check_character(world: World, character: int) -> None:
    if not (isinstance(character, int) and 0 <= character < len(world.characters)):
        raise ConfigError(
            f"character {character!r} is not in the world (it has {len(world.characters)})"
        )
