"""Group-riding courses (TOML): the terrain (a grade), the obstacles (cylinders), the group's
global velocity (a speed along a route of waypoints) and the finish. Every key is checked: an
unknown key, a wrong type or a number out of range raises a
:class:`~reactmocap.errors.ConfigError` naming the file, the key and what was expected.

Example (``examples/athletics/courses/corner_on_a_hill.toml``)::

    name = "corner on a hill"
    seconds = 60.0

    [terrain]
    grade_pct = 5.0        # the ground rises 5 m per 100 m ...
    direction_deg = 0.0    # ... toward +X

    [group]
    speed = 5.0            # the global speed (m/s) along the route
    route = [[0, 0], [60, 0], [60, 60]]
    spacing = 2.0          # desired distance between riders (m)

    [[obstacles]]
    x = 30.0
    y = 0.5
    radius = 0.4
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.cycling_scene import Obstacle, Terrain
from reactmocap.errors import ConfigError
from reactmocap.io import read_toml

__all__ = ["Course", "Route", "load_course", "parse_course"]

F64 = NDArray[np.float64]
#: the group's speed range (m/s) the rider's controller is measured over
SPEED_RANGE = (1.5, 12.0)


@dataclass(frozen=True)
class Route:
    """A polyline of waypoints ``(n, 2)`` (m): the group's global velocity points along it."""

    points: F64

    def __post_init__(self) -> None:
        p = np.asarray(self.points, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 2 or not np.all(np.isfinite(p)):
            raise ConfigError("a route needs at least two finite [x, y] waypoints")
        seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
        if np.any(seg < 1e-6):
            raise ConfigError("route waypoints must differ from their neighbours")
        p.setflags(write=False)
        object.__setattr__(self, "points", p)

    @property
    def lengths(self) -> F64:
        """``(n,)`` distance along the route at each waypoint."""
        return np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(self.points, axis=0), axis=1))]

    @property
    def length(self) -> float:
        return float(self.lengths[-1])

    def project(self, xy: F64) -> tuple[F64, F64]:
        """For points ``(k, 2)``: distance along the route of the nearest route point ``(k,)``
        (negative before the start, beyond the length after the end) and that point ``(k, 2)``."""
        p = self.points
        a, b = p[:-1], p[1:]
        ab = b - a
        t = np.einsum("kij,ij->ki", xy[:, None] - a[None], ab) / np.einsum("ij,ij->i", ab, ab)
        # the route goes on straight before its start and after its end (riders start behind
        # the start line and ride on after the finish)
        lo = np.zeros(len(ab))
        hi = np.ones(len(ab))
        lo[0], hi[-1] = -np.inf, np.inf
        t = np.clip(t, lo, hi)
        near = a[None] + t[..., None] * ab[None]
        d = np.linalg.norm(xy[:, None] - near, axis=2)
        k = np.argmin(d, axis=1)
        rows = np.arange(xy.shape[0])
        s = self.lengths[k] + t[rows, k] * np.linalg.norm(ab[k], axis=1)
        return s, near[rows, k]

    def point(self, s: F64) -> F64:
        """Route points ``(k, 2)`` at distances ``s`` ``(k,)``; before the start and past the
        end the route goes on straight."""
        lens = self.lengths
        s = np.asarray(s, dtype=np.float64)
        x = np.interp(np.clip(s, 0.0, lens[-1]), lens, self.points[:, 0])
        y = np.interp(np.clip(s, 0.0, lens[-1]), lens, self.points[:, 1])
        out = np.column_stack([x, y])
        p = self.points
        first, last = p[1] - p[0], p[-1] - p[-2]
        out += np.minimum(s, 0.0)[:, None] * first / np.linalg.norm(first)
        out += np.maximum(s - lens[-1], 0.0)[:, None] * last / np.linalg.norm(last)
        return out

    def direction(self, s: F64) -> F64:
        """Unit directions ``(k, 2)`` of the route at distances ``s``."""
        lens = self.lengths
        k = np.clip(np.searchsorted(lens, s, side="right") - 1, 0, len(lens) - 2)
        d = np.diff(self.points, axis=0)[k]
        return d / np.linalg.norm(d, axis=1, keepdims=True)


