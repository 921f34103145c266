"""A test controller defined outside the package: PD tracking whose stiffness sways between two
gains, as a stand-in for anyone's own controller. One file plus one ``register`` call."""

from __future__ import annotations

from typing import Any

import numpy as np

from reactmocap.sim import PDTracker, World
from reactmocap.sim.controllers import ControllerSpec, register
from reactmocap.sim.controllers.registry import Reference


class SwayingPD:
    def __init__(self, world: World, character: int, ref: Reference, start: float, *,
                 kp: float, kv: float | None, control_every: int, period: float) -> None:  # fmt: skip
        self.pd = PDTracker(world, character, ref, start, kp=kp, kv=kv,
                            control_every=control_every, refresh_every=control_every)  # fmt: skip
        self.kp, self.period, self.character = kp, period, character
        self.control_every = control_every
        self.ticks = 0

    def reset(self, world: World) -> None:
        self.pd.reset(world)

    def control(self, world: World, t: float) -> None:
        self.ticks += 1
        scale = 1.0 + 0.5 * np.sin(2 * np.pi * t / self.period)
        world.servo.set_gains(self.kp * scale, None, self.character)
        self.pd.control(world, t)


def _build(world: World, c: int, ref: Reference, start: float, p: dict[str, Any]) -> SwayingPD:
    return SwayingPD(world, c, ref, start, **p)


SPEC = ControllerSpec(
    "swaying_pd", "test: PD with a stiffness that sways", {"kp": 3000.0, "kv": None,
    "control_every": 10, "period": 0.5}, _build,
)  # fmt: skip


def ensure_registered() -> ControllerSpec:
    from reactmocap.sim.controllers import CONTROLLERS

    return CONTROLLERS.get(SPEC.name) or register(SPEC)
