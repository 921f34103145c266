"""The cycling scene, a :class:`~reactmocap.sim.world.Scene`: bicycles, whatever ties riders to
them, obstacle cylinders and a hill (the World's floor plane turned to a grade: the paper's
"sloped planes"). Contact bits: a ridden bicycle's wheels share their rider's bit (they touch
the floor, obstacles and other riders, never their own rider); obstacles touch everything."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bicycle import Bicycle
from reactmocap.errors import ConfigError
from reactmocap.sim.world import World

__all__ = ["CyclingScene", "Obstacle", "ScenePart", "Terrain"]

F64 = NDArray[np.float64]
#: contact bit of bicycles without a rider (they touch the floor and obstacles only)
BARE_BIT = 1 << 29


@dataclass(frozen=True)
class Terrain:
    """A plane rising ``grade`` (rise over run, 0.05 = 5%) toward heading ``direction`` (rad),
    at height 0 over the point ``origin`` ``(x, y)``."""

    grade: float = 0.0
    direction: float = 0.0
    origin: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.grade) and abs(self.grade) <= 0.3):
            raise ConfigError(f"grade must be within +-30% (0.3), got {self.grade!r}")
        if not math.isfinite(self.direction):
            raise ConfigError("terrain direction must be finite")

    @property
    def normal(self) -> F64:
        """``(3,)`` unit normal of the plane."""
        c, s = math.cos(self.direction), math.sin(self.direction)
        n = np.array([-self.grade * c, -self.grade * s, 1.0])
        return n / np.linalg.norm(n)

    @property
    def point(self) -> F64:
        return np.array([self.origin[0], self.origin[1], 0.0])

    def height(self, xy: F64) -> F64:
        """Ground height (m) at points ``(..., 2)``."""
        d = np.asarray(xy, dtype=np.float64) - self.origin
        return self.grade * (
            d[..., 0] * math.cos(self.direction) + d[..., 1] * math.sin(self.direction)
        )

    def quat(self) -> F64:
        """The floor geom's rotation: level turned to the grade."""
        n = self.normal
        axis = np.cross([0.0, 0.0, 1.0], n)
        s = float(np.linalg.norm(axis))
        if s < 1e-12:
            return np.array([1.0, 0.0, 0.0, 0.0])
        angle = math.atan2(s, float(n[2]))
        return np.r_[math.cos(angle / 2), math.sin(angle / 2) * axis / s]


@dataclass(frozen=True)
class Obstacle:
    """A vertical cylinder standing on the ground: centre ``(x, y)``, ``radius`` and ``height``
    (m)."""

    x: float
    y: float
    radius: float = 0.3
    height: float = 1.2

    def __post_init__(self) -> None:
        if not all(math.isfinite(v) for v in (self.x, self.y, self.radius, self.height)):
            raise ConfigError("obstacle x, y, radius and height must be finite")
        if not (0.05 <= self.radius <= 10.0 and 0.1 <= self.height <= 10.0):
            raise ConfigError(
                f"obstacle radius must be 0.05-10 m and height 0.1-10 m, got {self.radius}, "
                f"{self.height}"
            )


class ScenePart(Protocol):
    """Anything else in the scene (a rider's mount on its bicycle)."""

    def build(self, spec: mujoco.MjSpec) -> None: ...

    def bind(self, world: World) -> None: ...


class CyclingScene:
    """Bicycles (their contact bit: the rider's, ``riders[k]`` the character index riding
    bicycle ``k`` or ``None``), obstacles, the terrain and other parts (rider mounts)."""

    def __init__(
        self,
        bicycles: Sequence[Bicycle],
        *,
        terrain: Terrain | None = None,
        obstacles: Sequence[Obstacle] = (),
        parts: Sequence[ScenePart] = (),
        riders: Sequence[int | None] = (),
    ) -> None:
        prefixes = [b.prefix for b in bicycles]
        if len(set(prefixes)) != len(prefixes):
            raise ConfigError(f"bicycle prefixes must be unique, got {prefixes}")
        self.bicycles = list(bicycles)
        self.terrain = terrain or Terrain()
        self.obstacles = list(obstacles)
        self.parts = list(parts)
        self.riders = list(riders) + [None] * (len(bicycles) - len(riders))
        self.obstacle_geoms = np.zeros(0, dtype=np.int64)

    def build(self, spec: mujoco.MjSpec) -> None:
        # the floor turns here, in the spec: MuJoCo 4 fixes static geoms' poses at compile time
        # (writing the model's geom_quat afterwards moves nothing)
        floor = spec.geom("floor")
        floor.quat = self.terrain.quat().tolist()
        floor.pos = self.terrain.point.tolist()
        for b in self.bicycles:
            b.build(spec)
        h = self.terrain.height(np.array([[o.x, o.y] for o in self.obstacles]).reshape(-1, 2))
        for k, (o, z) in enumerate(zip(self.obstacles, h)):
            g = spec.worldbody.add_geom(
                name=f"obstacle{k}",
                type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                size=[o.radius, o.height / 2 + 0.5, 0.0],
                pos=[o.x, o.y, float(z) + o.height / 2 - 0.5],
            )  # fmt: skip  (0.5 m sunk into the ground: a slope never leaves a gap under it)
            g.rgba = [0.95, 0.55, 0.1, 1.0]
        for p in self.parts:
            p.build(spec)

    def configure(self, world: World) -> None:
        m = world.model
        floor = int(m.geom("floor").id)
        all_bits = 1 | sum(1 << (k + 1) for k in range(len(world.characters)))
        self.obstacle_geoms = np.array(
            [m.geom(f"obstacle{k}").id for k in range(len(self.obstacles))], dtype=np.int64
        )
        m.geom_contype[self.obstacle_geoms] = 1
        m.geom_conaffinity[self.obstacle_geoms] = all_bits | BARE_BIT
        m.geom_conaffinity[floor] |= BARE_BIT
        for b, rider in zip(self.bicycles, self.riders):
            b.bind(world)
            own = BARE_BIT if rider is None else 1 << (rider + 1)
            m.geom_contype[b.wheel_geoms] = own
            m.geom_conaffinity[b.wheel_geoms] = 1 if rider is None else all_bits & ~own
        for p in self.parts:
            p.bind(world)

    def place(self, world: World) -> None:
        """Put every bicycle at its placement on the terrain."""
        for b in self.bicycles:
            b.place(floor_normal=self.terrain.normal, floor_point=self.terrain.point)
        del world
