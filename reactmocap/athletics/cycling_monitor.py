"""The group ride's monitor (:class:`Monitor`, an engine controller): collisions, falls, the
closest approach between two bicycles and finish times, measured as the ride goes. Used by
:func:`reactmocap.athletics.cycling.group_ride` and :func:`~reactmocap.athletics.cycling.ride`;
figures: ``docs/athletics.md``."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.course import Route
from reactmocap.sim.world import World

if TYPE_CHECKING:
    from reactmocap.athletics.cycling import Team

__all__ = ["COLLISION_GAP", "MONITOR_EVERY", "Monitor"]

F64 = NDArray[np.float64]
#: the group monitor's period (steps) and how long (s) two things must be apart before their
#: next contact counts as a new collision
MONITOR_EVERY = 10
COLLISION_GAP = 0.5


def _segment_distances(a0: F64, a1: F64, b0: F64, b1: F64) -> F64:
    """Closest distances ``(k,)`` between 2-D segments ``a0-a1`` and ``b0-b1`` ``(k, 2)``
    (non-crossing: the four endpoint-to-segment distances; crossing: 0)."""

    def point_seg(p: F64, s0: F64, s1: F64) -> F64:
        d = s1 - s0
        t = np.clip(
            np.einsum("ij,ij->i", p - s0, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-12), 0, 1
        )
        return np.linalg.norm(p - (s0 + t[:, None] * d), axis=1)

    def cross(o: F64, a: F64, b: F64) -> F64:
        return (a[:, 0] - o[:, 0]) * (b[:, 1] - o[:, 1]) - (a[:, 1] - o[:, 1]) * (b[:, 0] - o[:, 0])

    d = np.minimum.reduce([point_seg(a0, b0, b1), point_seg(a1, b0, b1),
                           point_seg(b0, a0, a1), point_seg(b1, a0, a1)])  # fmt: skip
    hit = (cross(a0, a1, b0) * cross(a0, a1, b1) < 0) & (cross(b0, b1, a0) * cross(b0, b1, a1) < 0)
    return np.where(hit, 0.0, d)


class Monitor:
    """Measures a ride as it goes (an engine controller, every :data:`MONITOR_EVERY` steps):
    collisions (a new contact between two riders, a rider's body or wheels with another's, or
    with an obstacle; a pair counts again after :data:`COLLISION_GAP` s apart), falls (the
    bicycle rolled past 60 degrees, or the rider's body touched the ground), the closest
    distance between two bicycles (between their wheelbase lines, in the plane) and, with a
    route, when each rider reaches its end."""

    def __init__(self, team: Team, route: Route | None = None,
                 control_every: int = MONITOR_EVERY) -> None:  # fmt: skip
        self.team = team
        self.route = route
        self.control_every = control_every
        w = team.world
        m = w.model
        n = len(team.riders)
        owner = np.full(m.ngeom, -3, dtype=np.int64)  # -3: looks only
        owner[w.geom_character >= 0] = w.geom_character[w.geom_character >= 0]
        for k, b in enumerate(team.bicycles):
            owner[b.wheel_geoms] = k
        owner[team.scene.obstacle_geoms] = -2
        owner[m.geom("floor").id] = -1
        self.owner = owner
        self.is_wheel = np.zeros(m.ngeom, dtype=bool)
        for b in team.bicycles:
            self.is_wheel[b.wheel_geoms] = True
        self.n = n
        self.collisions: list[tuple[float, int, int]] = []  # (t, i, j); j = -2: an obstacle
        self._last: dict[tuple[int, int], float] = {}
        self.fell_at = np.full(n, np.nan)
        self.finish = np.full(n, np.nan)
        self.min_separation = math.inf
        self.separation_pair = (-1, -1)
        self.separation_time = math.nan
        iu = np.triu_indices(n, 1)
        self._pairs = iu

    def reset(self, world: World) -> None:
        del world

    def control(self, world: World, t: float) -> None:
        d = world.data
        nc = d.ncon
        if nc:
            g = d.contact.geom[:nc]
            o = self.owner[g]
            floor = (o == -1).any(axis=1)
            # wheels on the floor (nearly every contact) and looks-only geoms are not events
            other = np.where(o[:, 0] == -1, g[:, 1], g[:, 0])
            keep = ~(o == -3).any(axis=1) & ~(floor & self.is_wheel[other]) & (o[:, 0] != o[:, 1])
            for (a, b), on_floor in zip(o[keep], floor[keep]):
                if on_floor:  # a rider's body on the ground: a fall
                    k = int(b if a == -1 else a)
                    if k >= 0 and np.isnan(self.fell_at[k]):
                        self.fell_at[k] = t
                    continue
                pair = (int(min(a, b)), int(max(a, b))) if min(a, b) >= 0 else (int(max(a, b)), -2)
                last = self._last.get(pair)
                if last is None or t - last > COLLISION_GAP:
                    self.collisions.append((t, *pair))
                self._last[pair] = t
        for k, b in enumerate(self.team.bicycles):
            if b.fallen and np.isnan(self.fell_at[k]):
                self.fell_at[k] = t
        if self.n > 1:
            a0, a1 = self._lines()
            i, j = self._pairs
            dist = _segment_distances(a0[i], a1[i], a0[j], a1[j])
            k = int(np.argmin(dist))
            if dist[k] < self.min_separation:
                self.min_separation = float(dist[k])
                self.separation_pair = (int(i[k]), int(j[k]))
                self.separation_time = t
        if self.route is not None:
            a0, a1 = self._lines()
            s, _ = self.route.project(0.5 * (a0 + a1))
            done = (s >= self.route.length - 0.05) & np.isnan(self.finish)
            self.finish[done] = t

    def _lines(self) -> tuple[F64, F64]:
        """Each bicycle's wheelbase line in the plane: ground points under the wheel centres."""
        a0 = np.empty((self.n, 2))
        a1 = np.empty((self.n, 2))
        for k, b in enumerate(self.team.bicycles):
            p = b.position
            fwd = b.rotation()[:2, 0]
            a0[k] = p[:2]
            a1[k] = p[:2] + b.params.wheelbase * fwd / max(float(np.linalg.norm(fwd)), 1e-9)
        return a0, a1
