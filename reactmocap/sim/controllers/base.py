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

__all__ = ["Controller", "FunctionController", "Group", "check_character", "check_params"]


@runtime_checkable
class Controller(Protocol):
    """Anything the engine can tick."""

    #: physics steps between control ticks (>= 1)
    control_every: int

    def reset(self, world: World) -> None:
        """Prepare for a rollout starting from the world's current state."""

    def control(self, world: World, t: float) -> None:
        """Act at rollout time ``t`` (seconds since the rollout started)."""


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
