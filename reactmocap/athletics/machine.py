"""The athletic state-machine base over the engine's :class:`~reactmocap.sim.controllers.
StateMachine`: a shared context per run (the athlete's rig and senses, a per-tick log), exit
events for athletes (touchdown, lift-off, apex, time, joint angle), and basis controllers as
groups of states that hand over to the next one (:data:`NEXT`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import Athlete
from reactmocap.athletics.rig import Rig, joint_index
from reactmocap.athletics.senses import Senses
from reactmocap.errors import ConfigError
from reactmocap.sim.controllers.base import FunctionController
from reactmocap.sim.controllers.machine import Event, State, after
from reactmocap.sim.world import World

__all__ = [
    "NEXT",
    "Basis",
    "Context",
    "Log",
    "after",
    "angle",
    "apex",
    "law",
    "liftoff",
    "touchdown",
]

F64 = NDArray[np.float64]
#: an exit target meaning "hand over to the next basis controller of the sequence"
NEXT = "<next>"


@dataclass
class Log:
    """What every control tick saw: time, COM, COM velocity, ground reaction force, the feet
    in contact, the state, and the servo torques and joint velocities (for the strength
    check); turned into arrays by :meth:`arrays`."""

    rows: list[tuple[float, F64, F64, F64, int, str]] = field(default_factory=list)
    torques: list[F64] = field(default_factory=list)
    powers: list[F64] = field(default_factory=list)
    #: per tick: whether anything but the feet touched the floor, and the pelvis height above the floor plane
    others: list[bool] = field(default_factory=list)
    pelvis: list[float] = field(default_factory=list)
    #: per tick: horizontal distance (m) of the COM from the support centre
    offsets: list[float] = field(default_factory=list)
    #: per tick: whole-body angular momentum about the COM (kg m^2/s, world)
    momentum: list[F64] = field(default_factory=list)
    #: per tick: somersault rotation so far (rad, unwrapped trunk pitch in the starting
    #: heading's sagittal plane, > 0 forward) and twist so far (rad, about the trunk's axis)
    rotation: list[float] = field(default_factory=list)
    twist: list[float] = field(default_factory=list)
    #: per tick: the pelvis-to-head line (world, unit)
    trunk: list[F64] = field(default_factory=list)

    def arrays(self) -> dict[str, NDArray]:
        if not self.rows:
            z = np.zeros(0)
            return {"t": z, "com": np.zeros((0, 3)), "com_vel": np.zeros((0, 3)),
                    "grf": np.zeros((0, 3)), "feet": z.astype(int), "state": np.array([]),
                    "torque": np.zeros((0, 15)), "power": np.zeros((0, 15)),
                    "others": z.astype(bool), "pelvis": z, "offset": z,
                    "momentum": np.zeros((0, 3)), "rotation": z, "twist": z,
                    "trunk": np.zeros((0, 3))}  # fmt: skip
        t, com, vel, grf, feet, state = zip(*self.rows)
        return {
            "t": np.array(t), "com": np.array(com), "com_vel": np.array(vel),
            "grf": np.array(grf), "feet": np.array(feet), "state": np.array(state),
            "torque": np.array(self.torques), "power": np.array(self.powers),
            "others": np.array(self.others), "pelvis": np.array(self.pelvis),
            "offset": np.array(self.offsets), "momentum": np.array(self.momentum),
            "rotation": np.array(self.rotation), "twist": np.array(self.twist),
            "trunk": np.array(self.trunk),
        }  # fmt: skip


@dataclass(eq=False)
class Context:
    """One athlete in one world, shared by the basis controllers of a run."""

    world: World
    athlete: Athlete
    character: int
    rig: Rig
    senses: Senses
    #: physics steps between control ticks
    control_every: int = 4
    log: Log = field(default_factory=Log)
    #: times of the latest lift-off and touchdown (None until they happen)
    liftoff_time: float | None = None
    touchdown_time: float | None = None
    #: the standing COM height (m above the support), measured before any leap
    standing_com: float | None = None
    #: anything a basis controller hands to the next (e.g. the landing's balance posture)
    handover: dict[str, object] = field(default_factory=dict)
    #: somersault rotation and twist so far (rad; see :class:`Log`), kept by the sequencer
    rotation: float = 0.0
    twist: float = 0.0
    #: the heading (rad) whose sagittal plane the rotation is measured in (the first tick's)
    heading0: float | None = None

    @classmethod
    def make(
        cls, world: World, athlete: Athlete, character: int = 0, control_every: int = 4
    ) -> Context:
        if not (isinstance(control_every, int) and control_every >= 1):
            raise ConfigError(f"control_every must be an int >= 1, got {control_every!r}")
        return cls(world, athlete, character, Rig(world, athlete, character),
                   Senses(world, athlete, character), control_every)  # fmt: skip

    def sense(self, t: float) -> Senses:
        self.senses.update(t)
        return self.senses


# ---------------------------------------------------------------------------------- events
def touchdown(ctx: Context, both: bool = False) -> Event:
    """Fires when a foot (``both``: both feet) touches the floor; records the time."""

    def event(_w: World, t: float, _t_in: float) -> bool:
        s = ctx.sense(t)
        hit = bool(s.foot_contact.all() if both else s.foot_contact.any()) or bool(s.other_contact)
        if hit:
            ctx.touchdown_time = t
        return hit

    return event


def liftoff(ctx: Context, ticks: int = 2, rising: float = 0.1) -> Event:
    """Fires when nothing of the athlete has touched the floor for ``ticks`` control ticks in
    a row while the COM rises faster than ``rising`` m/s (a jolt that lifts the feet for a
    moment is not a take-off); records the time the feet left."""
    seen = {"count": 0, "since": 0.0}

    def event(_w: World, t: float, _t_in: float) -> bool:
        s = ctx.sense(t)
        if s.airborne and float(s.com_vel @ s.floor_normal) > rising:
            if seen["count"] == 0:
                seen["since"] = t
            seen["count"] += 1
        else:
            seen["count"] = 0
        if seen["count"] >= ticks:
            ctx.liftoff_time = seen["since"]
            seen["count"] = 0
            return True
        return False

    return event


def apex(ctx: Context) -> Event:
    """Fires when the centre of mass stops rising (vertical velocity <= 0)."""
    return lambda _w, t, _t_in: bool(ctx.sense(t).com_vel[2] <= 0.0)


def angle(ctx: Context, joint: str, axis: int, threshold: float, above: bool = True) -> Event:
    """Fires when the anatomical angle of ``joint`` about ``axis`` (0 pitch, 1 roll, 2 yaw)
    goes above (or below) ``threshold`` radians."""
    j = joint_index(joint)
    if axis not in (0, 1, 2):
        raise ConfigError(f"angle axis must be 0 (pitch), 1 (roll) or 2 (yaw), got {axis!r}")

    def event(_w: World, _t: float, _t_in: float) -> bool:
        a = float(ctx.rig.current_angles()[j, axis])
        return a > threshold if above else a < threshold

    return event


# ---------------------------------------------------------------------------------- basis
class Basis:
    """A basis controller: a named group of states on a shared :class:`Context`. States exit to
    each other by their local names, or to :data:`NEXT` to hand over to the next basis
    controller of a sequence (the rig's targets carry on from where they are)."""

    name: str = "basis"
    initial: str = ""

    def states(self, ctx: Context) -> list[State]:
        raise NotImplementedError


def law(fn: Callable[[World, float], None], control_every: int) -> FunctionController:
    """A state's per-tick law from a function."""
    return FunctionController(fn, control_every)