@dataclass(frozen=True)
class Course:
    """A parsed course. ``speed``: the group's global speed (m/s); ``spacing``: the desired
    distance between riders (m); ``lookahead``: how far ahead along the route the global
    velocity points (m); ``seconds``: the ride's length; ``source``: the file."""

    name: str
    terrain: Terrain
    obstacles: tuple[Obstacle, ...]
    route: Route
    speed: float
    spacing: float
    lookahead: float
    seconds: float
    source: str = "<course>"


_TOP = {"name": str, "seconds": float, "terrain": dict, "group": dict, "obstacles": list}
_TERRAIN = {"grade_pct": float, "direction_deg": float}
_GROUP = {"speed": float, "route": list, "spacing": float, "lookahead": float}
_OBSTACLE = {"x": float, "y": float, "radius": float, "height": float}


def _check(table: Mapping[str, Any], allowed: Mapping[str, type], where: str, src: str) -> None:
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise ConfigError(
            f"{src}: unknown key(s) {unknown} in {where}; valid keys are {sorted(allowed)}"
        )
    for key, typ in allowed.items():
        if key not in table:
            continue
        v = table[key]
        ok = (
            isinstance(v, (int, float)) and not isinstance(v, bool)
            if typ is float
            else isinstance(v, typ)
        )
        if not ok:
            raise ConfigError(
                f"{src}: {where}.{key} must be a {'number' if typ is float else typ.__name__}, "
                f"got {v!r}"
            )
        if typ is float and not math.isfinite(float(v)):
            raise ConfigError(f"{src}: {where}.{key} must be finite, got {v!r}")


def _range(v: float, lo: float, hi: float, what: str, src: str) -> float:
    if not lo <= v <= hi:
        raise ConfigError(f"{src}: {what} must be within {lo:g}-{hi:g}, got {v:g}")
    return float(v)


def parse_course(data: Mapping[str, Any], source: str = "<course>") -> Course:
    """A course from a parsed TOML table (see the module docstring)."""
    src = source
    _check(data, _TOP, "the top level", src)
    for key in ("group",):
        if key not in data:
            raise ConfigError(f"{src}: missing table [{key}]")
    terrain_t = data.get("terrain", {})
    _check(terrain_t, _TERRAIN, "[terrain]", src)
    grade = _range(float(terrain_t.get("grade_pct", 0.0)), -20.0, 20.0, "[terrain].grade_pct", src)
    terrain = Terrain(grade / 100.0, math.radians(float(terrain_t.get("direction_deg", 0.0))))
    group = data["group"]
    _check(group, _GROUP, "[group]", src)
    for key in ("speed", "route"):
        if key not in group:
            raise ConfigError(f"{src}: [group] needs {key!r}")
    speed = _range(float(group["speed"]), *SPEED_RANGE, "[group].speed (m/s)", src)
    route_raw = group["route"]
    try:
        points = np.array(route_raw, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"{src}: [group].route must be a list of [x, y] pairs") from None
    try:
        route = Route(points)
    except ConfigError as exc:
        raise ConfigError(f"{src}: [group].route: {exc}") from None
    spacing = _range(float(group.get("spacing", 2.0)), 0.8, 20.0, "[group].spacing (m)", src)
    lookahead = _range(float(group.get("lookahead", 6.0)), 1.0, 50.0, "[group].lookahead (m)", src)
    obstacles = []
    raw: Sequence[Any] = data.get("obstacles", [])
    for k, o in enumerate(raw):
        if not isinstance(o, dict):
            raise ConfigError(f"{src}: obstacles[{k}] must be a table ([[obstacles]])")
        _check(o, _OBSTACLE, f"obstacles[{k}]", src)
        if "x" not in o or "y" not in o:
            raise ConfigError(f"{src}: obstacles[{k}] needs x and y")
        try:
            obstacles.append(Obstacle(float(o["x"]), float(o["y"]), float(o.get("radius", 0.3)),
                                      float(o.get("height", 1.2))))  # fmt: skip
        except ConfigError as exc:
            raise ConfigError(f"{src}: obstacles[{k}]: {exc}") from None
    seconds = _range(float(data.get("seconds", 60.0)), 0.5, 600.0, "seconds", src)
    name = str(data.get("name", Path(source).stem))
    return Course(name, terrain, tuple(obstacles), route, speed, spacing, lookahead, seconds,
                  source)  # fmt: skip


def load_course(path: str | Path) -> Course:
    """Read and check a course file."""
    p = Path(path)
    return parse_course(read_toml(p, "course"), str(p))
